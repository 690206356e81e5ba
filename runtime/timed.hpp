#pragma once
// Wall-time accounting of the stages of a run (summary.json's times).
#include <chrono>

namespace shatter {

/// Runs f and adds its wall time to `seconds`.
template <class F>
void timed(double& seconds, F f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace shatter
