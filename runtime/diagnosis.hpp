#pragma once
// What, where and when of the failures a step detects (docs/errors.md "During
// a run"): the messages name the nodes, bodies, positions and remedies.
#include <optional>
#include <span>
#include <string>

#include "contact/candidates.hpp"
#include "contact/dcr.hpp"
#include "runtime/contact_stage.hpp"
#include "runtime/ledger.hpp"
#include "runtime/model.hpp"

namespace shatter {

/// A step whose DCR sweeps reached the cap, when the scene says
/// contact.on_sweep_cap: fail; `pair`: the first pair left penetrating
/// (ContactStage::unresolved). `step` is the step under way.
std::string sweep_cap_diagnosis(const Model& model, const std::optional<UnresolvedPair>& pair, long step,
                                double time);

/// The stable step of a step's configuration and the element that sets it
/// (Simulation::check_step_collapse).
struct StepCollapse {
  double dt = 0, dt0 = 0;    ///< s: the stable step now and of the initial state
  Index element = -1;        ///< local index of the element with the smallest stable step
  double element_dt = 0, J = 0;  ///< s, and its det F
  Vec3 centre = Vec3::Zero();    ///< its centre, m
};

/// A stable step below Simulation::kStepCollapse of the initial one: the
/// element that sets it, its body, where it is, its det F, and the likely
/// cause: the boundary conditions that drive its nodes, or its compression.
std::string step_collapse_diagnosis(const Model& model, const StepCollapse& c, long step, double time);

/// A ledger that is no longer finite, or whose largest term is beyond
/// `overflow` J, at the end of step `step` (a NaN or overflow that has not
/// reached the positions yet): the node whose velocity or acceleration is not
/// finite, else the fastest node. Step 0 (the initial state): the message of
/// an InputError, without the step.
std::string ledger_diagnosis(double overflow, const Model& model, std::span<const Vec3> x, std::span<const Vec3> v,
                                 std::span<const Vec3> a, const Ledger& l, long step, double time);

}  // namespace shatter
