#pragma once
// Ortiz-Pandolfi cohesive law (M. Ortiz, A. Pandolfi, "Finite-deformation
// irreversible cohesive elements for three-dimensional crack-propagation
// analysis", IJNME 44 (1999) 1267-1282, eqs. 20-27), extrinsic form: the
// element is rigid until inserted, so loading starts at t = sigma_c.
//
// With the opening vector Delta (m) split along the unit facet normal n into
//   delta_n = Delta . n,  delta_s = Delta - delta_n n   (vector),
// the effective opening is  delta = sqrt(beta^2 |delta_s|^2 + delta_n^2)  and
// the traction (Pa) derives from a potential phi(delta, delta_max):
//   T = (t / delta) (beta^2 delta_s + delta_n n),
// so that T . dDelta = t d(delta) along any path. The effective traction is
//   loading   (delta >= delta_max): t = envelope(delta)
//   unloading (delta <  delta_max): t = envelope(delta_max) / delta_max * delta
//                                   (secant to the origin)
// with the envelope
//   t = k_p delta                                 for delta <= delta_0,
//   t = sigma_c (delta_c - delta) / (delta_c - delta_0)  up to delta_c, 0 past it,
// delta_c = 2 Gc / sigma_c and delta_0 = sigma_c / k_p. The work of separation
// is the area of this triangle, sigma_c delta_c / 2 = Gc (J/m^2), for every
// mode mixity. The state is the largest effective opening reached.
//
// The short elastic rise to sigma_c (delta_0 / delta_c = sigma_c^2 / (2 Gc
// k_p), 2 % on the fine expanding ring and 4 % on the coarse one) replaces the rigid start of the purely
// extrinsic law, whose secant sigma_c / delta_max is unbounded as
// delta_max -> 0: a facet that recloses just after insertion then acts as an
// arbitrarily stiff spring on its nodes, which no time step integrates stably
// (measured 10-100 x beyond the limit on the fine ring, docs/validation.md).
// With the rise,
// every stiffness of the law (secant, the loading branch's transverse part
// t / delta, the compression penalty) is at most max(1, beta^2) k_p
// (cohesive_stiffness_bound), which the stable step includes. Insertion stays
// extrinsic: the facet is rigid until the criterion breaks it.
//
// Compression (delta_n < 0): the cohesive law acts on the shear part only
// (delta = beta |delta_s|) and interpenetration is resisted by a linear normal
// penalty T_n = k_p delta_n n with the same stiffness k_p (Pa/m), e.g. E / h.
// This is a choice of this code: contact (DCR) will also act on crack faces
// once they are in the contact surface, the penalty only keeps the two sides
// of a closed crack apart between contact sweeps.
//
// Energies per unit reference area (J/m^2):
//   stored     = 1/2 (t(delta_max) / delta_max) delta^2 + 1/2 k_p <-delta_n>^2
//                (recoverable: the area under the secant, plus the penalty)
//   dissipated = W(delta_max) - 1/2 t(delta_max) delta_max
//              = (sigma_c delta_max - t(delta_max) delta_0) / 2 past delta_0
//                (0 on the elastic rise), Gc once delta_max >= delta_c,
// where W(delta_max) is the area under the envelope up to delta_max.
#include <algorithm>
#include <cmath>

#include "kernels/error.hpp"
#include "kernels/types.hpp"

namespace shatter {

/// Parameters of the Ortiz-Pandolfi law. Build with `make_cohesive_law`.
struct CohesiveLaw {
  double sigma_c = 0;  ///< cohesive strength, Pa
  double delta_c = 0;  ///< critical effective opening 2 Gc / sigma_c, m
  double beta = 1;     ///< shear-to-normal weighting, dimensionless
  double penalty = 0;  ///< k_p, Pa/m: slope of the elastic rise and normal stiffness in compression

