// Issue 21, "Nothing crashes, nothing hangs, nothing is lost", second round:
// input that used to be accepted or took minutes to refuse (a 50 MB scene,
// two conditions that contradict each other, material constants no run can
// survive) gets exit 2 and one line naming the file, the key path and what
// was expected; --quiet hides progress, never a warning. Through the binary.
#include <gtest/gtest.h>

#include "kernels/error.hpp"
#include "scene_text.hpp"
#include "shatter_cli.hpp"

namespace fs = std::filesystem;
using shatter::test::run_shatter;
using shatter::test::scratch_dir;
using shatter::test::write_scene;

namespace {

const std::string kGood = shatter::test::steel_box_scene("limits");

void expect_refused(const shatter::test::CliOutcome& r, const std::vector<std::string>& parts) {
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "one line expected:\n" << r.output.substr(0, 2000);
  EXPECT_EQ(r.output.rfind("error: ", 0), 0u) << r.output.substr(0, 2000);
  for (const std::string& p : parts) EXPECT_NE(r.output.find(p), std::string::npos) << p << " in " << r.output;
}

/// The good scene padded with a comment to `bytes` bytes.
std::string padded_scene(const std::string& name, std::size_t bytes) {
  std::string text = kGood + "#";
  text += std::string(bytes - text.size() - 1, 'x') + "\n";
  return write_scene(name, text);
}

}  // namespace

// A 50 MB scene took 40 s and 5.8 GB to be refused (yaml-cpp's tree of a
// long list); any file above kMaxSceneBytes is refused from its size, before
// it is read. A file of exactly the limit is read as usual.
TEST(InputLimits, OversizedSceneIsRefusedBeforeParsing) {
  const std::string over = padded_scene("limits_over", shatter::kMaxSceneBytes + 1);
  expect_refused(run_shatter("check " + over),
                 {over + ": the scene file is 1048577 bytes; expected at most 1048576 (1 MiB"});
  const std::string at = padded_scene("limits_at", shatter::kMaxSceneBytes);
  ASSERT_EQ(fs::file_size(at), shatter::kMaxSceneBytes);
  const auto ok = run_shatter("check " + at);
  EXPECT_EQ(ok.status, 0) << ok.output.substr(0, 2000);
  // parse_scene (the fuzz target's entry) refuses the same text.
  EXPECT_THROW(shatter::parse_scene(std::string(shatter::kMaxSceneBytes + 1, '#'), "big.yaml"),
               shatter::InputError);
}

// The bad value quoted in a message is cut after 200 characters (it was the
// whole 50 MB list, on one line).
TEST(InputLimits, LongBadValuesAreCutInTheMessage) {
  std::string list = "[0";
  for (int i = 0; i < 5000; ++i) list += ", 0";
  const std::string scene = write_scene("limits_long", kGood + "gravity: " + list + "]\n");
  const auto r = run_shatter("check " + scene);
  expect_refused(r, {scene + ": gravity: expected a list of 3 numbers [x, y, z], got '[0, 0, 0",
                     "... (15003 characters)'"});
  EXPECT_LT(r.output.size(), 400u) << r.output;
}

// Two conditions giving one component of one node different values: the last
// used to win. Now exit 2 with both key paths, the node and where it is. The
// same value twice (regions that overlap on a fixed edge) is accepted.
TEST(InputLimits, ConflictingConditionsNameBoth) {
  const std::string scene = write_scene("limits_bc", kGood);
  const std::string first = "{body: b, region: {box: [[-1, -1, -1], [-0.004, 1, 1]]}, velocity: [0, null, 0]}";
  const auto with = [&](const std::string& second) {
    return run_shatter("check " + scene + " --set 'boundary_conditions=[" + first + ", " + second + "]'");
  };
  expect_refused(with("{body: b, region: {box: [[-1, -1, -1], [1, -0.004, 1]]}, velocity: [null, 1, 2.5]}"),
                 {scene + ": boundary_conditions[1].velocity[2]: prescribes 2.5 m/s on node ",
                  " of body 'b' at (-0.005, -0.005, ",
                  "where boundary_conditions[0].velocity[2] prescribes 0 m/s; expected one value per component of "
                  "a node (regions that overlap must agree)"});
  const auto same = with("{body: b, region: {box: [[-1, -1, -1], [1, -0.004, 1]]}, velocity: [0, 1, 0]}");
  EXPECT_EQ(same.status, 0) << same.output;
  // Different components of one node do not conflict.
  const auto apart = with("{body: b, region: {box: [[-1, -1, -1], [1, -0.004, 1]]}, velocity: [null, 1, null]}");
  EXPECT_EQ(apart.status, 0) << apart.output;
}

// --quiet hides the progress line and the closing 'done' line, not a warning:
// time.dt above the stable step still says the run may blow up.
TEST(InputLimits, QuietHidesProgressNotWarnings) {
  const fs::path dir = scratch_dir("limits_quiet");
  const std::string scene = write_scene("limits_quiet", kGood);
  const auto r = run_shatter("run " + scene + " --quiet --out " + dir.string() +
                             " --set time.dt=1.0e-6 --set time.end=1.0e-6");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("warning: " + scene + ": time.dt = 1.000e-06 s is above the stable step"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("done:"), std::string::npos) << r.output;
}

// Material constants whose wave speed is infinite or beyond light's: E = 1e308
// ran into a strain energy of 5e284 J at steps of 4e-156 s, density 1e-300 at
// steps of 1e-159 s, both crawling without end. Refused, naming the material;
// a soft, light material of the scaled test scenes is accepted.
TEST(InputLimits, MaterialsFasterThanLightAreRefused) {
  const std::string scene = write_scene("limits_material", kGood);
  expect_refused(run_shatter("check " + scene + " --set materials.steel.youngs_modulus=1e308"),
                 {scene + ": materials.steel: the dilatational wave speed sqrt((lambda + 2 mu) / density) from "
                          "youngs_modulus 1e+308, poisson_ratio 0.3 and density 7850 is 1.30952e+152 m/s; expected at "
                          "most 3e8 m/s (the speed of light; steel's is 5.9e3 m/s)"});
  expect_refused(run_shatter("check " + scene + " --set materials.steel.density=1e-300"),
                 {"and density 1e-300 is inf m/s; expected at most 3e8 m/s"});
  expect_refused(run_shatter("check " + scene + " --set materials.steel.youngs_modulus=1e30"),
                 {"is 1.30952e+13 m/s; expected at most 3e8 m/s"});
  const auto soft = run_shatter("check " + scene +
                                " --set materials.steel.youngs_modulus=21000 --set materials.steel.density=0.0785");
  EXPECT_EQ(soft.status, 0) << soft.output;
}

// An initial state whose energy is already beyond Simulation::kEnergyOverflow
// (1e100 J) is bad input: no step of it is a good state to keep.
TEST(InputLimits, InitialEnergyBeyondOverflowIsRefused) {
  const std::string scene = write_scene("limits_energy", kGood);
  expect_refused(run_shatter("check " + scene + " --set 'bodies[0].initial_velocity=[1e60, 0, 0]'"),
                 {scene + ": the initial state's energy ledger is beyond 1e+100 J (kinetic 3.925e+117, ",
                  "the fastest node ", "has velocity (1e+60, 0, 0); expected initial velocities "
                  "(bodies[].initial_velocity, angular_velocity, velocity_gradient, boundary_conditions[].velocity) "
                  "and densities whose energy a run can hold"});
}
