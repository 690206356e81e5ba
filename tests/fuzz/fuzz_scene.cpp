// Fuzz entry for the scene loader (issue 8, "Hardening"): any bytes as a scene
// file's text. Leading lines "#set key.path=value" (YAML comments) are also
// passed as --set overrides, so the key-path walker is fuzzed too. The only
// acceptable failure is shatter::InputError (exit 2 in the CLI); any other
// exception escapes and aborts, and the sanitizers catch memory errors.
// Built as a libFuzzer binary by the fuzz preset and as a replay test of the
// seeds and crashes in every build (replay_main.cpp, ctest label fuzz).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "kernels/error.hpp"
#include "runtime/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  for (std::size_t at = 0; text.compare(at, 5, "#set ") == 0;) {
    const std::size_t end = text.find('\n', at);
    overrides.push_back(text.substr(at + 5, end == std::string::npos ? std::string::npos : end - at - 5));
    if (end == std::string::npos) break;
    at = end + 1;
  }
  try {
    shatter::parse_scene(text, "fuzz/scene.yaml", overrides);
  } catch (const shatter::InputError&) {
  }
  return 0;
}
