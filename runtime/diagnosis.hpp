#pragma once
// What, where and when of the failures a step detects (docs/errors.md "During
// a run"): the messages name the nodes, bodies, positions and remedies.
#include <span>
#include <string>

#include "contact/candidates.hpp"
#include "contact/dcr.hpp"
#include "runtime/ledger.hpp"
#include "runtime/model.hpp"

namespace shatter {

/// A step whose DCR sweeps reached the cap, when the scene says
/// contact.on_sweep_cap: fail. `step` is the step under way.
std::string sweep_cap_diagnosis(const Model& model, std::span<const Vec3> x, const ContactPairs& pairs,
                                const DcrResult& r, long step, double time);

/// A ledger that is no longer finite at the end of step `step` (a NaN or
/// overflow that has not reached the positions yet).
std::string non_finite_diagnosis(const Model& model, std::span<const Vec3> x, std::span<const Vec3> v,
                                 std::span<const Vec3> a, const Ledger& l, long step, double time);

}  // namespace shatter
