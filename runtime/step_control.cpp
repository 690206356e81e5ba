#include "runtime/step_control.hpp"

#include <algorithm>

namespace shatter {

double StepControl::next(double safe) {
  if (dt > 0 && safe >= dt) {
    window_min = std::min(window_min, safe);
    if (++window_steps < kWindow) return dt;
    // The end of a window of kWindow steps at this step.
    dt = std::max(dt, std::min(kGrowth * dt, kHeadroom * window_min));
  } else {
    dt = dt > 0 ? kHeadroom * safe : safe;
  }
  window_min = HUGE_VAL;
  window_steps = 0;
  return dt;
}

}  // namespace shatter
