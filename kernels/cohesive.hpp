#pragma once
// Extrinsic Ortiz-Pandolfi cohesive law (G. T. Camacho, M. Ortiz, "Computational
// modelling of impact damage in brittle materials", IJSS 33 (1996)
// 2899-2938; M. Ortiz, A. Pandolfi, "Finite-deformation irreversible
// cohesive elements for three-dimensional crack-propagation analysis", IJNME
// 44 (1999) 1267-1282, eqs. 20-27): a facet is rigid until the criterion
// breaks it, and its traction then starts where the facet was, at the
// strength sigma_c, and softens.
//
// With the opening vector Delta (m) split along the unit facet normal n into
//   delta_n = Delta . n,  delta_s = Delta - delta_n n   (vector),
// the effective opening is  delta = sqrt(beta^2 |delta_s|^2 + <delta_n>^2)  and
// the traction (Pa) derives from a potential phi(delta, delta_max):
//   T = (t / delta) (beta^2 delta_s + <delta_n> n),
// so that T . dDelta = t d(delta) along any path. The state is the largest
// effective opening reached, delta_max. The effective traction is
//   loading   (delta >= delta_max): t = envelope(delta) = sigma_c <1 - delta / delta_c>,
//   unloading (delta <  delta_max): t = envelope(delta_max) delta / delta_max,
// the secant to the origin (Ortiz and Pandolfi), delta_c = 2 Gc / sigma_c.
// Either way t / delta = envelope(delta_max) / delta_max: the point is a
// linear spring whose stiffness the opening can only lower. The work of
// separation is the area under the envelope, sigma_c delta_c / 2 = Gc
// (J/m^2), for every mode mixity.
//
// Stability. The secant's slope envelope(delta_max) / delta_max is unbounded
// as delta_max -> 0. With K = min(k_p, secant) the traction is the sum of
//   (i)  a linear part K (beta^2 delta_s + <delta_n> n), of stiffness at most
//        max(1, beta^2) k_p, plus the penalty k_p in compression: the
//        stiffness the stable step includes (cohesive_stiffness_bound);
//   (ii) the rest, (secant - K) delta along the opening direction on
//        unloading and the softening envelope less (i) on loading: at most
//        envelope(delta_max) - K delta_max <= sigma_c, times max(1, beta).
// Part (ii) is stiffer than the step resolves where delta_max < delta_u =
// sigma_c / (k_p + sigma_c / delta_c), but it acts only while delta <=
// delta_max and its force is bounded: an oscillation it excites cannot grow
// past delta_max without loading the point (delta_max grows and the secant
// falls), so it ends as damage, not as a growing solution
// (CohesiveLaw.ReclosedPointSettlesUnderCentralDifference).
// Until session 19 the unloading slope was capped at k_p (a line t_0 + K
// delta with t_0 > 0 at delta = 0, a cone at the origin): exact for energy
// too, but its force flips wherever the opening passes the cone's tip, and a
// closed point sheared back and forth by a passing wave (delta = beta
// |delta_s| in compression) gained energy at every flip: 2.6 % of the
// energy on the 1e3 /s structured ring, 0.35 % with the secant
// (docs/validation.md, "Where the 1e3 /s ring's energy gain comes from").
// The secant is linear on unloading, which central difference integrates
// with no energy error (the trapezoid rule is exact for it).
// At Delta = 0 with delta_max = 0 (a facet just inserted: its two sides
// coincide) the direction of the opening is undefined; the traction is
// sigma_c n, the subgradient of the cone phi ~ sigma_c delta along the normal:
// the facet pulls with the strength it broke at, so the bulk's work on the
// first opening is taken out as the law's dissipation counts it (with 0
// there, the ledger gained sigma_c delta_1 per unit area at every insertion,
// delta_1 the first step's opening: +0.6 % of the external work on the
// alumina bar).
//
// Compression (delta_n < 0): the cohesive law acts on the shear part only
// (delta = beta |delta_s|) and interpenetration is resisted by a linear normal
// penalty T_n = k_p delta_n n with stiffness k_p (Pa/m): k_p = E / h
// (runtime/fracture_stage.cpp), as stiff as the adjacent elements, not a
// user knob. Crack faces that part meet through contact (DCR) once freed.
//
// A point comes apart: once it has opened past delta_c and is then not in
// compression (delta_n >= 0), it exerts nothing from then on, not even the
// penalty (state delta_max = kPointApart). Its opening may grow to many
// element sizes while another point of the facet still holds (a chip hanging
// by a corner), where the mid-surface of the two sides' corners defines no
// normal: its area fell to 4e-5 of the facet's on the 1e3 /s structured ring,
// and the penalty's turning-normal force, dphi/dn over that area
// (cohesive_forces), reached 2e5 sigma_c A and inverted an element
// (docs/validation.md). It comes apart only while not compressed, so the
// penalty holds no energy when it stops acting. A facet whose every point
// has come apart is freed (release_debonded).
//
// Energies per unit reference area (J/m^2):
//   stored     = envelope(delta_max) delta^2 / (2 delta_max) + k_p <-delta_n>^2 / 2
//                (recoverable: the triangle under the secant, plus the penalty)
//   dissipated = W(delta_max) - stored(delta_max) = sigma_c delta_max / 2
//                before delta_c, Gc past it,
// where W(delta_max) is the area under the envelope up to delta_max.
#include <algorithm>
#include <cmath>
#include <limits>

