#pragma once
// Effective traction of the extrinsic insertion criterion on facets, one
// facet or N side by side (vectorised across facets, as the element lane
// kernels of kernels/tet4.hpp).
#include <algorithm>
#include <cmath>

#include "kernels/types.hpp"

namespace shatter {

/// a b + c as Eigen 3.4 evaluates the first two rows of a fixed-size
/// Matrix3d * Vector3d (one 2-double packet, pmadd: fused where the SIMD
/// width has FMA, -ffp-contract=off or not). Lets the lane kernel keep the
/// bits of the Eigen form sigma * n (tests/kernels/test_facet_traction.cpp).
[[gnu::always_inline]] inline double packet_madd(double a, double b, double c) {
#ifdef EIGEN_VECTORIZE_FMA
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

/// Lane l: the effective traction of the criterion of Camacho & Ortiz (IJSS
/// 33 (1996) 2899; Pandolfi & Ortiz, Eng. Comput. 18 (2002) 148),
///   t_eff = sqrt(<tn>^2 + tau^2 / beta^2),  t = sigma n,  tn = t . n,
///   tau = |t - tn n|,
/// for the Cauchy stress sigma (row-major, sigma[3i + j][l] = sigma(i, j),
/// Pa) and the unit normal n (n[i][l]); compressive tn does not open the
/// facet. Returns Pa. The operations are those of the Eigen expressions
/// t = sigma * n, t.dot(n), (t - tn n).squaredNorm() (same order and
/// rounding), so every lane has their bits.
template <int N>
[[gnu::always_inline]] inline double effective_traction_lane(const double (&sigma)[9][N], const double (&n)[3][N],
                                                             double beta, int l) {
  const double n0 = n[0][l], n1 = n[1][l], n2 = n[2][l];
  const double t0 = packet_madd(sigma[2][l], n2, packet_madd(sigma[1][l], n1, sigma[0][l] * n0));
  const double t1 = packet_madd(sigma[5][l], n2, packet_madd(sigma[4][l], n1, sigma[3][l] * n0));
  const double t2 = sigma[6][l] * n0 + (sigma[7][l] * n1 + sigma[8][l] * n2);
  const double tn = t0 * n0 + t1 * n1 + t2 * n2;
  const double s0 = t0 - tn * n0, s1 = t1 - tn * n1, s2 = t2 - tn * n2;
  const double tau2 = s0 * s0 + s1 * s1 + s2 * s2;
  const double tn_pos = std::max(tn, 0.0);
  return std::sqrt(tn_pos * tn_pos + tau2 / (beta * beta));
}

/// Effective traction t_eff of the criterion (effective_traction_lane) for
/// the Cauchy stress sigma (Pa) on a facet of unit normal n. Returns Pa; the
/// facet breaks when t_eff >= sigma_c.
inline double facet_effective_traction(const Mat3& sigma, const Vec3& n, double beta) {
  double s[9][1], u[3][1];
  for (int i = 0; i < 3; ++i) {
    u[i][0] = n[i];
    for (int j = 0; j < 3; ++j) s[3 * i + j][0] = sigma(i, j);
  }
  return effective_traction_lane(s, u, beta, 0);
}

/// Row-major index q = 3i + j of a symmetric stress -> its Voigt component
/// (xx, yy, zz, yz, xz, xy).
inline constexpr int kVoigtOfRowMajor[9] = {0, 5, 4, 5, 1, 3, 4, 3, 2};

/// N facets side by side (lane l = one facet), struct-of-arrays, for
/// facet_traction_lanes. S = 6: stresses in Voigt order (xx, yy, zz, yz, xz,
/// xy); S = 9: row-major, stress_sum[3i + j][l] = sigma_0(i, j) + sigma_1(i, j).
/// The kernels read the two stresses only through their sum, so the caller
/// adds them before filling the lanes (half the rows to fill).
template <int N, int S>
struct FacetTractionLanes {
  static_assert(S == 6 || S == 9);
  double x[9][N];           ///< in: corners a, b, c of the facet, x[3a + i][l], m
  double stress_sum[S][N];  ///< in: sigma_0 + sigma_1, the sum of its two elements' Cauchy stresses, Pa
  double beta[N];           ///< in: shear-to-normal weighting of its law
  double traction[N];       ///< out: effective traction t_eff, Pa
};

/// (b - a) x (c - a) of lane l's corner triangle, the operations of Eigen's
/// cross product: facet_traction_lanes and facet_criterion_lanes share its bits.
template <int N, int S>
[[gnu::always_inline]] inline void facet_cross(const FacetTractionLanes<N, S>& L, int l, double& c0, double& c1,
                                               double& c2) {
  double u[3], v[3];
  for (int i = 0; i < 3; ++i) {
    u[i] = L.x[3 + i][l] - L.x[i][l];
    v[i] = L.x[6 + i][l] - L.x[i][l];
  }
  c0 = u[1] * v[2] - u[2] * v[1];
  c1 = u[2] * v[0] - u[0] * v[2];
  c2 = u[0] * v[1] - u[1] * v[0];
}

/// Effective traction of N facets: n the unit normal (b - a) x (c - a) /
/// |(b - a) x (c - a)| of the corner triangle (0 if degenerate), sigma the
/// mean of the two elements' stresses, then effective_traction_lane. The
/// operations are those of the Eigen forms (b - a).cross(c - a).normalized()
/// and 0.5 * (sigma_0 + sigma_1) in scalar IEEE arithmetic with a fixed
/// order, so the compiler vectorises across facets and every lane has the
/// bits of the one-facet Eigen evaluation (any N, any lane: ranks x threads
/// determinism). ~70 flops, a square root and 4 divisions per facet.
template <int N, int S>
inline void facet_traction_lanes(FacetTractionLanes<N, S>& L) {
  double n[3][N], sigma[9][N];
  for (int l = 0; l < N; ++l) {
    double c0, c1, c2;
    facet_cross(L, l, c0, c1, c2);
    const double z = c0 * c0 + c1 * c1 + c2 * c2;
    const double r = z > 0 ? std::sqrt(z) : 1.0;  // Eigen: a zero vector stays zero
    n[0][l] = c0 / r;
    n[1][l] = c1 / r;
    n[2][l] = c2 / r;
    double mean[S];
    for (int q = 0; q < S; ++q) mean[q] = 0.5 * L.stress_sum[q][l];
    for (int q = 0; q < 9; ++q) sigma[q][l] = mean[S == 6 ? kVoigtOfRowMajor[q] : q];
  }
  for (int l = 0; l < N; ++l) L.traction[l] = effective_traction_lane(sigma, n, L.beta[l], l);
}

/// The decision t_eff >= strength of facet_traction_lanes for N facets,
/// without its divisions and square roots (the bulk of its time, slow in wide
/// vectors). With c = (b - a) x (c - a), z = |c|^2 (n = c / sqrt(z)) and
/// w = (sigma_0 + sigma_1) c = 2 sigma c, p = c . w, q = |w|^2: tn = p / 2z,
/// tau^2 = q / 4z - tn^2, so t_eff >= sigma_c, times 4 z^2 beta^2 > 0, is
///   D = <p>^2 beta^2 + (q z - p^2) - (2 sigma_c beta z)^2 >= 0.
/// Lane l is decided, breaks[l] = D > 0, only where |D| exceeds
///   1e-10 ((p^2 + q z)(1 + beta^2) + (2 sigma_c beta z)^2):
/// D's round-off (some 30 roundings of terms bounded by that sum, p^2 <= q z)
/// and that of facet_traction_lanes' t_eff^2 (terms bounded by
/// |t|^2 (1 + 1 / beta^2), scaled alike) are each below 1e-14 of it, with c
/// the same bits in both (facet_cross), so the decision is that of
/// t_eff >= strength. Elsewhere (within the margin, a degenerate or extreme
/// z, inf or NaN) undecided[l] is set: evaluate those lanes with
/// facet_traction_lanes. L.traction is not read.
template <int N, int S>
inline void facet_criterion_lanes(const FacetTractionLanes<N, S>& L, const double (&strength)[N], bool (&breaks)[N],
                                  bool (&undecided)[N]) {
  double d[N], margin[N], z_of[N];
  for (int l = 0; l < N; ++l) {  // vectorised across lanes: no branch, no bool in it
    double c[3];
    facet_cross(L, l, c[0], c[1], c[2]);
    const double z = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    double sum[9];
    for (int q = 0; q < 9; ++q) sum[q] = L.stress_sum[S == 6 ? kVoigtOfRowMajor[q] : q][l];
    const double w0 = sum[0] * c[0] + sum[1] * c[1] + sum[2] * c[2];
    const double w1 = sum[3] * c[0] + sum[4] * c[1] + sum[5] * c[2];
    const double w2 = sum[6] * c[0] + sum[7] * c[1] + sum[8] * c[2];
    const double p = c[0] * w0 + c[1] * w1 + c[2] * w2;
    const double qz = (w0 * w0 + w1 * w1 + w2 * w2) * z;
    const double b2 = L.beta[l] * L.beta[l];
    const double p_pos = std::max(p, 0.0), g = 2.0 * strength[l] * L.beta[l] * z;
    d[l] = p_pos * p_pos * b2 + (qz - p * p) - g * g;
    margin[l] = 1e-10 * ((p * p + qz) * (1.0 + b2) + g * g);
    z_of[l] = z;
  }
  for (int l = 0; l < N; ++l) {
    // z within [1e-150, 1e150]: z^2 and the terms neither underflow nor overflow.
    const bool decided = (std::abs(d[l]) > margin[l]) & (z_of[l] >= 1e-150) & (z_of[l] <= 1e150);
    breaks[l] = d[l] > 0;
    undecided[l] = !decided;
  }
}

}  // namespace shatter
