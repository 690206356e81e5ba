// Issue 21: a restart continues its run exactly or refuses, with exit 2, one
// line naming what differs, and every file of the run as it was (it used to
// cut history.csv and bodies.csv and rewrite summary.json for a time.end
// before the checkpoint, leave a gap after a short history.csv, and accept a
// changed Young's modulus or gravity). Through the binary.
#include <gtest/gtest.h>

#include <map>

#include "scene_text.hpp"
#include "shatter_cli.hpp"

namespace fs = std::filesystem;
using shatter::test::file_bytes;
using shatter::test::run_shatter;
using shatter::test::scratch_dir;
using shatter::test::write_scene;

namespace {

const std::string kScene = shatter::test::steel_box_scene("restart_refusals", "0.005", "    initial_velocity: [1, 0, 0]\n",
                                                           "output: {every: 0}\ncheckpoint: {every_steps: 5}\n");

/// A finished run with a checkpoint at step 10 (11 steps in all).
struct FinishedRun {
  std::string scene;
  fs::path dir;
  std::map<std::string, std::string> files;  ///< name -> bytes, after the run

  void keep() {
    files.clear();
    for (const auto& e : fs::directory_iterator(dir)) files[e.path().filename()] = file_bytes(e.path());
  }
  void expect_untouched() const {
    for (const auto& [name, bytes] : files) EXPECT_EQ(file_bytes(dir / name), bytes) << name << " changed";
    for (const auto& e : fs::directory_iterator(dir))
      EXPECT_TRUE(files.count(e.path().filename())) << e.path() << " appeared";
  }
  shatter::test::CliOutcome restart(const std::string& extra) const {
    return run_shatter("run " + scene + " --quiet --restart " + (dir / "checkpoint.h5").string() + " " + extra);
  }
};

FinishedRun finished_run(const std::string& name) {
  // A scene file per test: ctest runs the tests of this file side by side.
  FinishedRun r{write_scene(name, kScene), scratch_dir(name), {}};
  const auto out = run_shatter("run " + r.scene + " --quiet --out " + r.dir.string());
  EXPECT_EQ(out.status, 0) << out.output;
  r.keep();
  return r;
}

void expect_refused(const shatter::test::CliOutcome& r, const std::string& part) {
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "one line expected:\n" << r.output;
  EXPECT_NE(r.output.find(part), std::string::npos) << part << " in " << r.output;
}

/// `text` without its lines whose first column is above `step` (and the last row cut short).
std::string rows_up_to(const std::string& text, long step) {
  std::istringstream in(text);
  std::string line, out;
  std::getline(in, line);
  out = line + "\n";
  while (std::getline(in, line))
    if (std::stol(line.substr(0, line.find(','))) <= step) out += line + "\n";
  return out;
}

}  // namespace

TEST(RestartRefusal, TimeEndBeforeTheCheckpointTouchesNothing) {
  FinishedRun r = finished_run("restart_time_end");
  expect_refused(r.restart("--set time.end=5.0e-7"),
                 "(step 10), time.end = 5e-07 s in " + r.scene + "; expected a time.end after the checkpoint's time");
  r.expect_untouched();
}

TEST(RestartRefusal, RowsEndingBeforeTheCheckpointAreRefused) {
  for (const char* csv : {"history.csv", "bodies.csv"}) {
    FinishedRun r = finished_run(std::string("restart_short_") + csv);
    std::ofstream(r.dir / csv, std::ios::binary | std::ios::trunc) << rows_up_to(r.files[csv], 7);
    r.keep();
    expect_refused(r.restart("--set time.end=2.0e-6"),
                   (r.dir / csv).string() + " ends at step 7 but the checkpoint is at step 10 (a row every 1 steps)");
    r.expect_untouched();
  }
  // A row that is not a row.
  FinishedRun r = finished_run("restart_bad_row");
  std::ofstream(r.dir / "history.csv", std::ios::binary | std::ios::trunc)
      << rows_up_to(r.files["history.csv"], 4) << "5x,garbage\n"
      << r.files["history.csv"].substr(rows_up_to(r.files["history.csv"], 5).size());
  r.keep();
  expect_refused(r.restart("--set time.end=2.0e-6"),
                 (r.dir / "history.csv").string() + ":7: expected a step number in the first column, got '5x'");
  r.expect_untouched();
}

// A history.csv of an older shatter (no contact_work column): the rows appended would be
// one value wider than its header.
TEST(RestartRefusal, HistoryOfOtherColumnsIsRefused) {
  FinishedRun r = finished_run("restart_old_columns");
  std::string old = r.files["history.csv"];
  const size_t header_end = old.find('\n');
  std::string header = old.substr(0, header_end);
  header.replace(header.find(",contact_work"), 13, "");
  old.replace(0, header_end, header);
  std::ofstream(r.dir / "history.csv", std::ios::binary | std::ios::trunc) << old;
  r.keep();
  expect_refused(r.restart("--set time.end=2.0e-6"), (r.dir / "history.csv").string() + " has the columns '" +
                                                         header + "'; expected '");
  r.expect_untouched();
}

TEST(RestartRefusal, ChangedPhysicsIsRefusedNamingTheKey) {
  FinishedRun r = finished_run("restart_physics");
  expect_refused(r.restart("--set time.end=2.0e-6 --set materials.steel.youngs_modulus=100.0e9"),
                 "materials.steel.youngs_modulus is 210000000000 in the checkpoint's scene and 100000000000 in " +
                     r.scene);
  expect_refused(r.restart("--set time.end=2.0e-6 --set gravity=[0,0,-9.81]"),
                 "gravity[2] is 0 in the checkpoint's scene and -9.81 in " + r.scene);
  expect_refused(r.restart("--set time.end=2.0e-6 --set 'contact={friction: 0.2}'"),
                 "contact is off in the checkpoint's scene and on in " + r.scene);
  r.expect_untouched();
  // What a restart may change: time.end, time.safety, output, checkpoint.
  const auto ok = r.restart("--set time.end=2.0e-6 --set time.safety=0.4 --set output.history_every=2");
  EXPECT_EQ(ok.status, 0) << ok.output;
}
