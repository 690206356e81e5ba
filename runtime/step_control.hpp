#pragma once
// The adaptive time step's controller (docs/physics.md "Step control").
#include <cmath>

namespace shatter {

/// Control of the adaptive step (docs/physics.md "Step control"). Central
/// difference is symplectic at a fixed step; a step re-evaluated from the
/// state every step follows the vibration of the element that sets it, and
/// the map is no longer symplectic: the energy drifts (Skeel, BIT 33 (1993)
/// 172; Calvo & Sanz-Serna, SIAM J. Sci. Comput. 14 (1993) 936; Hairer,
/// Lubich & Wanner, Geometric Numerical Integration, 2nd ed. 2006, sec. VIII.1).
/// So the step is held constant and changes only
///   - down, when the safe step (safety x stable step of the state at the
///     start of a step) falls below it: to kHeadroom x the safe step, so a
///     vibration of the safe step by less than the headroom does not move it
///     again (the step is then the running minimum of the safe step, less the
///     headroom: a monotone sequence);
///   - up, at the end of a window of kWindow steps (counted from the last
///     change or window) in which the safe step stayed above dt / kHeadroom:
///     to min(kGrowth x dt, kHeadroom x the window's smallest safe step).
/// The step taken is never above the safe step. Each change shifts the
/// modified energy that a fixed step conserves by O(omega^2 |d(dt^2)|); a
/// monotone sequence of drops shifts it by at most O(omega^2 dt0^2) in all and
/// growth happens at most once per kWindow steps, so the energy error stays
/// bounded instead of drifting. The state is deterministic (the safe step is
/// a minimum over all ranks) and is part of a checkpoint.
struct StepControl {
  static constexpr double kHeadroom = 0.95;
  static constexpr long kWindow = 1000;
  static constexpr double kGrowth = 1.1;

  double dt = 0;                 ///< s: the step held
  double window_min = HUGE_VAL;  ///< s: smallest safe step in the current window
  long window_steps = 0;         ///< steps in the current window

  /// The step to take from a state whose safe step is `safe` (s); advances
  /// the controller. The first call (dt = 0) takes the safe step.
  double next(double safe);
};

}  // namespace shatter