#include "kernels/error.hpp"
#include "kernels/types.hpp"

namespace shatter {

/// Parameters of the extrinsic Ortiz-Pandolfi law. Build with `make_cohesive_law`.
struct CohesiveLaw {
  double sigma_c = 0;  ///< cohesive strength, Pa
  double delta_c = 0;  ///< critical effective opening 2 Gc / sigma_c, m
  double beta = 1;     ///< shear-to-normal weighting, dimensionless
  double penalty = 0;  ///< k_p, Pa/m: the normal stiffness in compression, and the split of the secant (top of this file)

  /// Fracture energy Gc = sigma_c delta_c / 2, J/m^2.
  double fracture_energy() const { return 0.5 * sigma_c * delta_c; }
};

/// sigma_c (Pa), Gc (J/m^2), beta (-), penalty k_p (Pa/m), all positive; any
/// such values make a law.
inline CohesiveLaw make_cohesive_law(double sigma_c, double fracture_energy, double beta,
                                     double penalty) {
  SHATTER_ASSERT(sigma_c > 0 && fracture_energy > 0 && beta > 0 && penalty > 0);
  return CohesiveLaw{sigma_c, 2.0 * fracture_energy / sigma_c, beta, penalty};
}

/// The same law with another strength and the same Gc (delta_c = 2 Gc / sigma_c):
/// a facet's own strength under strength scatter.
inline CohesiveLaw with_strength(const CohesiveLaw& law, double sigma_c) {
  return make_cohesive_law(sigma_c, law.fracture_energy(), law.beta, law.penalty);
}

/// Effective traction on the loading envelope, Pa: sigma_c (1 - delta / delta_c), 0 past delta_c.
inline double cohesive_envelope(const CohesiveLaw& law, double delta) {
  return law.sigma_c * std::max(0.0, 1.0 - delta / law.delta_c);
}

/// Stiffness t / delta of a point in state delta_max, Pa/m: the secant
/// envelope(delta_max) / delta_max (0 past delta_c), for loading and
/// unloading alike. Unbounded as delta_max -> 0; only delta_max > 0.
inline double cohesive_secant_stiffness(const CohesiveLaw& law, double delta_max) {
  return cohesive_envelope(law, delta_max) / delta_max;
}

/// Upper bound of the stiffness of the linear part (i) of the traction, Pa/m:
/// max(1, beta^2) k_p (K = min(k_p, secant) in every direction, and the
/// compression penalty). The rest of the traction is bounded by
/// max(1, beta) sigma_c (see the top of this file).
inline double cohesive_stiffness_bound(const CohesiveLaw& law) {
  return std::max(1.0, law.beta * law.beta) * law.penalty;
}

/// delta_max of a point that has come apart (see the top of this file): it
/// exerts no traction and no penalty, and has dissipated Gc.
inline constexpr double kPointApart = std::numeric_limits<double>::infinity();

/// Result of one evaluation of the law at one point of a cohesive surface.
struct CohesiveTraction {
  Vec3 traction;  ///< T, Pa, acting on side 1 against the opening (side 0 gets -T)
  /// dphi/dn, J/m^2: the derivative of the energy density phi(Delta, n) with
  /// respect to the unit normal at fixed opening and state,
  /// c Delta with c = (t/delta) (<delta_n> - beta^2 delta_n) + k_p min(delta_n, 0);
  /// zero for beta = 1 in tension. Where n follows the deformation, the force
  /// of this term (cohesive_forces) balances the torque Delta x T = -n x dphi/dn
  /// (phi is invariant under rotations of both).
  Vec3 dphi_dn;
  double delta_max;   ///< updated state: largest effective opening reached, m, or kPointApart
  double stored;      ///< recoverable energy density, J/m^2
  double dissipated;  ///< dissipated energy density up to delta_max, J/m^2
};

/// Traction of the law for opening `opening` = x(side 1) - x(side 0) (m),
/// unit normal `n` pointing from side 0 to side 1, previous state
/// `delta_max` (m). Pure; the caller stores the returned state.
inline CohesiveTraction cohesive_traction(const CohesiveLaw& law, const Vec3& opening,
                                          const Vec3& n, double delta_max) {
  const double delta_n = opening.dot(n);
  const Vec3 delta_s = opening - delta_n * n;
  const double beta2 = law.beta * law.beta;
  const double open_n = std::max(delta_n, 0.0);  // only tension opens
  const double delta = std::sqrt(beta2 * delta_s.squaredNorm() + open_n * open_n);

  CohesiveTraction out;
  if (delta_max == kPointApart)
    return {Vec3::Zero(), Vec3::Zero(), kPointApart, 0.0, law.fracture_energy()};
  const double dm = std::max(delta, delta_max);
  out.delta_max = dm;
  // t / delta: the secant, for loading (delta = dm) and unloading alike.
  const double t_over_delta = dm > 0 ? cohesive_secant_stiffness(law, dm) : 0.0;
  out.traction = t_over_delta * (beta2 * delta_s + open_n * n);
  // Just inserted (Delta = 0, no state: its sides still together): the
  // traction it carried at the strength, along the normal.
  if (dm == 0 && delta_n == 0) out.traction = law.sigma_c * n;
  out.stored = 0.5 * t_over_delta * delta * delta;
  // phi(Delta, n) depends on n through delta_n = Delta . n and |delta_s|^2 =
  // |Delta|^2 - delta_n^2: dphi/dn = (t/delta (<delta_n> - beta^2 delta_n)
  // + k_p min(delta_n, 0)) Delta.
  double c = t_over_delta * (open_n - beta2 * delta_n);
  if (delta_n < 0) {
    out.traction += law.penalty * delta_n * n;
    out.stored += 0.5 * law.penalty * delta_n * delta_n;
    c += law.penalty * delta_n;
  }
  out.dphi_dn = c * opening;
  // Past delta_c and not compressed: no traction (t = 0) and no penalty now, none from now on.
  if (dm >= law.delta_c && delta_n >= 0) out.delta_max = kPointApart;
  out.dissipated = dm >= law.delta_c ? law.fracture_energy() : 0.5 * law.sigma_c * dm;
  return out;
}

}  // namespace shatter
