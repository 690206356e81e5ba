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
  for (Index e : dec_->owned_element_ids()) {
    const double dt = element_stable_step(model_, x_, e).dt;
    // Ascending local ids ascend in the whole model too: the first of a tie is the smallest.
    if (dt < least.dt) least = {dt, static_cast<int>(model_.whole_element(e))};
  }
  if (dec_->distributed()) MPI_Allreduce(MPI_IN_PLACE, &least, 1, MPI_DOUBLE_INT, MPI_MINLOC, dec_->comm());
  StepCollapse c;
  c.dt = stable_dt_;
  c.dt0 = stable_dt0_;
  // A shell element set the step: no tetrahedron to name.
  if (least.e == std::numeric_limits<int>::max() || dec_->min(last_shells_.stable_dt) < least.dt) throw PhysicsError(step_collapse_diagnosis(model_, c, step, time));
  // Its owner has its current positions and its part of the mesh.
  throw PhysicsError(from_owner(least.e, [&](Index e) {
    c.element = e;
    c.element_dt = least.dt;
    for (int a = 0; a < 4; ++a) c.centre += 0.25 * x_[model_.mesh.element(e)[a]];
    c.J = element_stable_step(model_, x_, e).J;
    return step_collapse_diagnosis(model_, c, step, time);
  }));
}

std::string Simulation::from_owner(Index whole, const std::function<std::string(Index)>& what) const {
  if (whole < 0) return "";
  const int owner = dec_->granule_rank(whole / ElementForces::kGranule);
  std::string text;
  if (owner == dec_->rank()) {
    const Index e = model_.local_element(whole);
    SHATTER_REQUIRE(e >= 0, "from_owner: element " << whole << " is not held by its owner");
    text = what(e);
  }
  return dec_->broadcast(std::move(text), owner);
}

void Simulation::check_ledger() {
  if (ledger_.largest() <= kEnergyOverflow) return;
  const std::string why = ledger_diagnosis(kEnergyOverflow, model_, x_, v_, a_, ledger_, step_, time_);
  // In the initial state (the constructor's ledger) only the scene can be the cause.
  if (step_ == 0) throw InputError(model_.scene.file + ": " + why);
  throw PhysicsError(why);
}

}  // namespace shatter
