#pragma once
// The shatter binary run from a test: exit status and output, and files
// read whole, so that a test can check what a command printed and that the
// files it must not touch are byte for byte as they were.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

/// A shatter process started in the background (start_shatter).
struct Child {
  pid_t pid = -1;
  std::filesystem::path log;
};

/// Starts the shatter binary with `args`, stdout and stderr to `log`.
inline Child start_shatter(const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<std::string> argv{std::string(SHATTER_BINARY_DIR) + "/apps/shatter"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> cargv;
  for (auto& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  Child c;
  c.log = log;
  EXPECT_EQ(posix_spawn(&c.pid, cargv[0], &actions, nullptr, cargv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  return c;
}

/// Waits for the child; returns its exit status (-1 when ended by a signal).
inline int finish(const Child& c) {
  int st = 0;
  EXPECT_EQ(waitpid(c.pid, &st, 0), c.pid);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
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
