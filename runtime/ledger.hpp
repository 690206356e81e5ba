#pragma once
// The energy and momentum ledger of a run (SCENE.md, history.csv).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

/// The energy and momentum ledger of SCENE.md (history.csv columns), SI units.
/// contact_dissipated: the kinetic energy the contact impulses and friction took out of
/// the mid-step velocities (DcrResult::dissipated), >= 0 every step, so it never decreases.
/// contact_work: the signed first-order energy the contact's changes dx of x(n+1) and dv
/// of v(n+1/2) took out of the central-difference energy, sum f(n+1) . (dx - dt/2 dv)
/// (docs/contact.md, "The ledger with e < 1"), plus the kinetic energy the projections'
/// angular-momentum counterpart took out (DcrResult::work); > 0 when they removed energy.
struct Ledger {
  double kinetic = 0, strain = 0, cohesive_stored = 0, cohesive_dissipated = 0, contact_dissipated = 0,
         contact_work = 0, external_work = 0;
  Vec3 momentum = Vec3::Zero();          ///< kg m/s
  Vec3 angular_momentum = Vec3::Zero();  ///< about the origin, kg m^2/s
  long contacts = 0, cohesive_elements = 0, fragments = 0;
  long contact_capped_steps = 0;  ///< steps whose DCR sweeps hit the cap (extra history column)
  /// kinetic + strain + cohesive_stored + cohesive_dissipated + contact_dissipated + contact_work
  /// - external_work
  double total() const {
    return kinetic + strain + cohesive_stored + cohesive_dissipated + contact_dissipated + contact_work -
           external_work;
  }
  /// The largest magnitude of the energy terms, J; NaN when one is NaN.
  double largest() const {
    double m = 0;
    for (double e : {kinetic, strain, cohesive_stored, cohesive_dissipated, contact_dissipated, contact_work,
                     external_work}) {
      if (std::isnan(e)) return e;
      m = std::max(m, std::abs(e));
    }
    return m;
  }
};

/// The header of history.csv: SCENE.md's columns in its order, then contact_capped_steps.
inline const std::vector<std::string>& history_columns() {
  static const std::vector<std::string> columns{
      "step",  "time", "dt", "kinetic", "strain", "cohesive_stored", "cohesive_dissipated", "contact_dissipated",
      "contact_work", "external_work", "total", "px", "py", "pz", "Lx", "Ly", "Lz", "contacts",
      "cohesive_elements", "fragments", "contact_capped_steps"};
  return columns;
}

}  // namespace shatter
