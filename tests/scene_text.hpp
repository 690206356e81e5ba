#pragma once
// Scenes written from text for tests: the full loader path is exercised.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "runtime/scene.hpp"

namespace shatter::test {

/// This process's folder of scenes (and the files they name). ctest runs tests
/// side by side, the same test program too (a test alone and under mpiexec):
/// a folder shared by processes let one read a scene while another rewrote it.
/// (The ranks of one run can share rank 0's: pass its process id.)
inline std::filesystem::path scenes_dir(pid_t process = getpid()) {
  const auto dir =
      std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_test_scenes" / std::to_string(process);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Write `yaml` to a file named `name`.yaml in this process's scenes folder; return its path.
inline std::string write_scene(const std::string& name, const std::string& yaml) {
  const auto path = scenes_dir() / (name + ".yaml");
  std::ofstream(path) << yaml;
  return path.string();
}

/// The fragmenting rings' aluminium (scenes/expanding_ring.yaml) as the `materials:` block of
/// one material `alu`; `fracture_extra` is appended inside its fracture map (", scatter: ...").
inline std::string ring_aluminium(const std::string& fracture_extra = "") {
  return "materials:\n"
         "  alu:\n"
         "    model: neo_hookean\n"
         "    density: 2750\n"
         "    youngs_modulus: 275.0e9\n"
         "    poisson_ratio: 0.3\n"
         "    fracture: {strength: 300.0e6, energy: 100.0, beta: 1.0" +
         fracture_extra + "}\n";
}

/// A scene of one steel body named b, run to `end` s, its mesh given by
/// `mesh` (the inside of mesh: {...}); `body` lines (indented by four
/// spaces) are added to the body, `extra` lines at the top level.
inline std::string steel_body_scene(const std::string& name, const std::string& mesh, const std::string& body = "",
                                    const std::string& extra = "", const std::string& end = "1.0") {
  return "name: " + name + "\ntime: {end: " + end +
         "}\n"
         "materials:\n"
         "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
         "bodies:\n"
         "  - name: b\n"
         "    material: steel\n"
         "    mesh: {" +
         mesh + "}\n" + body + extra;
}

/// The scene the command-line tests share: one steel box of 1 cm named b,
/// meshed at `element_size`, run to 1e-6 s (body and extra as above).
inline std::string steel_box_scene(const std::string& name, const std::string& element_size = "0.005",
                                   const std::string& body = "", const std::string& extra = "") {
  return steel_body_scene(name, "shape: box, size: [0.01, 0.01, 0.01], element_size: " + element_size, body, extra,
                          "1.0e-6");
}

/// A steel sphere (radius 10 mm) and a 20 mm steel box beside it, with contact:
/// the contact stage's tests move them into each other.
inline std::string sphere_and_box_contact_scene(const std::string& name) {
  return "name: " + name + "\n"
         "time: {end: 1.0}\n"
         "materials:\n"
         "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
         "bodies:\n"
         "  - {name: a, material: steel, mesh: {shape: sphere, radius: 0.01, element_size: 0.004}}\n"
         "  - {name: b, material: steel, mesh: {shape: box, size: [0.02, 0.02, 0.02], center: [0.021, 0.003, 0], "
         "element_size: 0.004}}\n"
         "contact: {}\n";
}

/// A double as scene text, every bit kept (%.17g).
inline std::string num(double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", a);
  return buf;
}

inline Scene scene_from_text(const std::string& name, const std::string& yaml) {
  return load_scene(write_scene(name, yaml));
}

}  // namespace shatter::test
