#pragma once
// The central difference's drift, x(n+1) = x(n) + dt v(n+1/2), as one
// expression: the time loop makes every deformable node's x(n+1) with it
// (Simulation::predict), and a contact patch remakes the x(n+1) of the nodes
// whose velocity alone it receives (ContactPatch::exchange). With no
// contraction (CMakeLists.txt) both give the owner's bits only while they are
// this same expression.
#include "kernels/types.hpp"

namespace shatter {

inline Vec3 drift(const Vec3& x, double dt, const Vec3& v) { return x + dt * v; }

}  // namespace shatter