  /// Fracture energy Gc = sigma_c delta_c / 2, J/m^2.
  double fracture_energy() const { return 0.5 * sigma_c * delta_c; }
  /// End of the elastic rise, delta_0 = sigma_c / k_p, m.
  double delta_0() const { return sigma_c / penalty; }
};

/// sigma_c (Pa), Gc (J/m^2), beta (-), penalty k_p (Pa/m). Requires
/// delta_0 = sigma_c / k_p < delta_c = 2 Gc / sigma_c.
inline CohesiveLaw make_cohesive_law(double sigma_c, double fracture_energy, double beta,
                                     double penalty) {
  const CohesiveLaw law{sigma_c, 2.0 * fracture_energy / sigma_c, beta, penalty};
  SHATTER_REQUIRE(law.delta_0() < law.delta_c,
                  "cohesive law: the elastic rise sigma_c / k_p = "
                      << law.delta_0() << " m must end before delta_c = 2 Gc / sigma_c = "
                      << law.delta_c << " m (raise Gc or the penalty k_p)");
  return law;
}

/// Effective traction on the loading envelope, Pa: k_p delta up to delta_0,
/// then sigma_c (delta_c - delta) / (delta_c - delta_0), 0 past delta_c.
inline double cohesive_envelope(const CohesiveLaw& law, double delta) {
  const double d0 = law.delta_0();
  if (delta <= d0) return law.penalty * delta;
  return law.sigma_c * std::max(0.0, (law.delta_c - delta) / (law.delta_c - d0));
}

/// Secant t(delta) / delta of the envelope, Pa/m: k_p on the elastic rise
/// (also the limit at delta = 0), so never above k_p.
inline double cohesive_secant(const CohesiveLaw& law, double delta) {
  return delta <= law.delta_0() ? law.penalty : cohesive_envelope(law, delta) / delta;
}

/// Upper bound of the norm of dT/dDelta over every state and opening, Pa/m:
/// max(1, beta^2) k_p (secants, the loading branch's transverse stiffness
/// t / delta and the compression penalty are all at most this; the loading
/// branch's own slope is -sigma_c / (delta_c - delta_0), smaller in size).
inline double cohesive_stiffness_bound(const CohesiveLaw& law) {
  return std::max(1.0, law.beta * law.beta) * law.penalty;
}

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
  double delta_max;   ///< updated state: largest effective opening reached, m
  double stored;      ///< recoverable energy density, J/m^2
  double dissipated;  ///< dissipated energy density up to delta_max, J/m^2
};

/// Ortiz-Pandolfi traction for opening `opening` = x(side 1) - x(side 0) (m),
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
  out.delta_max = std::max(delta, delta_max);
  const double t_over_delta = cohesive_secant(law, out.delta_max);  // Pa/m
  out.traction = t_over_delta * (beta2 * delta_s + open_n * n);
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
  const double dm = out.delta_max;
  out.dissipated = dm >= law.delta_c ? law.fracture_energy()
                   : dm <= law.delta_0()
                       ? 0.0
                       : 0.5 * (law.sigma_c * dm - cohesive_envelope(law, dm) * law.delta_0());
  return out;
}

/// Effective traction of the extrinsic insertion criterion (Camacho & Ortiz,
/// IJSS 33 (1996) 2899; Pandolfi & Ortiz, Eng. Comput. 18 (2002) 148):
/// t_eff = sqrt(<tn>^2 + tau^2 / beta^2) for the traction t = sigma n on a
/// facet of unit normal n, sigma the Cauchy stress (Pa). Compressive tn does
/// not open the facet. Returns Pa; the facet breaks when t_eff >= sigma_c.
inline double facet_effective_traction(const Mat3& sigma, const Vec3& n, double beta) {
  const Vec3 t = sigma * n;
  const double tn = t.dot(n);
  const double tau2 = (t - tn * n).squaredNorm();
  const double tn_pos = std::max(tn, 0.0);
  return std::sqrt(tn_pos * tn_pos + tau2 / (beta * beta));
}

}  // namespace shatter
