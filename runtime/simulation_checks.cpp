// Failures a step detects besides an inverted element (compute_forces): a
// collapsed stable step and an energy ledger that is not finite or beyond
// kEnergyOverflow. Each throws Error with what, where and when (diagnosis.hpp);
// run() then checkpoints the last good state (simulation_run.cpp).
#include <cmath>
#include <limits>

#include "kernels/error.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/diagnosis.hpp"
#include "runtime/simulation.hpp"

namespace shatter {

void Simulation::check_step_collapse(long step, double time) {
  if (!(stable_dt0_ > 0) || stable_dt_ >= kStepCollapse * stable_dt0_) return;
  // The element with the smallest stable step: over the owned elements, then
  // over the ranks (the smallest index on a tie, as on one rank).
  struct {
    double dt;
    int e;
  } least{HUGE_VAL, std::numeric_limits<int>::max()};
  const Index ne = model_.mesh.num_elements();
  for (Index e = 0; e < ne; ++e)
    if (dec_->owns_element(e)) {
      const double dt = element_stable_step(model_, x_, e).dt;
      if (dt < least.dt) least = {dt, static_cast<int>(e)};
    }
  if (dec_->distributed()) MPI_Allreduce(MPI_IN_PLACE, &least, 1, MPI_DOUBLE_INT, MPI_MINLOC, dec_->comm());
  StepCollapse c;
  c.dt = stable_dt_;
  c.dt0 = stable_dt0_;
  if (least.e != std::numeric_limits<int>::max()) {
    c.element = least.e;
    c.element_dt = least.dt;
    // Its owner has its current positions.
    double where[4] = {0, 0, 0, 0};
    if (dec_->owns_element(c.element)) {
      for (int a = 0; a < 4; ++a) c.centre += 0.25 * x_[model_.mesh.element(c.element)[a]];
      where[0] = c.centre.x(), where[1] = c.centre.y(), where[2] = c.centre.z();
      where[3] = element_stable_step(model_, x_, c.element).J;
    }
    dec_->broadcast({where, 4}, dec_->granule_rank(c.element / ElementForces::kGranule));
    c.centre = Vec3(where[0], where[1], where[2]);
    c.J = where[3];
  }
  throw Error(step_collapse_diagnosis(model_, c, step, time));
}

void Simulation::check_ledger() {
  if (ledger_.largest() <= kEnergyOverflow) return;
  const std::string why = ledger_diagnosis(kEnergyOverflow, model_, x_, v_, a_, ledger_, step_, time_);
  // In the initial state (the constructor's ledger) only the scene can be the cause.
  if (step_ == 0) throw InputError(model_.scene.file + ": " + why);
  throw Error(why);
}

}  // namespace shatter
