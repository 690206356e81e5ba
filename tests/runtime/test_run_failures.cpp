// Issue 21, "Nothing crashes, nothing hangs, nothing is lost", second round:
// a run that would crawl (its stable step collapsed) or overflow (an energy
// beyond 1e100 J) stops with exit 1, a diagnosis naming what, where, when and
// the likely cause, and the checkpoint of the last good state, from which a
// restart continues exactly (and meets the same failure at the same step).
// Through the binary, as a user meets them.
#include <gtest/gtest.h>

#include <fstream>

#include "checkpoint_failure.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/model.hpp"
#include "scene_text.hpp"
#include "shatter_cli.hpp"

namespace fs = std::filesystem;
using shatter::test::failure_attribute;
using shatter::test::run_shatter;
using shatter::test::scratch_dir;
using shatter::test::write_scene;

namespace {

/// A 1 cm steel box whose face x = -5 mm is driven at `speed` in x toward
/// its face x = +5 mm, held; `material` replaces the steel's constants.
std::string crushed_box(const std::string& name, const std::string& speed,
                        const std::string& material = "density: 7850, youngs_modulus: 210.0e9") {
  return "name: " + name +
         "\ntime: {end: 1.0e-4}\noutput: {every: 0}\n"
         "materials:\n"
         "  steel: {model: neo_hookean, " + material + ", poisson_ratio: 0.3}\n"
         "bodies:\n"
         "  - {name: b, material: steel, mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005}}\n"
         "boundary_conditions:\n"
         "  - {body: b, region: {box: [[-1, -1, -1], [-0.004, 1, 1]]}, velocity: [" + speed + ", null, null]}\n"
         "  - {body: b, region: {box: [[0.004, -1, -1], [1, 1, 1]]}, velocity: [0, null, null]}\n";
}

long last_history_step(const fs::path& dir) {
  std::ifstream in(dir / "history.csv");
  std::string line, last;
  while (std::getline(in, line)) last = line;
  return std::stol(last.substr(0, last.find(',')));
}

/// Runs `scene` into `dir`: exit 1 with `parts` in the first line, the
/// checkpoint of the step before the failing one (with the error in its
/// attribute `failure`), the history up to it; a restart from that checkpoint
/// fails at the same step with the same first line. Returns the first line.
std::string expect_failure_with_checkpoint(const std::string& scene, const fs::path& dir,
                                           const std::vector<std::string>& parts) {
  const auto r = run_shatter("run " + scene + " --quiet --threads 1 --out " + dir.string());
  EXPECT_EQ(r.status, 1) << r.output;
  for (const std::string& p : parts) EXPECT_NE(r.first_line().find(p), std::string::npos) << p << "\n" << r.output;
  shatter::Model model = shatter::build_model(shatter::load_scene(scene));
  const fs::path checkpoint = dir / "checkpoint.h5";
  const shatter::SimulationState s = shatter::read_checkpoint(checkpoint, model);
  EXPECT_NE(r.first_line().find("error: step " + std::to_string(s.step + 1) + ", t = "), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("the last good state (step " + std::to_string(s.step) + ") is in " + checkpoint.string()),
            std::string::npos)
      << r.output;
  // The cause is in the scene: no advice to restart with a smaller step.
  EXPECT_NE(r.output.find(": a restart would continue the same physics (it refuses changed physics keys), so "
                          "correct the scene (the likely cause above) and run it again"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("time.safety"), std::string::npos) << r.output;
  EXPECT_EQ(last_history_step(dir), s.step);
  EXPECT_EQ(failure_attribute(checkpoint), r.first_line().substr(7));
  const auto again = run_shatter("run " + scene + " --quiet --threads 1 --restart " + checkpoint.string());
  EXPECT_EQ(again.status, 1) << again.output;
  EXPECT_EQ(again.first_line(), r.first_line());
  return r.first_line();
}

}  // namespace

// A face driven at 300 m/s crushes the box against its held face in 33 us:
// the stable step fell 5 orders of magnitude and the run crawled (1e-17 s
// steps) with no word. Now it stops when the step falls below 1e-3 of the
// initial one, naming the element that sets it and the driving conditions.
TEST(RunFailures, StepCollapseStopsNamingTheElementAndTheCause) {
  const fs::path dir = scratch_dir("failures_collapse");
  const std::string scene = write_scene("failures_collapse", crushed_box("failures_collapse", "300"));
  const std::string line = expect_failure_with_checkpoint(
      scene, dir,
      {"s: the stable step collapsed to ", " s, below 1e-3 of the initial ", " s (the run would crawl); element ",
       " (body 'b') near (", ") sets it (stable step ", ", det F = ",
       "likely cause: the velocities prescribed on its body (boundary_conditions[0].velocity = [300, null, null] "
       "m/s", "and it is crushed to ", " of its volume; check those velocities against the body's size and wave speed"});
  // The collapse is found before the faces meet (t = 33.3 us).
  const double t = std::stod(line.substr(line.find("t = ") + 4));
  EXPECT_LT(t, 0.01 / 300);
  EXPECT_GT(t, 0.9 * 0.01 / 300);
}

// Constants a run can hold (a wave speed of 1e5 m/s) but energies that reach
// 1e100 J once the driven face has squeezed the box by 1 %: the run stops at
// that step, naming the ledger's terms and the fastest node.
TEST(RunFailures, EnergyOverflowStopsWithTheLedger) {
  const fs::path dir = scratch_dir("failures_overflow");
  const std::string scene = write_scene(
      "failures_overflow",
      crushed_box("failures_overflow", "10", "density: 1.0e100, youngs_modulus: 1.0e110"));
  expect_failure_with_checkpoint(scene, dir,
                                 {"s: the energy ledger is beyond 1e+100 J, an overflow under way (kinetic ",
                                  "; the fastest node ", " (body 'b') at (",
                                  "; check the scene's velocities, gravity and material constants"});
}
