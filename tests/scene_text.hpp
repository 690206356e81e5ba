#pragma once
// Scenes written from text for tests: the full loader path is exercised.
#include <filesystem>
#include <fstream>
#include <string>

#include "runtime/scene.hpp"

namespace shatter::test {

/// Write `yaml` to a file named `name`.yaml in a test folder; return its path.
inline std::string write_scene(const std::string& name, const std::string& yaml) {
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_test_scenes";
  std::filesystem::create_directories(dir);
  const auto path = dir / (name + ".yaml");
  std::ofstream(path) << yaml;
  return path.string();
}

inline Scene scene_from_text(const std::string& name, const std::string& yaml) {
  return load_scene(write_scene(name, yaml));
}

}  // namespace shatter::test
