// docs/errors.md against the binary: every row of its tables that gives a
// command is run (SCENE = the page's base scene, DIR = a folder of the bad
// files listed on the page, made here), and the first line the binary prints
// must be the row's message, with the row's exit status. The page is thus
// the exact list of bad-input messages, and stays so.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "runtime/checkpoint.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"

namespace fs = std::filesystem;

namespace {

struct Row {
  std::string what, command, message;
  int status = 0;
};

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

/// The text between the first pair of backticks of a table cell.
std::string code(const std::string& cell) {
  const size_t a = cell.find('`'), b = cell.rfind('`');
  return a == std::string::npos || b <= a ? "" : cell.substr(a + 1, b - a - 1);
}

std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|') {
      cur += '|';
      ++i;
    } else if (line[i] == '|') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += line[i];
    }
  }
  return out;
}

struct Page {
  std::string base_scene;
  std::vector<Row> rows;
};

/// The base scene (the ```yaml block after "Base scene") and the rows
/// | what | `command` | exit | `message` |.
Page read_page(const fs::path& path) {
  std::ifstream in(path);
  Page page;
  std::string line;
  bool in_yaml = false, base_done = false;
  while (std::getline(in, line)) {
    if (!base_done && line == "```yaml") {
      in_yaml = true;
    } else if (in_yaml && line == "```") {
      in_yaml = false;
      base_done = true;
    } else if (in_yaml) {
      page.base_scene += line + "\n";
    } else if (line.rfind("| ", 0) == 0) {
      const std::vector<std::string> c = cells(line);
      if (c.size() != 4 || code(c[1]).rfind("shatter ", 0) != 0) continue;
      page.rows.push_back({c[0], code(c[1]), code(c[3]), std::stoi(c[2])});
    }
  }
  return page;
}

