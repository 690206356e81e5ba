// Regressions on the small versions of the seeds' examples
// (scenes/regression/*.yaml): each scene is loaded through load_scene and
// build_model, run whole with Simulation (no files written) and checked
// against the figures its header promises:
//   - linear momentum conserved to 1e-12 of sum |m v| (no gravity, no
//     boundary conditions);
//   - the ledger total within 0.5 % (1 % for the 76 cubes) with and without
//     friction, contact_work included (measured at most 0.13 %, 0.56 %);
//   - friction dissipates (contact_dissipated > 0), contact_dissipated never
//     decreases (every scene, run_scene);
//   - contacts during the impact, and the centre-of-mass velocities after it
//     turned as the physics says.
//   - angular momentum kept to 1e-12 of sum m |x| |v| through every contact scene.
// A last test runs `shatter plot` on a small run's output folder.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "expect_close.hpp"
#include "run_checks.hpp"
#include "runtime/model.hpp"
#include "runtime/scene.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/simulation.hpp"

using namespace shatter;

namespace {

std::string scene_path(const std::string& name) {
  return std::string(SHATTER_SOURCE_DIR) + "/scenes/regression/" + name + ".yaml";
}

/// Centre-of-mass velocity of every body, m/s.
std::vector<Vec3> body_velocities(const Model& m, std::span<const Vec3> v) {
  std::vector<Vec3> mv(m.body_mass.size(), Vec3::Zero());
  for (Index i = 0; i < m.mesh.num_nodes(); ++i) mv[m.mesh.node_body[i]] += m.mass[i] * v[i];
  for (size_t b = 0; b < mv.size(); ++b) mv[b] /= m.body_mass[b];
  return mv;
}

/// What a whole run of a scene gives: the ledger at the start and end, the
/// largest energy error and contact count over the run, the body velocities
/// before and after, and the momentum scales.
struct SceneRun {
  Ledger first, last;
  double max_energy_error = 0;  ///< max |total - total(0)| / total(0)
  long max_contacts = 0;
  std::vector<Vec3> v_before, v_after;
  double p_scale = 0;  ///< sum m |v| at the start, kg m/s
  double l_scale = 0;  ///< sum m |x| |v| at the start, kg m^2/s
  double max_dL = 0;    ///< max |L - L(0)| over the run, kg m^2/s
};

SceneRun run_scene(const std::string& name) {
  Model model = build_model(load_scene(scene_path(name)));
  Simulation sim(model, {});
  SceneRun r;
  r.first = sim.ledger();
  r.v_before = body_velocities(model, sim.velocities());
  for (Index i = 0; i < model.mesh.num_nodes(); ++i) {
    r.p_scale += model.mass[i] * sim.velocities()[i].norm();
    r.l_scale += model.mass[i] * sim.positions()[i].norm() * sim.velocities()[i].norm();
  }
  const double end = model.scene.end_time;
  std::vector<double> contact_dissipated;
  while (sim.time() < end - 1e-12 * end) {
    sim.step();
    contact_dissipated.push_back(sim.ledger().contact_dissipated);
    r.max_contacts = std::max(r.max_contacts, sim.ledger().contacts);
    r.max_dL = std::max(r.max_dL, (sim.ledger().angular_momentum - r.first.angular_momentum).norm());
    r.max_energy_error =
        std::max(r.max_energy_error, std::abs(sim.ledger().total() - r.first.total()) / r.first.total());
  }
  r.last = sim.ledger();
  std::printf("%s: contact_dissipated %.4e J, contact_work %+.4e J, energy error final %+.3e, max %.3e, "
              "angular momentum max change %.2e of sum m |x| |v|\n",
              name.c_str(), r.last.contact_dissipated, r.last.contact_work,
              (r.last.total() - r.first.total()) / r.first.total(), r.max_energy_error, r.max_dL / r.l_scale);
  EXPECT_TRUE(test::never_decreases(contact_dissipated)) << name << ": contact_dissipated decreased";
  r.v_after = body_velocities(model, sim.velocities());
  return r;
}

void expect_momentum_conserved(const SceneRun& r) {
  EXPECT_LT((r.last.momentum - r.first.momentum).norm(), 1e-12 * r.p_scale)
      << "linear momentum changed by " << (r.last.momentum - r.first.momentum).norm() << " of " << r.p_scale;
}

/// Two bodies meeting off-centre along x (left at +v, right at -v, the right
/// one higher in y): after the impact each moves back along x and is deflected
/// in y away from the other.
void expect_oblique_rebound(const SceneRun& r) {
  ASSERT_EQ(r.v_after.size(), 2u);
  EXPECT_LT(r.v_after[0].x(), 0.0);
  EXPECT_GT(r.v_after[1].x(), 0.0);
  EXPECT_LT(r.v_after[0].y(), 0.0);
  EXPECT_GT(r.v_after[1].y(), 0.0);
}

}  // namespace

