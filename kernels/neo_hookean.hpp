#pragma once
// Compressible Neo-Hookean solid (Ogden form; e.g. Bonet & Wood, "Nonlinear
// Continuum Mechanics for FEA", 2nd ed., eq. 6.27-6.28):
//   W(F) = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,   I1 = tr(F^T F), J = det F
//   P(F) = dW/dF = mu (F - F^-T) + lambda ln J F^-T        (first Piola-Kirchhoff, Pa)
// Units: Pa for mu, lambda; kg/m^3 for density.
#include <cmath>

#include "kernels/types.hpp"

namespace shatter {

struct NeoHookean {
  double mu = 0;       ///< shear modulus, Pa
  double lambda = 0;   ///< first Lame parameter, Pa
  double density = 0;  ///< reference density, kg/m^3

  static NeoHookean from_young_poisson(double young, double poisson, double density) {
    NeoHookean m;
    m.mu = young / (2.0 * (1.0 + poisson));
    m.lambda = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    m.density = density;
    return m;
  }

  /// Dilatational wave speed of the undeformed material, m/s.
  double wave_speed() const { return std::sqrt((lambda + 2.0 * mu) / density); }

  /// Dilatational wave speed at volume ratio J, from the current Lame moduli
  /// lambda' = lambda/J, mu' = (mu - lambda ln J)/J and density rho/J:
  /// c^2 = (lambda + 2 mu - 2 lambda ln J)/rho; never below the reference value.
  double wave_speed(double J) const {
    const double stiff = lambda + 2.0 * mu - 2.0 * lambda * std::log(J);
    return std::sqrt(std::max(stiff, lambda + 2.0 * mu) / density);
  }

  /// Strain energy density W(F), J/m^3 (per reference volume).
  double energy(const Mat3& F) const {
    const double J = F.determinant();
    const double lnJ = std::log(J);
    return 0.5 * mu * (F.squaredNorm() - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ;
  }

  /// First Piola-Kirchhoff stress P(F), Pa. F^-T is formed from the cofactor
  /// matrix, cof(F) = J F^-T, without a general inverse.
  Mat3 stress(const Mat3& F) const {
    const Mat3 cof = cofactor(F);
    const double J = F.col(0).dot(cof.col(0));
    return mu * F + ((lambda * std::log(J) - mu) / J) * cof;
  }

  /// Stress and energy density together (one determinant, one log).
  void stress_energy(const Mat3& F, Mat3& P, double& W) const {
    const Mat3 cof = cofactor(F);
    const double J = F.col(0).dot(cof.col(0));
    const double lnJ = std::log(J);
    P = mu * F + ((lambda * lnJ - mu) / J) * cof;
    W = 0.5 * mu * (F.squaredNorm() - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ;
  }

  /// Cauchy stress sigma = P F^T / J, Pa.
  Mat3 cauchy_stress(const Mat3& F) const { return stress(F) * F.transpose() / F.determinant(); }

  /// Cofactor matrix cof(F) = det(F) F^-T.
  static Mat3 cofactor(const Mat3& F) {
    Mat3 c;
    c.col(0) = F.col(1).cross(F.col(2));
    c.col(1) = F.col(2).cross(F.col(0));
    c.col(2) = F.col(0).cross(F.col(1));
    return c;
  }
};

/// von Mises equivalent stress of a Cauchy stress, Pa.
inline double von_mises(const Mat3& s) {
  const double dxx = s(0, 0) - s(1, 1), dyy = s(1, 1) - s(2, 2), dzz = s(2, 2) - s(0, 0);
  return std::sqrt(0.5 * (dxx * dxx + dyy * dyy + dzz * dzz) +
                   3.0 * (s(0, 1) * s(0, 1) + s(1, 2) * s(1, 2) + s(0, 2) * s(0, 2)));
}

}  // namespace shatter
