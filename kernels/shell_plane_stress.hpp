#pragma once
// Compressible Neo-Hookean material (kernels/neo_hookean.hpp)
//   W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2
// in plane stress, at one point through the thickness of a Kirchhoff-Love
// shell, in the convected frame of the shell (Cirak & Ortiz, IJNME 51 (2001)
// 813-833: the normal stretch is condensed out by S^33 = 0).
//
// With g_ab and G_ab the current and reference in-plane metrics at the point
// and C33 = lambda_3^2 the squared normal stretch (the normal stays normal,
// so C = diag(g_ab, C33) in the frame (g_1, g_2, a_3)):
//   I1 = G^ab g_ab + C33,   J^2 = C33 det g / det G.
// S^33 = 2 dW/dC33 = 0 gives, with s = ln C33 and L = ln det g - ln det G,
//   h(s) = mu (e^s - 1) + lambda/2 (L + s) = 0,
// which is convex and increasing in s: Newton from s = -nu/(1-nu) L (its
// linearisation) converges monotonically after at most one step. Because
// dW/dC33 = 0 there, the in-plane second Piola-Kirchhoff stress is the
// partial derivative at fixed C33:
//   S^ab = 2 dW/dg_ab = mu G^ab + (lambda ln J - mu) g^ab      (Pa).
#include <cmath>

#include "kernels/neo_hookean.hpp"

namespace shatter {

using Mat2 = Eigen::Matrix2d;

/// Energy density (J/m^3 of reference volume), in-plane contravariant second
/// Piola-Kirchhoff stress (Pa) and squared normal stretch at one point.
struct PlaneStressPoint {
  double energy;
  Mat2 S;
  double C33;
};

/// Plane-stress Neo-Hookean state from the current metric g and the reference
/// inverse metric G^-1 and ln det G (precomputed once per point).
inline PlaneStressPoint neo_hookean_plane_stress(const NeoHookean& mat, const Mat2& g, const Mat2& G_inv,
                                                 double ln_det_G) {
  const double mu = mat.mu, lambda = mat.lambda;
  const double det_g = g(0, 0) * g(1, 1) - g(0, 1) * g(1, 0);
  const double L = std::log(det_g) - ln_det_G;
  double s = -lambda / (lambda + 2.0 * mu) * L;
  // Quadratic convergence; the cap only stops a NaN metric.
  for (int it = 0; it < 30; ++it) {
    const double es = std::exp(s);
    const double step = (mu * (es - 1.0) + 0.5 * lambda * (L + s)) / (mu * es + 0.5 * lambda);
    s -= step;
    if (!(std::abs(step) > 1e-15 * (1.0 + std::abs(s)))) break;
  }
  const double C33 = std::exp(s);
  const double lnJ = 0.5 * (L + s);
  Mat2 g_inv;
  g_inv << g(1, 1), -g(0, 1), -g(1, 0), g(0, 0);
  g_inv /= det_g;
  PlaneStressPoint out;
  out.S = mu * G_inv + (lambda * lnJ - mu) * g_inv;
  out.energy = 0.5 * mu * ((G_inv.cwiseProduct(g)).sum() + C33 - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ;
  out.C33 = C33;
  return out;
}

}  // namespace shatter
