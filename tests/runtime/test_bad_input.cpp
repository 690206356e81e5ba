// Bad input never crashes: `shatter check` and `shatter run` exit 2 with a
// message that names the file, the key path and what was expected. One case
// per error class of SCENE.md.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "runtime/model.hpp"
#include "scene_text.hpp"

namespace {

struct Outcome {
  int status;
  std::string output;
};

Outcome run_shatter(const std::string& args) {
  const std::string cmd = std::string(SHATTER_BINARY_DIR) + "/apps/shatter " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 512> buf;
  while (fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

const std::string kGood =
    "name: good\n"
    "time: {end: 1.0e-6}\n"
    "materials:\n"
    "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
    "bodies:\n"
    "  - name: b\n"
    "    material: steel\n"
    "    mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005}\n";

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return s.replace(p, from.size(), to);
}

struct Case {
  const char* name;
  std::string yaml;
  std::vector<std::string> expect;  // substrings of the message
};

}  // namespace

TEST(BadInput, GoodSceneChecksClean) {
  const auto r = run_shatter("check " + shatter::test::write_scene("good", kGood));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("stable dt"), std::string::npos) << r.output;
}

// `shatter check` of order-2 curved shapes: valid (exit 0), and the minimum
// scaled Jacobian it prints is that of the mesh the model holds.
TEST(Check, OrderTwoSphereAndTubeReportTheirMinimumScaledJacobian) {
  const std::string box = "mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005}";
  for (const auto& [name, mesh] :
       {std::pair{"sphere", "mesh: {shape: sphere, radius: 0.01, element_size: 0.004, order: 2}"},
        std::pair{"tube", "mesh: {shape: tube, inner_radius: 0.008, outer_radius: 0.01, length: 0.005, "
                          "element_size: 0.002, order: 2}"}}) {
    SCOPED_TRACE(name);
    const std::string yaml = replaced(kGood, box, mesh);
    const auto r = run_shatter("check " + shatter::test::write_scene(std::string("order2_") + name, yaml));
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string key = "TET10 minimum scaled Jacobian ";
    const size_t at = r.output.find(key);
    ASSERT_NE(at, std::string::npos) << r.output;
    const double printed = std::stod(r.output.substr(at + key.size()));
    const shatter::Model model = shatter::build_model(shatter::test::scene_from_text(name, yaml));
    EXPECT_NEAR(printed, shatter::min_scaled_jacobian(model.mesh).value, 5e-5);
    EXPECT_GT(printed, 0.3);
  }
}

