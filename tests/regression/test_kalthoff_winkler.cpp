// Kalthoff-Winkler plate (issue 19, done-when 4; docs/validation.md): a coarse
// run of scenes/kalthoff_winkler.yaml with its field output, the crack angle
// measured on it by bench/kalthoff_angle.py. Writing fields.h5 needs MPI
// (runtime/field_output.cpp), hence a program of its own with MPI_Init.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "mpi_environment.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/model.hpp"
#include "runtime/scene.hpp"
#include "runtime/simulation.hpp"

using namespace shatter;

// Kalthoff-Winkler half plate (scenes/kalthoff_winkler.yaml) on the coarse mesh of
// docs/validation.md (h = 2 mm, 4 mm thick, ~30 000 TET4) to 60 us (~3 900 steps,
// ~15 s): the first facets to open are at the notch tip (x = 50 mm, y = 25 mm),
// not at the struck edge or along the notch flanks, after 20 us (the stress wave
// from the struck edge has to reach the tip: 50 mm at 5.6 km/s is 9 us, then the
// tip's stress has to build up; measured 24 us); and the crack from the tip,
// measured by bench/kalthoff_angle.py, is longer than 3 elements and heads away
// from the notch at 60-85 degrees: around the direction of largest hoop stress
// under the tip's shear loading (70.5 degrees in pure mode II), where this mesh
// measured 65-77 degrees once the crack was 6 mm long (73.7 at 60 us), h = 1.5 mm
// 70.4 and h = 1 mm 66.1. A shear crack along the notch (0 degrees), one toward the
// symmetry plane (negative) or straight across (90) fails it. The ledger's energy
// error stays under 1e-3 until the first facet opens, while the struck edge
// speeds up (measured at most 1.3e-4, in the first steps, when the energy put in
// is still tiny; 1e-9 at 20 us): the reactions' work includes that of their
// inertial part, the struck nodes' own kinetic energy (without it the error
// reached 1.0 in the first steps and 0.42 at 0.4 us), and under 1 % after it
// (the cohesive law's chatter, docs/physics.md; measured at most 4.7e-3)
// (docs/validation.md "Kalthoff-Winkler").
TEST(Scenes, KalthoffWinklerCrackLeavesTheNotchTipAtTheHoopStressAngle) {
  const std::string path = std::string(SHATTER_SOURCE_DIR) + "/scenes/kalthoff_winkler.yaml";
  const double h = 2.0e-3, tip_x = 0.050, tip_y = 0.025;
  Model model = build_model(load_scene(
      path, {"bodies[0].mesh.element_size=2.0e-3", "bodies[0].mesh.size=[0.1, 0.1, 4.0e-3]", "time.end=60.0e-6"}));
  const auto out = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "kalthoff_winkler";
  std::filesystem::remove_all(out);
  RunOptions opt;
  opt.out_dir = out;
  opt.quiet = true;
  const Simulation* running = nullptr;
  double max_energy_error = 0, max_intact_error = 0;
  std::vector<Vec3> first_damaged;  // reference centroids of the first elements with damage
  opt.before_step = [&](long) {
    max_energy_error = std::max(max_energy_error, std::abs(running->energy_error()));
    if (running->ledger().cohesive_elements == 0)
      max_intact_error = std::max(max_intact_error, std::abs(running->energy_error()));
    if (!first_damaged.empty() || running->ledger().cohesive_elements == 0) return;
    const std::vector<double> damage = running->fracture()->damage();
    for (Index e = 0; e < model.mesh.num_elements(); ++e) {
      if (damage[e] <= 0) continue;
      Vec3 c = Vec3::Zero();
      for (int a = 0; a < 4; ++a) c += 0.25 * model.mesh.reference[model.mesh.element(e)[a]];
      first_damaged.push_back(c);
    }
  };
  Simulation sim(model, opt);
  running = &sim;
  sim.run();
  max_energy_error = std::max(max_energy_error, std::abs(sim.energy_error()));
  EXPECT_LT(max_intact_error, 1e-3);
  EXPECT_LT(max_energy_error, 0.01);
  ASSERT_FALSE(first_damaged.empty()) << "no facet opened by " << sim.time() << " s";
  EXPECT_GT(sim.time(), 20e-6);
  for (const Vec3& c : first_damaged) {
    EXPECT_LT(std::hypot(c.x() - tip_x, c.y() - tip_y), 2.0 * h) << "first damage at " << c.transpose();
  }
  if (std::system("/usr/bin/python3 -c 'import h5py, numpy' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no h5py or numpy: crack angle not measured";
  const auto csv = out / "angle.csv";
  const std::string cmd = std::string("/usr/bin/python3 ") + SHATTER_SOURCE_DIR + "/bench/kalthoff_angle.py " +
                          out.string() + " --h 2.0e-3 --csv > " + csv.string();
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0) << "kalthoff_angle.py found no crack from the notch tip";
  double angle = 0, length_mm = 0;
  int elements = 0;
  std::FILE* in = std::fopen(csv.c_str(), "r");
  ASSERT_NE(in, nullptr);
  ASSERT_EQ(std::fscanf(in, "%lf,%d,%lf", &angle, &elements, &length_mm), 3);
  std::fclose(in);
  EXPECT_GT(length_mm, 3 * h) << "the crack did not run";
  EXPECT_GT(angle, 60.0);
  EXPECT_LT(angle, 85.0);
}
