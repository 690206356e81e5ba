// Issue 21, "Nothing crashes, nothing hangs, nothing is lost": input the
// scene format used to accept or misread, and output folders the run could
// not use, are refused before any work with exit 2 and one line naming the
// file, the key path and what was expected; a stop during set-up says so.
// Through the binary, as a user meets them.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <thread>

#include "scene_text.hpp"
#include "shatter_cli.hpp"

namespace fs = std::filesystem;
using shatter::test::file_bytes;
using shatter::test::run_shatter;
using shatter::test::scratch_dir;
using shatter::test::write_scene;

namespace {

const std::string kMaterial =
    "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n";
const std::string kBody =
    "bodies:\n"
    "  - name: b\n"
    "    material: steel\n"
    "    mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005}\n";
const std::string kGood = shatter::test::steel_box_scene("strict");

void expect_refused(const shatter::test::CliOutcome& r, const std::vector<std::string>& parts) {
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "one line expected:\n" << r.output;
  EXPECT_EQ(r.output.rfind("error: ", 0), 0u) << r.output;
  for (const std::string& p : parts) EXPECT_NE(r.output.find(p), std::string::npos) << p << " in " << r.output;
}

}  // namespace

TEST(StrictInput, RepeatedKeysAreRefusedWithBothLines) {
  // Top level: the first value used to win.
  const std::string top = write_scene("dup_top", "name: strict\ntime: {end: 1.0e-6}\ntime: {end: 2.0e-6}\nmaterials:\n" +
                                                     kMaterial + kBody);
  expect_refused(run_shatter("check " + top), {top + ":3:1: time: duplicate key (first at line 2:1)"});
  // In materials the last one used to win.
  const std::string mats =
      write_scene("dup_materials", "name: strict\ntime: {end: 1.0e-6}\nmaterials:\n" + kMaterial +
                                       "  steel: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e9, "
                                       "poisson_ratio: 0.3}\n" + kBody);
  expect_refused(run_shatter("check " + mats), {mats + ":5:3: materials.steel: duplicate key (first at line 4:3)"});
  // Inside a list item, in flow style.
  const std::string nested = write_scene(
      "dup_nested", "name: strict\ntime: {end: 1.0e-6}\nmaterials:\n" + kMaterial +
                        "bodies:\n  - name: b\n    material: steel\n"
                        "    mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005, element_size: 1}\n");
  expect_refused(run_shatter("check " + nested), {"bodies[0].mesh.element_size: duplicate key"});
  // In a --set value.
  expect_refused(run_shatter("check " + write_scene("strict_dup_set", kGood) + " --set 'time={end: 1, end: 2}'"),
                 {"--set time={end: 1, end: 2}", "time.end: duplicate key"});
}

TEST(StrictInput, SetIndexesAreDecimalIntegersOnly) {
  const std::string scene = write_scene("strict_index", kGood);
  for (const char* index : {"0abc", "0x1", "-0", "+0", " 0", "", "1e0"})
    expect_refused(run_shatter("check " + scene + " --set 'bodies[" + index + "].material=steel'"),
                   {"expected a decimal index inside [ ], got '" + std::string(index) + "'"});
  EXPECT_EQ(run_shatter("check " + scene + " --set 'bodies[0].material=steel'").status, 0);
}

TEST(StrictInput, UnusableOutputFolderIsRefusedBeforeMeshing) {
  const fs::path dir = scratch_dir("strict_output");
  const std::string scene = write_scene("strict_output", kGood);
  std::ofstream(dir / "a_file") << "x";
  expect_refused(run_shatter("run " + scene + " --quiet --out " + (dir / "a_file" / "out").string()),
                 {"output folder " + (dir / "a_file" / "out").string() + ": cannot create it (Not a directory)"});
  // A folder where fields.h5 goes used to print 14 lines of HDF5 diagnostics.
  fs::create_directories(dir / "taken" / "fields.h5");
  expect_refused(run_shatter("run " + scene + " --quiet --out " + (dir / "taken").string()),
                 {(dir / "taken" / "fields.h5").string() + " is a folder"});
  // A device in place of an output file (a write there fails: /dev/full).
  fs::create_directories(dir / "device");
  fs::create_symlink("/dev/full", dir / "device" / "checkpoint.h5.tmp");
  expect_refused(run_shatter("run " + scene + " --quiet --out " + (dir / "device").string()),
                 {(dir / "device" / "checkpoint.h5.tmp").string() + " is not a regular file"});
  EXPECT_FALSE(fs::exists(dir / "taken" / ".shatter_reserve"));
  // A good folder: the reserve file is gone after the run.
  const auto ok = run_shatter("run " + scene + " --quiet --out " + (dir / "good").string());
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(fs::exists(dir / "good" / "summary.json"));
  EXPECT_FALSE(fs::exists(dir / "good" / ".shatter_reserve"));
}

// SIGTERM while the mesher works (a fine mesh takes seconds): one line, exit 1.
TEST(StrictInput, StopDuringSetUpSaysSo) {
  const fs::path dir = scratch_dir("strict_stop");
  const std::string scene = write_scene("strict_stop", kGood);
  for (int sig : {SIGTERM, SIGINT}) {
    fs::remove_all(dir / "out");
    const fs::path log = dir / "log.txt";
    const shatter::test::Child c = shatter::test::start_shatter(
        {"run", scene, "--quiet", "--out", (dir / "out").string(), "--set", "bodies[0].mesh.element_size=0.0002"},
        log);
    // In set-up once the output folder is made (before the meshing); under
    // load the process may take a while to get there.
    for (int i = 0; i < 600 && !fs::exists(dir / "out"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    kill(c.pid, sig);
    EXPECT_EQ(shatter::test::finish(c), 1);
    EXPECT_EQ(file_bytes(log), "error: stopped by signal " + std::to_string(sig) + (sig == SIGINT ? " (SIGINT)" : " (SIGTERM)") +
                                   " during set-up (before step 0): nothing to continue from; run it again\n");
    EXPECT_FALSE(fs::exists(dir / "out" / ".shatter_reserve"));
  }
}

// `shatter plot` on a corrupt history.csv: one line naming the file and the
// line, exit 2 (it printed a Python traceback).
TEST(StrictInput, PlotOfACorruptHistoryNamesTheLine) {
  if (std::system("/usr/bin/python3 -c '' > /dev/null 2>&1") != 0) GTEST_SKIP() << "no /usr/bin/python3";
  const fs::path dir = scratch_dir("strict_plot");
  const std::string header =
      "step,time,dt,kinetic,strain,cohesive_stored,cohesive_dissipated,contact_dissipated,external_work,total,"
      "px,py,pz,Lx,Ly,Lz,contacts,cohesive_elements,fragments,contact_capped_steps\n";
  const std::string row = "0,0,1,1,0,0,0,0,0,1,0,0,0,0,0,0,0,0,1,0\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {header + row + "1,0.1,1,xx\n", "history.csv:3: expected 20 comma-separated values, got 4"},
      {header + row + "1,0.1,1,1,0,0,0,0,0,1,0,0,0,0,0,0,0,0,1,abc\n",
       "history.csv:3: column contact_capped_steps: expected a number, got 'abc'"},
      {header + row + "\xff\xfe garbage\n", "history.csv:3: not text (not UTF-8); expected a CSV row of numbers"},
  };
  for (const auto& [text, message] : cases) {
    std::ofstream(dir / "history.csv", std::ios::binary | std::ios::trunc) << text;
    const auto r = run_shatter("plot " + dir.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_EQ(r.output, "shatter plot: error: " + (dir / "history.csv").string() + message.substr(11) + "\n");
  }
}
