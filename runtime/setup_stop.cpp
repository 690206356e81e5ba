#include "runtime/setup_stop.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>

#include "runtime/disk_reserve.hpp"

namespace shatter {
namespace {

volatile std::sig_atomic_t g_rank = -1;  // -1: not known yet

/// The rank a launcher gives a process before MPI_Init (Open MPI, MPICH /
/// PMI); -1 when run without one.
int launcher_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
    if (const char* v = std::getenv(name)) return std::atoi(v);
  return -1;
}

void write_text(const char* s) {
  ssize_t ignored = ::write(STDERR_FILENO, s, std::strlen(s));
  (void)ignored;
}

// Only async-signal-safe calls: write, unlink, _exit.
void stop_during_setup(int sig) {
  if (g_rank <= 0) {
    write_text(sig == SIGINT ? "error: stopped by signal 2 (SIGINT)" : "error: stopped by signal 15 (SIGTERM)");
    write_text(" during set-up (before step 0): nothing to continue from; run it again\n");
  }
  const char* reserve = disk_reserve_path();
  if (reserve[0] != '\0') ::unlink(reserve);
  ::_exit(kSetupStopStatus);
}

}  // namespace

void install_setup_stop_handlers() {
  if (g_rank < 0) g_rank = launcher_rank();
  struct sigaction sa {};
  sa.sa_handler = stop_during_setup;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

void set_setup_stop_rank(int rank) {
  g_rank = rank;
}

void ignore_stop_signals() {
  std::signal(SIGINT, SIG_IGN);
  std::signal(SIGTERM, SIG_IGN);
}

}  // namespace shatter
