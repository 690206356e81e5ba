#pragma once
// Linear 4-node tetrahedron, one quadrature point (constant strain).
// Node order: Gmsh's (corners 0..3, positive volume when
// (x1-x0) . ((x2-x0) x (x3-x0)) > 0).
// With Ds = [x1-x0, x2-x0, x3-x0] (current) and Dm the same of the reference
// coordinates, F = Ds Dm^-1 and the nodal internal forces are
//   [f1 f2 f3] = -V0 P Dm^-T,   f0 = -(f1 + f2 + f3)
// (e.g. Sifakis & Barbic, "FEM simulation of 3D deformable solids", SIGGRAPH
// 2012 course notes, sec. 4.2).
#include <array>
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "kernels/lane_log.hpp"
#include "kernels/neo_hookean.hpp"
#include "kernels/types.hpp"

namespace shatter {

/// Signed volume of the tetrahedron (a, b, c, d), m^3.
inline double tet_signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

/// Smallest altitude of the tetrahedron (a, b, c, d) = 3 |V| / (largest face area), m.
/// The characteristic length of the stable time step.
inline double tet_min_altitude(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 ab = b - a, ac = c - a, ad = d - a, bc = c - b, bd = d - b;
  const double twice_area_max = std::max(std::max(ab.cross(ac).squaredNorm(), ab.cross(ad).squaredNorm()),
                                         std::max(ac.cross(ad).squaredNorm(), bc.cross(bd).squaredNorm()));
  const double six_volume = std::abs(ab.dot(ac.cross(ad)));
  return six_volume / std::sqrt(twice_area_max);  // 3V / A = (6V) / (2A)
}

/// Reference constants of one TET4: Dm^-1 and the reference volume V0.
struct Tet4Reference {
  Mat3 Dm_inv;
  double volume;
};

inline Tet4Reference tet4_reference(const Vec3& X0, const Vec3& X1, const Vec3& X2, const Vec3& X3) {
  Mat3 Dm;
  Dm << X1 - X0, X2 - X0, X3 - X0;
  return {Dm.inverse(), Dm.determinant() / 6.0};
}

/// Deformation gradient of a TET4 from its current corner positions.
inline Mat3 tet4_deformation_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                                      const Mat3& Dm_inv) {
  Mat3 Ds;
  Ds << x1 - x0, x2 - x0, x3 - x0;
  return Ds * Dm_inv;
}

/// Internal nodal forces (N, columns = nodes 0..3) and strain energy (J) of
/// one TET4; also its deformation gradient determinant J for the stable step.
struct Tet4Force {
  Eigen::Matrix<double, 3, 4> f;
  double energy;
  double J;
};

/// N TET4 elements side by side in struct-of-arrays layout (lane l = one
/// element), for tet4_neo_hookean_lanes. Units as in tet4_internal_force.
template <int N>
struct Tet4Lanes {
  double x[12][N];       ///< in: corner positions, x[3a + i][l] = x_{a,i}, m
  double Dm_inv[9][N];   ///< in: Dm^-1 column-major, Dm_inv[3j + k][l] = Dm^-1(k, j), 1/m
  double V0[N];          ///< in: reference volume, m^3
  double f[12][N];       ///< out: internal nodal forces dE/dx, f[3a + i][l], N
  double energy[N];      ///< out: strain energy V0 W, J
  double J[N];           ///< out: det F
  double lnJ[N];         ///< out: ln det F (for NeoHookean wave speed without a second log)
};

/// Lane l of the lane kernels: cof(F) = J F^-T into C and det F returned
/// (F, C column-major, F[3j + i][l] = F(i, j)): column j of cof(F) is the
/// cross product of the two other columns. The lane helpers are always
/// inlined: a call inside the loop over the lanes stops its vectorisation
/// (GCC 12 at -march=x86-64-v4: 2.6x slower).
template <int N>
[[gnu::always_inline]] inline double cofactor_lane(const double (&F)[9][N], double (&C)[9][N], int l) {
  C[0][l] = F[4][l] * F[8][l] - F[5][l] * F[7][l];
  C[1][l] = F[5][l] * F[6][l] - F[3][l] * F[8][l];
  C[2][l] = F[3][l] * F[7][l] - F[4][l] * F[6][l];
  C[3][l] = F[7][l] * F[2][l] - F[8][l] * F[1][l];
  C[4][l] = F[8][l] * F[0][l] - F[6][l] * F[2][l];
  C[5][l] = F[6][l] * F[1][l] - F[7][l] * F[0][l];
  C[6][l] = F[1][l] * F[5][l] - F[2][l] * F[4][l];
  C[7][l] = F[2][l] * F[3][l] - F[0][l] * F[5][l];
  C[8][l] = F[0][l] * F[4][l] - F[1][l] * F[3][l];
  return F[0][l] * C[0][l] + F[1][l] * C[1][l] + F[2][l] * C[2][l];
}