// Four spinning cubes thrown at a fifth from four sides: corners and edges
// hit faces. Measured at ecfc919 (element_size 0.35): energy error max
// 1.3 %, final -0.8 % (finer meshes lose less: at 0.25, 0.9 % / -0.4 %).
// With the contact's first-order work in the ledger (contact_work, 0.82 J):
// max 0.12 %, final +0.12 %.
// Commit 267cf4c (collision at t*, reverted by ecfc919) made it GAIN 15 %:
// this test is what caught it.
TEST(Scenes, FiveCubesFrictionless) {
  const SceneRun r = run_scene("five_cubes");
  expect_momentum_conserved(r);
  EXPECT_GT(r.max_contacts, 0);
  EXPECT_LT(r.max_energy_error, 0.005);
  EXPECT_EQ(r.last.contact_dissipated, 0.0);
  // Every thrower (bodies 1-4) has lost at least half of its speed along its
  // line of flight; the resting hub is set moving.
  for (int b = 1; b <= 4; ++b) {
    const Vec3 dir = r.v_before[b].normalized();
    EXPECT_LT(r.v_after[b].dot(dir), 0.5 * r.v_before[b].norm()) << "body " << b;
  }
  EXPECT_GT(r.v_after[0].norm(), 5.0);
}

TEST(Scenes, FiveCubesFriction) {
  const SceneRun r = run_scene("five_cubes_friction");
  expect_momentum_conserved(r);
  EXPECT_GT(r.max_contacts, 0);
  EXPECT_GT(r.last.contact_dissipated, 0.01 * r.first.total());
  EXPECT_LT(r.last.kinetic + r.last.strain, r.first.total());
  EXPECT_LT(r.max_energy_error, 0.005);
}

// Two solid spheres (R = 1) meeting off-centre at 2 x 25 m/s.
// Measured at ecfc919 (element_size 0.25): energy error max 1.3 %, final -0.9 %;
// with contact_work (2.30 J) in the ledger: max 0.04 %, final +0.04 %.
TEST(Scenes, SpheresImpactFrictionless) {
  const SceneRun r = run_scene("spheres_impact");
  expect_momentum_conserved(r);
  EXPECT_GT(r.max_contacts, 0);
  EXPECT_EQ(r.last.contacts, 0);
  EXPECT_LT(r.max_energy_error, 0.005);
  expect_oblique_rebound(r);
}

TEST(Scenes, SpheresImpactFriction) {
  const SceneRun r = run_scene("spheres_impact_friction");
  expect_momentum_conserved(r);
  EXPECT_GT(r.max_contacts, 0);
  EXPECT_EQ(r.last.contacts, 0);
  EXPECT_GT(r.last.contact_dissipated, 0.0);
  EXPECT_LT(r.max_energy_error, 0.005);
  expect_oblique_rebound(r);
}

// Two disks (R = 1, thickness 0.25) meeting rim to rim, off-centre.
// Measured at ecfc919 (element_size 0.125): energy error max 0.6 %, final -0.3 %;
// with contact_work (0.17 J) in the ledger: max 0.03 %, final +0.03 %.
TEST(Scenes, TwoDisks) {
  const SceneRun r = run_scene("two_disks");
  expect_momentum_conserved(r);
  EXPECT_GT(r.max_contacts, 0);
  EXPECT_EQ(r.last.contacts, 0);
  EXPECT_LT(r.max_energy_error, 0.005);
  expect_oblique_rebound(r);
}

