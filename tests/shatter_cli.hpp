#pragma once
// The shatter binary run from a test: exit status and output, and files
// read whole, so that a test can check what a command printed and that the
// files it must not touch are byte for byte as they were.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace shatter::test {

struct CliOutcome {
  int status = -1;     ///< exit status; -1 when ended by a signal
  std::string output;  ///< stdout and stderr
  std::string first_line() const { return output.substr(0, output.find('\n')); }
};

/// Runs `shatter args` (args as a shell would split them) in the build's apps/.
inline CliOutcome run_shatter(const std::string& args) {
  const std::string cmd = std::string(SHATTER_BINARY_DIR) + "/apps/shatter " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  CliOutcome r;
  std::array<char, 4096> buf;
  while (fgets(buf.data(), buf.size(), p)) r.output += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// The bytes of a file ("" when it cannot be read).
inline std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

/// A fresh, empty folder under the build's test_scratch/.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace shatter::test