/// Lane l of the lane kernels: w P (column-major, into P) and the energy
/// w W returned, for the volume (or quadrature weight) w, with
/// w P = a F + b cof(F), a = w mu, b = w (lambda ln J - mu) / J, from
/// P = mu F + ((lambda ln J - mu) / J) cof(F).
template <int N>
[[gnu::always_inline]] inline double neo_hookean_lane_stress(const double (&F)[9][N], const double (&C)[9][N],
                                                             double detF, double lnJ, double w, const NeoHookean& mat,
                                                             int l, double (&P)[9]) {
  const double mu = mat.mu, lambda = mat.lambda;
  double I1 = 0.0;
  for (int q = 0; q < 9; ++q) I1 += F[q][l] * F[q][l];
  const double a = w * mu, b = w * ((lambda * lnJ - mu) / detF);
  for (int q = 0; q < 9; ++q) P[q] = a * F[q][l] + b * C[q][l];
  return w * (0.5 * mu * (I1 - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ);
}

/// TET4 Neo-Hookean internal forces of N elements at once. Same formulas as
/// tet4_internal_force written lane-wise, in scalar IEEE arithmetic with a fixed
/// order of operations, so the compiler vectorises across elements (SSE2: 2
/// lanes) and every lane is bitwise equal to the single-element result
/// (tet4_internal_force with NeoHookean is this function with N = 1).
/// ~170 flops and one log per element (lane_log, across the lanes too); no
/// Eigen temporaries, no second determinant: cof(F) gives both det F and F^-T.
template <int N>
inline void tet4_neo_hookean_lanes(Tet4Lanes<N>& L, const NeoHookean& mat) {
  double F[9][N], C[9][N], detF[N];
  double(&lnJ)[N] = L.lnJ;
  for (int l = 0; l < N; ++l) {
    // Ds columns d[3k + i] = x_{k+1,i} - x_{0,i};  F = Ds Dm^-1, F[3j + i] = F(i, j)
    double d[9];
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) d[3 * k + i] = L.x[3 * (k + 1) + i][l] - L.x[i][l];
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        F[3 * j + i][l] = d[i] * L.Dm_inv[3 * j][l] + d[3 + i] * L.Dm_inv[3 * j + 1][l] +
                          d[6 + i] * L.Dm_inv[3 * j + 2][l];
    detF[l] = cofactor_lane(F, C, l);
  }
  lane_log(detF, lnJ);
  for (int l = 0; l < N; ++l) {
    double P[9];
    L.energy[l] = neo_hookean_lane_stress(F, C, detF[l], lnJ[l], L.V0[l], mat, l, P);
    // forces on nodes 1..3: H = V0 P Dm^-T, H(i, j) = sum_k V0 P(i, k) Dm^-1(j, k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        L.f[3 * (j + 1) + i][l] =
            P[i] * L.Dm_inv[j][l] + P[3 + i] * L.Dm_inv[3 + j][l] + P[6 + i] * L.Dm_inv[6 + j][l];
    for (int i = 0; i < 3; ++i) L.f[i][l] = -(L.f[3 + i][l] + L.f[6 + i][l] + L.f[9 + i][l]);
    L.J[l] = detF[l];
  }
}