/// The bad files the page's rows refer to as DIR/...
void write_bad_files(const fs::path& dir, const std::string& base_scene) {
  const std::string header = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  std::ofstream(dir / "inverted.msh") << header
                                      << "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0 0 -1\n$EndNodes\n"
                                         "$Elements\n2\n1 4 2 1 1 1 2 3 4\n42 4 2 1 1 2 3 1 5\n$EndElements\n";
  std::ofstream(dir / "flat.msh") << header
                                  << "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n$EndNodes\n"
                                     "$Elements\n1\n7 4 2 1 1 1 2 3 4\n$EndElements\n";
  std::ofstream(dir / "far.msh") << header
                                 << "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1e200\n$EndNodes\n"
                                    "$Elements\n1\n5 4 2 1 1 1 2 3 4\n$EndElements\n";
  std::ofstream(dir / "triangles.msh") << header
                                       << "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                                          "$Elements\n1\n1 2 2 1 1 1 2 3\n$EndElements\n";
  std::ofstream(dir / "garbage.msh") << "this is not a mesh\n";
  // A good tetrahedron with named physical groups: a point, a surface, the volume.
  std::ofstream(dir / "tet.msh") << header
                                 << "$PhysicalNames\n3\n0 1 \"corner\"\n2 2 \"bottom\"\n3 3 \"solid\"\n$EndPhysicalNames\n"
                                    "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"
                                    "$Elements\n3\n1 15 2 1 1 1\n2 2 2 2 2 1 3 2\n3 4 2 3 3 1 2 3 4\n$EndElements\n";
  std::ofstream(dir / "v40.msh") << "$MeshFormat\n4 0 8\n$EndMeshFormat\n";
  std::ofstream(dir / "cut.msh") << header << "$Elements\n2\n1 4 2 1 1 1 2 3 4\n";
  std::ofstream(dir / "unknown_type.msh") << header << "$Elements\n1\n3 777 0 1 2 3\n$EndElements\n";
  std::ofstream(dir / "mixed.msh") << header
                                   << "$Nodes\n10\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0.5 0 0\n6 0.5 0.5 0\n"
                                      "7 0 0.5 0\n8 0 0 0.5\n9 0 0.5 0.5\n10 0.5 0 0.5\n$EndNodes\n"
                                      "$Elements\n2\n1 4 2 1 1 1 2 3 4\n2 11 2 1 1 1 2 3 4 5 6 7 8 9 10\n"
                                      "$EndElements\n";
  // The unit corner tet with the mid-edge node of edge 1-2 moved by (0, 0.3, 0.3).
  std::ofstream(dir / "folded.msh") << header
                                    << "$Nodes\n10\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0.5 0.3 0.3\n6 0.5 0.5 0\n"
                                       "7 0 0.5 0\n8 0 0 0.5\n9 0 0.5 0.5\n10 0.5 0 0.5\n$EndNodes\n"
                                       "$Elements\n1\n3 11 2 1 1 1 2 3 4 5 6 7 8 9 10\n$EndElements\n";
  std::ofstream(dir / "prisms.msh") << header
                                    << "$PhysicalNames\n2\n3 1 \"core\"\n3 2 \"layers\"\n$EndPhysicalNames\n"
                                       "$Nodes\n7\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 -1\n5 0 0 1\n6 1 0 1\n7 0 1 1\n"
                                       "$EndNodes\n$Elements\n2\n1 4 2 1 1 1 3 2 4\n2 6 2 2 2 1 2 3 5 6 7\n"
                                       "$EndElements\n";
  std::ofstream(dir / "model.inp") << "*NODE\n";
  std::ofstream(dir / "garbage.vtk") << "# vtk DataFile Version 2.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                                        "POINTS 4 double\n0 0\n";
  std::ofstream(dir / "bad_yaml.yaml") << "name: x\ntime: [1, 2\n";
  std::ofstream(dir / "list.yaml") << "- name: x\n- time: 1\n";
  std::ofstream(dir / "not_hdf5.h5") << "this is not a checkpoint\n";
  // A checkpoint of another scene over the same mesh.
  std::ofstream(dir / "other.yaml") << replace_all(base_scene, "name: good", "name: other");
  shatter::Model model = shatter::build_model(shatter::load_scene((dir / "other.yaml").string()));
  shatter::Simulation sim(model, {});
  shatter::SimulationState state;
  sim.save_state(state);
  shatter::write_checkpoint(dir / "other.h5", model, state);
  // A run of the base scene stopped after one step, its rows lost.
  fs::create_directories(dir / "run");
  shatter::Model good = shatter::build_model(shatter::load_scene((dir / "scene.yaml").string()));
  shatter::Simulation run(good, {});
  run.step();
  run.save_state(state);
  shatter::write_checkpoint(dir / "run" / "checkpoint.h5", good, state);
  std::ofstream(dir / "run" / "history.csv") << "step,time,dt,kinetic\n";
  std::ofstream(dir / "run" / "bodies.csv") << "step,time,body,mass\n";
  {
    std::string huge = base_scene + "#";
    huge += std::string(shatter::kMaxSceneBytes + 1 - huge.size() - 1, 'x') + "\n";
    std::ofstream(dir / "huge.yaml") << huge;
  }
  std::ofstream(dir / "dup.yaml") << "name: x\ntime: {end: 1}\ntime: {end: 2}\n";
  fs::create_directories(dir / "taken" / "fields.h5");
  fs::create_directories(dir / "device");
  fs::create_symlink("/dev/full", dir / "device" / "fields.h5");
  fs::create_directories(dir / "corrupt_run");
  std::ofstream(dir / "corrupt_run" / "history.csv")
      << "step,time,dt,kinetic,strain,cohesive_stored,cohesive_dissipated,contact_dissipated,external_work,total,"
         "px,py,pz,Lx,Ly,Lz,contacts,cohesive_elements,fragments,contact_capped_steps\n"
         "0,0,1,1,0,0,0,0,0,1,0,0,0,0,0,0,0,0,1,0\n1,0.1,1,xx\n";
}

/// Exit status and first output line of `shatter args` (stdout and stderr).
std::pair<int, std::string> run_shatter(const std::string& args) {
  const std::string cmd = std::string(SHATTER_BINARY_DIR) + "/apps/" + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out.substr(0, out.find('\n'))};
}

}  // namespace

TEST(ErrorsDoc, EveryMessageIsTheBinarys) {
  const Page page = read_page(fs::path(SHATTER_SOURCE_DIR) / "docs" / "errors.md");
  ASSERT_FALSE(page.base_scene.empty()) << "docs/errors.md has no ```yaml base scene";
  ASSERT_GT(page.rows.size(), 30u);
  // One folder per process: the suites of other builds on the machine run this test too.
  const fs::path dir = fs::temp_directory_path() / ("shatter_errors_doc_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "scene.yaml") << page.base_scene;
  write_bad_files(dir, page.base_scene);
  const auto [good_status, good_line] = run_shatter("shatter check " + (dir / "scene.yaml").string());
  ASSERT_EQ(good_status, 0) << "the base scene must be good: " << good_line;
  for (const Row& row : page.rows) {
    const auto expand = [&](const std::string& s) {
      return replace_all(replace_all(s, "SCENE", "DIR/scene.yaml"), "DIR", dir.string());
    };
    const auto [status, line] = run_shatter(expand(row.command));
    EXPECT_EQ(status, row.status) << row.what << ": " << row.command;
    EXPECT_EQ(line, expand(row.message)) << row.what << ": " << row.command;
  }
  fs::remove_all(dir);
}
