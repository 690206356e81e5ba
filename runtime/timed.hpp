#pragma once
// Wall-time and CPU-time accounting of the stages of a run (summary.json's times).
#include <time.h>

#include <chrono>

namespace shatter {

/// Runs f and adds its wall time to `seconds`.
template <class F>
void timed(double& seconds, F f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// This thread's CPU time, s.
inline double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// Runs f, adds its wall time to `seconds` and the calling thread's CPU time to `cpu`, and
/// returns what f returns.
template <class F>
decltype(auto) timed(double& seconds, double& cpu, F f) {
  struct Clock {
    double &seconds, &cpu;
    std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
    double cpu0 = thread_cpu_seconds();
    ~Clock() {
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      cpu += thread_cpu_seconds() - cpu0;
    }
  } clock{seconds, cpu};
  return f();
}

}  // namespace shatter