/// Squared stable time step of N TET4 or TET10 Neo-Hookean elements, s^2,
/// after their lane kernel (Tet4Lanes or Tet10Lanes L: corners in L.x[0..11],
/// L.J and L.lnJ): dt^2 = h^2 / c^2 with h = `altitude_fraction` x the
/// smallest altitude of the corner tetrahedron (1/2: tet4_stable_length, 1/4:
/// tet10_stable_length), h^2 = fraction^2 (6V)^2 / max (2 A_face)^2 (no square
/// root), and c = mat.wave_speed(J) from L.lnJ (no second log); J <= 0 or
/// NaN uses the reference wave speed, as the runtime does. Take the minimum
/// over a block and one square root: sqrt is monotone, so sqrt(min dt^2) =
/// min sqrt(dt^2). Same value as h / wave_speed(J) up to rounding (a few
/// ulp), ~2x cheaper than both calls (which cost as much as the TET4 force
/// kernel itself).
template <class Lanes, int N>
inline void stable_dt_squared_lanes(const Lanes& L, const NeoHookean& mat, double altitude_fraction,
                                    double (&dt2)[N]) {
  const double ref_stiff = mat.lambda + 2.0 * mat.mu;
  const double scale = (altitude_fraction * altitude_fraction) * mat.density;
  for (int l = 0; l < N; ++l) {
    double d[9];  // ab, ac, ad
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) d[3 * k + i] = L.x[3 * (k + 1) + i][l] - L.x[i][l];
    const double bc[3] = {d[3] - d[0], d[4] - d[1], d[5] - d[2]};
    const double bd[3] = {d[6] - d[0], d[7] - d[1], d[8] - d[2]};
    auto cross_sq = [](const double* u, const double* v, double* w) {
      w[0] = u[1] * v[2] - u[2] * v[1];
      w[1] = u[2] * v[0] - u[0] * v[2];
      w[2] = u[0] * v[1] - u[1] * v[0];
      return w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    };
    double w[3], cd[3];
    const double a0 = cross_sq(d, d + 3, w), a1 = cross_sq(d, d + 6, w), a3 = cross_sq(bc, bd, w);
    const double a2 = cross_sq(d + 3, d + 6, cd);
    const double six_volume = d[0] * cd[0] + d[1] * cd[1] + d[2] * cd[2];
    const double twice_area_sq = std::max(std::max(a0, a1), std::max(a2, a3));
    const double stiff =
        L.J[l] > 0 ? std::max(ref_stiff - 2.0 * mat.lambda * L.lnJ[l], ref_stiff) : ref_stiff;
    dt2[l] = scale * (six_volume * six_volume) / (twice_area_sq * stiff);  // one division
  }
}

/// TET4: h = tet4_stable_length (half the smallest altitude).
template <int N>
inline void tet4_stable_dt_squared_lanes(const Tet4Lanes<N>& L, const NeoHookean& mat, double (&dt2)[N]) {
  stable_dt_squared_lanes(L, mat, 0.5, dt2);
}

template <class Material>
inline Tet4Force tet4_internal_force(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                                     const Mat3& Dm_inv, double V0, const Material& mat) {
  Tet4Force out;
  if constexpr (std::is_same_v<Material, NeoHookean>) {
    Tet4Lanes<1> L;
    for (int i = 0; i < 3; ++i) {
      L.x[i][0] = x0[i];
      L.x[3 + i][0] = x1[i];
      L.x[6 + i][0] = x2[i];
      L.x[9 + i][0] = x3[i];
    }
    for (int q = 0; q < 9; ++q) L.Dm_inv[q][0] = Dm_inv.data()[q];
    L.V0[0] = V0;
    tet4_neo_hookean_lanes(L, mat);
    for (int q = 0; q < 12; ++q) out.f.data()[q] = L.f[q][0];
    out.energy = L.energy[0];
    out.J = L.J[0];
  } else {
    const Mat3 F = tet4_deformation_gradient(x0, x1, x2, x3, Dm_inv);
    Mat3 P;
    double W;
    mat.stress_energy(F, P, W);
    const Mat3 H = V0 * P * Dm_inv.transpose();
    out.f.template rightCols<3>() = H;
    out.f.col(0) = -H.rowwise().sum();
    out.energy = V0 * W;
    out.J = F.determinant();
  }
  return out;
}

}  // namespace shatter

namespace shatter {

/// Characteristic length of a TET4 for the stable step dt = h / c_d: half its
/// smallest altitude. Half, because the element eigenvalue bound
/// 2 / omega_max(M_e^-1 K_e) of a lumped TET4 falls to 0.507 x altitude / c_d for a
/// regular tetrahedron at nu = 0.49 (tests/kernels/test_stable_dt.cpp measures it).
inline double tet4_stable_length(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return 0.5 * tet_min_altitude(a, b, c, d);
}

}  // namespace shatter