TEST(BadInput, EachErrorClassExitsTwoNamingTheKey) {
  const std::vector<Case> cases = {
      {"unknown_top_key", kGood + "gravty: [0, 0, -9.81]\n", {"gravty", "unknown key"}},
      {"unknown_nested_key", replaced(kGood, "element_size: 0.005", "element_size: 0.005, radus: 1"),
       {"bodies[0].mesh.radus", "unknown key"}},
      {"wrong_type", replaced(kGood, "end: 1.0e-6", "end: soon"), {"time.end", "expected a positive number", "soon"}},
      {"missing_required", replaced(kGood, "density: 7850, ", ""), {"materials.steel.density", "required"}},
      {"negative_density", replaced(kGood, "density: 7850", "density: -7850"),
       {"materials.steel.density", "positive"}},
      {"poisson_out_of_range", replaced(kGood, "poisson_ratio: 0.3", "poisson_ratio: 0.5"),
       {"materials.steel.poisson_ratio", "(-1, 0.5)"}},
      {"unknown_material", replaced(kGood, "material: steel", "material: stell"), {"bodies[0].material"}},
      {"bad_shape", replaced(kGood, "shape: box", "shape: cube"), {"bodies[0].mesh.shape", "box, cylinder"}},
      {"vector_length", replaced(kGood, "size: [0.01, 0.01, 0.01]", "size: [0.01, 0.01]"),
       {"bodies[0].mesh.size", "3 numbers"}},
      {"file_and_shape", replaced(kGood, "mesh: {", "mesh: {file: a.msh, "), {"bodies[0].mesh", "not both"}},
      {"missing_mesh_file", replaced(kGood, "mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005}",
                                     "mesh: {file: nowhere.msh}"),
       {"bodies[0].mesh", "nowhere.msh", "does not exist"}},
      {"empty_bc_region",
       kGood + "boundary_conditions:\n  - {body: b, region: {box: [[5, 5, 5], [6, 6, 6]]}, velocity: [0, null, null]}\n",
       {"boundary_conditions[0].region", "no node"}},
      {"restitution_range", kGood + "contact: {restitution: 1.5}\n", {"contact.restitution", "[0, 1]"}},
      {"hollow_sphere_inner_too_large",
       replaced(kGood, "shape: box, size: [0.01, 0.01, 0.01]", "shape: sphere, radius: 0.01, inner_radius: 0.02"),
       {"bodies[0].mesh.inner_radius", "smaller than radius"}},
      {"max_sweeps_zero", kGood + "contact: {max_sweeps: 0}\n", {"contact.max_sweeps", "integer >= 1"}},
      {"search_margin_negative", kGood + "contact: {search_margin: -0.1}\n", {"contact.search_margin", ">= 0"}},
      {"fracture_check_every_fraction", replaced(kGood, "time: {", "time: {fracture_check_every: 2.5, "),
       {"time.fracture_check_every", "integer >= 1"}},
      {"placement_unknown", kGood + "contact: {placement: start}\n", {"contact.placement", "one of end, middle, impact"}},
      {"invalid_yaml", kGood + "time: [\n", {"not valid YAML"}},
      {"notch_outside_the_box",
       replaced(kGood, "element_size: 0.005}", "element_size: 0.005, notch: {center: [1, 0, 0], size: [0.002, 0.002, 0.02]}}"),
       {"bodies[0].mesh.notch", "cuts into the body"}},
      {"notch_zero_size",
       replaced(kGood, "element_size: 0.005}", "element_size: 0.005, notch: {center: [0, 0, 0], size: [0, 0.002, 0.02]}}"),
       {"bodies[0].mesh.notch.size", "three positive lengths"}},
  };
  for (const Case& c : cases) {
    const std::string path = shatter::test::write_scene(std::string("bad_") + c.name, c.yaml);
    const auto r = run_shatter("check " + path);
    EXPECT_EQ(r.status, 2) << c.name << ": " << r.output;
    EXPECT_NE(r.output.find(path), std::string::npos) << c.name << " does not name the file: " << r.output;
    for (const auto& s : c.expect) EXPECT_NE(r.output.find(s), std::string::npos) << c.name << ": " << r.output;
  }
}

TEST(BadInput, InvertedElementInAMeshFileIsNamed) {
  std::ofstream(shatter::test::scenes_dir() / "inverted.msh")
      << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0 0 -1\n"
         "$EndNodes\n$Elements\n2\n1 4 2 1 1 1 2 3 4\n42 4 2 1 1 2 3 1 5\n$EndElements\n";
  const std::string path = shatter::test::write_scene(
      "inverted", replaced(kGood, "mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005}",
                           "mesh: {file: inverted.msh}"));
  const auto r = run_shatter("check " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("element 42 is inverted"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("bodies[0].mesh"), std::string::npos) << r.output;
}

TEST(BadInput, CommandLineErrors) {
  const std::string path = shatter::test::write_scene("good", kGood);
  auto r = run_shatter("check /nonexistent/scene.yaml");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("/nonexistent/scene.yaml"), std::string::npos) << r.output;
  r = run_shatter("run " + path + " --threads 0");
  EXPECT_EQ(r.status, 2) << r.output;
  r = run_shatter("frobnicate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  r = run_shatter("check " + path + " --set bodies[3].mesh.element_size=1");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("bodies[3]"), std::string::npos) << r.output;
  r = run_shatter("check " + path + " --set time.safety=2");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("time.safety"), std::string::npos) << r.output;
  r = run_shatter("check " + path + " --set time.safety=0.3");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("safety 0.30"), std::string::npos) << r.output;
}