// 12 spinning cubes flying into a loose 4 x 4 x 4 lattice of slowly spinning
// cubes. Momenta are kept and the impact travels through the lattice. The
// end placement's loss on every repeated contact (-10.8 % of the energy) is
// the contact_work (50.4 J): the ledger total ends +0.56 %.
TEST(Scenes, Cubes76) {
  const SceneRun r = run_scene("cubes76");
  ASSERT_EQ(r.v_after.size(), 76u);
  expect_momentum_conserved(r);
  EXPECT_LT(r.max_energy_error, 0.01);
  EXPECT_GT(r.max_contacts, 10);
  // The lattice cubes (the first 64) that were hit now move along +x.
  int pushed = 0;
  for (int b = 0; b < 64; ++b) pushed += r.v_after[b].x() > 1.0;
  EXPECT_GE(pushed, 4);
}

// The coarse expanding ring with contact, to 0.4 us
// (scenes/regression/expanding_ring_contact.yaml): ~1380 cohesive elements,
// ~90 fragments, up to 5 contacts at a time from 0.22 us (freed crack faces
// and fragments meeting). The faces of bonded facets stay out of the contact surface
// and the nodes a bonded facet joins count as one for the pairs, so DCR never
// fights the cohesive compression penalty: no step reaches the sweep cap (with
// the crack faces in contact as soon as their nodes split, 28 of the 771
// steps of the ring to 1.5 us did, and 16 with only the faces left out).
// Energy error max 1.0e-3 (the ring's own, issue 19).
TEST(Scenes, ExpandingRingContact) {
  const SceneRun r = run_scene("expanding_ring_contact");
  expect_momentum_conserved(r);
  EXPECT_EQ(r.last.contact_capped_steps, 0);
  EXPECT_GT(r.max_contacts, 0);
  EXPECT_GT(r.last.cohesive_elements, 1000);
  EXPECT_LT(r.max_energy_error, 2e-3);
}

// John & Shah (1990) beam, notch at gamma = 0.5 (scenes/john_shah_beam_g05.yaml)
// on a coarser mesh (h = 8 mm, ~6000 TET4): the first cohesive elements are
// inserted at the notch tip (x = 50.8 mm, y = 19 mm), not at mid-span or
// under the load. The run stops when the first inserted facets have opened
// (~0.14 ms, ~2800 steps, ~4 s). The gamma = 0.8 beam also cracks at its notch first, unlike the
// experiment (docs/validation.md), so it has no test here.
TEST(Scenes, JohnShahG05CrackStartsAtTheNotch) {
  const std::string path = std::string(SHATTER_SOURCE_DIR) + "/scenes/john_shah_beam_g05.yaml";
  Model model = build_model(load_scene(path, {"bodies[0].mesh.element_size=8.0e-3"}));
  Simulation sim(model, {});
  while (sim.ledger().cohesive_elements == 0 && sim.time() < model.scene.end_time) sim.step();
  ASSERT_GT(sim.ledger().cohesive_elements, 0) << "no crack by " << sim.time() << " s";
  // Inserted facets start closed (damage 0): step until they open.
  std::vector<double> damage = sim.fracture()->damage();
  for (int s = 0; s < 200 && *std::max_element(damage.begin(), damage.end()) == 0; ++s) {
    sim.step();
    damage = sim.fracture()->damage();
  }
  const double h = 8.0e-3, notch_x = 0.0508, notch_tip_y = 0.01905;
  int damaged = 0;
  for (Index e = 0; e < model.mesh.num_elements(); ++e) {
    if (damage[e] <= 0) continue;
    ++damaged;
    Vec3 c = Vec3::Zero();
    for (int a = 0; a < 4; ++a) c += 0.25 * model.mesh.reference[model.mesh.element(e)[a]];
    EXPECT_LT(std::abs(c.x() - notch_x), 1.5 * h) << "damaged element " << e << " at x = " << c.x();
    EXPECT_LT(std::abs(c.y() - notch_tip_y), 1.5 * h) << "damaged element " << e << " at y = " << c.y();
  }
  EXPECT_GT(damaged, 0);
  EXPECT_GT(sim.time(), 0.05e-3);  // bending had to build up: not a shock at the load line
}

