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
//   loading   (delta >= delta_max): t = sigma_c (1 - delta / delta_c), 0 past delta_c
//   unloading (delta <  delta_max): t = t(delta_max) / delta_max * delta  (secant to 0)
// with delta_c = 2 Gc / sigma_c, so that the work of separation is Gc (J/m^2)
// for every mode mixity. The state is the largest effective opening reached.
//
// Compression (delta_n < 0): the cohesive law acts on the shear part only
// (delta = beta |delta_s|) and interpenetration is resisted by a linear normal
// penalty T_n = k_p delta_n n with a user stiffness k_p (Pa/m), e.g. E / h.
// This is a choice of this code: contact (DCR) will also act on crack faces
// once they are in the contact surface, the penalty only keeps the two sides
// of a closed crack apart between contact sweeps.
//
// Energies per unit reference area (J/m^2):
//   stored     = 1/2 (t(delta_max) / delta_max) delta^2 + 1/2 k_p <-delta_n>^2
//                (recoverable: the area under the secant, plus the penalty)
//   dissipated = W(delta_max) - 1/2 t(delta_max) delta_max = sigma_c delta_max / 2,
//                capped at Gc once delta_max >= delta_c,
// where W(delta_max) is the area under the loading curve up to delta_max.
#include <algorithm>
#include <cmath>

#include "kernels/types.hpp"

namespace shatter {

/// Parameters of the Ortiz-Pandolfi law. Build with `make_cohesive_law`.
struct CohesiveLaw {
  double sigma_c = 0;  ///< cohesive strength, Pa
  double delta_c = 0;  ///< critical effective opening 2 Gc / sigma_c, m
  double beta = 1;     ///< shear-to-normal weighting, dimensionless
  double penalty = 0;  ///< normal stiffness in compression k_p, Pa/m

  /// Fracture energy Gc = sigma_c delta_c / 2, J/m^2.
  double fracture_energy() const { return 0.5 * sigma_c * delta_c; }
};

/// sigma_c (Pa), Gc (J/m^2), beta (-), penalty k_p (Pa/m).
inline CohesiveLaw make_cohesive_law(double sigma_c, double fracture_energy, double beta,
                                     double penalty) {
  return {sigma_c, 2.0 * fracture_energy / sigma_c, beta, penalty};
}

/// Effective traction on the loading envelope, t = sigma_c <1 - delta/delta_c>, Pa.
inline double cohesive_envelope(const CohesiveLaw& law, double delta) {
  return law.sigma_c * std::max(0.0, 1.0 - delta / law.delta_c);
}

/// Result of one evaluation of the law at one point of a cohesive surface.
struct CohesiveTraction {
  Vec3 traction;      ///< T, Pa, acting on side 1 against the opening (side 0 gets -T)
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
  double t_over_delta = 0;  // secant t / delta, Pa/m
  if (delta >= delta_max) {
    out.delta_max = delta;
    if (delta > 0) t_over_delta = cohesive_envelope(law, delta) / delta;
  } else {
    out.delta_max = delta_max;
    t_over_delta = cohesive_envelope(law, delta_max) / delta_max;
  }
  out.traction = t_over_delta * (beta2 * delta_s + open_n * n);
  out.stored = 0.5 * t_over_delta * delta * delta;
  if (delta_n < 0) {
    out.traction += law.penalty * delta_n * n;
    out.stored += 0.5 * law.penalty * delta_n * delta_n;
  }
  out.dissipated =
      out.delta_max >= law.delta_c ? law.fracture_energy() : 0.5 * law.sigma_c * out.delta_max;
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
