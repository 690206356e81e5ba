#pragma once
// Stable time step of the subdivision shell element (kernels/shell_kl.hpp)
// under central differences with the lumped mass: dt <= 2 / omega_max.
//
// A flat plate carries two families of waves (linearised, decoupled):
//  - membrane (in-plane P) waves, omega = c k, with the plate wave speed
//    c = sqrt(E / (rho (1 - nu^2)));
//  - flexural waves, omega = sqrt(D / (rho t)) k^2 = c t k^2 / sqrt(12),
//    D = E t^3 / (12 (1 - nu^2)): dispersive, so their largest frequency
//    grows as 1/h^2 instead of 1/h.
// On a mesh of element length h the largest resolved wave number is ~1/h,
// so omega_m,max = kappa_m c / h and omega_b,max = kappa_b c t / h^2, and
// omega_max^2 <= omega_m,max^2 + omega_b,max^2 gives
//   dt = 2 h / (c sqrt(kappa_m^2 + kappa_b^2 (t / h)^2)),
// the membrane bound h/c for t << h and the bending bound ~ h^2 / (t c) for
// t >~ h. h is the smallest altitude of the control triangle. The kappas
// were measured as the largest eigenvalue of M^-1 K (K from the exact
// forces, M lumped, 3-point quadrature) on regular lattices
// (tests/kernels/test_shell_stable_dt.cpp, docs/shells.md): equilateral,
// extrapolated to an infinite lattice, kappa_m = 1.035, kappa_b = 0.667,
// independent of nu; a sheared lattice (angles 43, 67, 70 deg; 14 x 14) 1.069 and 0.677.
// The constants below cover them with margin (10 % on the equilateral lattice).
#include <algorithm>
#include <cmath>

#include "kernels/neo_hookean.hpp"

namespace shatter {

inline constexpr double kShellMembraneKappa = 1.15;
inline constexpr double kShellBendingKappa = 0.75;

/// Plate (membrane P-wave) speed sqrt(E / (rho (1 - nu^2))) of the
/// undeformed material, m/s; E / (1 - nu^2) = 4 mu (lambda + mu) / (lambda + 2 mu).
inline double shell_wave_speed(const NeoHookean& m) {
  return std::sqrt(4.0 * m.mu * (m.lambda + m.mu) / ((m.lambda + 2.0 * m.mu) * m.density));
}

/// Smallest altitude of the triangle (a, b, c) = 2 area / longest edge, m.
inline double shell_stable_length(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double twice_area = (b - a).cross(c - a).norm();
  const double longest_sq = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return twice_area / std::sqrt(longest_sq);
}

/// Stable step of a shell element of length h (shell_stable_length) and
/// thickness t, s; the runtime multiplies it by its safety factor.
inline double shell_stable_dt(double h, double thickness, const NeoHookean& mat) {
  const double r = kShellBendingKappa * thickness / h;
  return 2.0 * h / (shell_wave_speed(mat) * std::sqrt(kShellMembraneKappa * kShellMembraneKappa + r * r));
}

}  // namespace shatter