// Angular momentum through contact (issue 18): the projections' velocity counterpart
// (kernels/dcr.hpp dcr_keep_angular_momentum, docs/contact.md "Angular momentum") keeps
// sum m x x v, which the time loop keeps exactly otherwise, so over every contact scene here
// (sliding and spinning impacts, friction, the 76 cubes' chains of pairs sharing nodes) it
// stays within 1e-12 of sum m |x| |v| at every step. Until then it changed by 2.1e-5 to
// 1.8e-4 of that scale (this test was DISABLED_KnownDefects). The energy: the ledger total
// within 1 % (the scenes' own tests hold most of them tighter).
TEST(Scenes, ContactKeepsAngularMomentum) {
  for (const char* name : {"five_cubes", "five_cubes_friction", "spheres_impact", "spheres_impact_friction",
                           "two_disks", "cubes76"}) {
    const SceneRun r = run_scene(name);
    EXPECT_GT(r.max_contacts, 0) << name;
    EXPECT_LT(r.max_dL, 1e-12 * r.l_scale) << name << ": angular momentum changed by " << r.max_dL / r.l_scale
                                           << " of the scale";
    EXPECT_LT(r.max_energy_error, 0.01) << name << ": final energy error "
                                        << (r.last.total() - r.first.total()) / r.first.total();
  }
}

// `shatter plot` on a run's output folder writes non-empty PNGs, and exits
// with status 2 on a folder without history.csv.
TEST(Scenes, PlotWritesPngs) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no matplotlib";
  const auto out = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_test_plot";
  std::filesystem::remove_all(out);
  {
    Model model = build_model(load_scene(scene_path("spheres_impact")));
    RunOptions opt;
    opt.out_dir = out;
    opt.quiet = true;
    Simulation sim(model, opt);
    sim.run();
  }
  const std::string shatter = std::string(SHATTER_BINARY_DIR) + "/apps/shatter";
  const int status = std::system((shatter + " plot " + out.string() + " > /dev/null").c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  for (const char* png : {"energies.png", "momenta.png", "contacts.png", "fragments.png", "bodies.png"}) {
    const auto path = out / "plots" / png;
    ASSERT_TRUE(std::filesystem::is_regular_file(path)) << path;
    EXPECT_GT(std::filesystem::file_size(path), 1000u) << path;
  }
  // A history.csv of a shatter before contact_work (issue 18) is still plotted.
  {
    std::ifstream in(out / "history.csv");
    std::string line, old;
    while (std::getline(in, line)) {
      size_t at = 0;
      for (int comma = 0; comma < 8; ++comma) at = line.find(',', at) + 1;  // the 9th column
      old += line.erase(at, line.find(',', at) + 1 - at) + "\n";
    }
    ASSERT_EQ(old.find("contact_work"), std::string::npos);
    in.close();
    std::ofstream(out / "history.csv", std::ios::trunc) << old;
  }
  std::filesystem::remove_all(out / "plots");
  const int old_status = std::system((shatter + " plot " + out.string() + " > /dev/null").c_str());
  ASSERT_TRUE(WIFEXITED(old_status));
  EXPECT_EQ(WEXITSTATUS(old_status), 0);
  EXPECT_GT(std::filesystem::file_size(out / "plots" / "energies.png"), 1000u);
  const auto empty = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_test_plot_empty";
  std::filesystem::create_directories(empty);
  const int missing = std::system((shatter + " plot " + empty.string() + " 2> /dev/null").c_str());
  ASSERT_TRUE(WIFEXITED(missing));
  EXPECT_EQ(WEXITSTATUS(missing), 2);
}
