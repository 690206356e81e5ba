#pragma once
// The energy and momentum ledger of a run (SCENE.md, history.csv).
#include "kernels/types.hpp"

namespace shatter {

/// The energy and momentum ledger of SCENE.md (history.csv columns), SI units.
struct Ledger {
  double kinetic = 0, strain = 0, cohesive_stored = 0, cohesive_dissipated = 0, contact_dissipated = 0,
         external_work = 0;
  Vec3 momentum = Vec3::Zero();          ///< kg m/s
  Vec3 angular_momentum = Vec3::Zero();  ///< about the origin, kg m^2/s
  long contacts = 0, cohesive_elements = 0, fragments = 0;
  long contact_capped_steps = 0;  ///< steps whose DCR sweeps hit the cap (extra history column)
  /// kinetic + strain + cohesive_stored + cohesive_dissipated + contact_dissipated - external_work
  double total() const {
    return kinetic + strain + cohesive_stored + cohesive_dissipated + contact_dissipated - external_work;
  }
};

}  // namespace shatter
