#pragma once
// Quadratic 10-node tetrahedron, 4-point Gauss rule (degree 2; Zienkiewicz &
// Taylor, "The Finite Element Method", vol. 1, table 9.3: a = 0.5854101966249685,
// b = 0.1381966011250105, weights 1/24 on the unit tetrahedron).
// Node order (Gmsh): corners 0..3, then mid-edge nodes on edges
//   4:(0,1) 5:(1,2) 6:(0,2) 7:(0,3) 8:(2,3) 9:(1,3).
// Shape functions in barycentrics L0 = 1 - xi - eta - zeta, L1 = xi, L2 = eta, L3 = zeta:
//   corner i: L_i (2 L_i - 1),   edge (i,j): 4 L_i L_j.
#include <array>
#include <cmath>
#include <type_traits>

#include "kernels/lane_log.hpp"
#include "kernels/neo_hookean.hpp"
#include "kernels/tet4.hpp"
#include "kernels/types.hpp"

namespace shatter {

inline constexpr std::array<std::array<int, 2>, 6> kTet10Edges = {
    {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}}};

using Tet10Nodes = Eigen::Matrix<double, 3, 10>;      ///< columns = node coordinates
using Tet10Gradients = Eigen::Matrix<double, 10, 3>;  ///< rows = dN_a/dX

/// Shape function values at reference point (xi, eta, zeta).
inline Eigen::Matrix<double, 10, 1> tet10_shape(const Vec3& p) {
  const double L[4] = {1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]};
  Eigen::Matrix<double, 10, 1> N;
  for (int i = 0; i < 4; ++i) N[i] = L[i] * (2.0 * L[i] - 1.0);
  for (int e = 0; e < 6; ++e) N[4 + e] = 4.0 * L[kTet10Edges[e][0]] * L[kTet10Edges[e][1]];
  return N;
}

/// Shape function derivatives dN_a/dxi_k at reference point (xi, eta, zeta).
inline Tet10Gradients tet10_shape_derivatives(const Vec3& p) {
  const double L[4] = {1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]};
  // dL_i/dxi_k
  static const double dL[4][3] = {{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  Tet10Gradients d;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) d(i, k) = (4.0 * L[i] - 1.0) * dL[i][k];
  for (int e = 0; e < 6; ++e) {
    const int i = kTet10Edges[e][0], j = kTet10Edges[e][1];
    for (int k = 0; k < 3; ++k) d(4 + e, k) = 4.0 * (dL[i][k] * L[j] + L[i] * dL[j][k]);
  }
  return d;
}

/// The 4-point rule's barycentrics: point q has L_q = a and the others b.
inline constexpr double kTet10RuleA = 0.5854101966249685, kTet10RuleB = 0.1381966011250105;

/// The 4-point rule: reference points and weights (sum of weights = 1/6).
inline const std::array<Vec3, 4>& tet10_quadrature_points() {
  constexpr double a = kTet10RuleA, b = kTet10RuleB;
  static const std::array<Vec3, 4> pts = {Vec3(b, b, b), Vec3(a, b, b), Vec3(b, a, b), Vec3(b, b, a)};
  return pts;
}
inline constexpr double kTet10QuadratureWeight = 1.0 / 24.0;

/// Reference constants of one TET10: per quadrature point, dxi/dX = (dX/dxi)^-1
/// and weight x det(dX/dxi) (reference volume measure, m^3). dN/dX = dN/dxi
/// dxi/dX (tet10_gradients); the lane kernel takes dxi/dX alone (9 numbers per
/// point instead of dN/dX's 30) and the constant dN/dxi of the rule.
struct Tet10Reference {
  std::array<Mat3, 4> dxi_dX;  ///< per point, (dX/dxi)^-1, 1/m
  std::array<double, 4> wdetJ;
  double volume;   ///< sum of wdetJ, m^3
  double min_jacobian;  ///< smallest det(dX/dxi) over the points (inverted if <= 0)
};

inline Tet10Reference tet10_reference(const Tet10Nodes& X) {
  Tet10Reference r;
  r.volume = 0.0;
  r.min_jacobian = HUGE_VAL;
  const auto& pts = tet10_quadrature_points();
  for (int q = 0; q < 4; ++q) {
    const Mat3 J = X * tet10_shape_derivatives(pts[q]);  // dX/dxi
    const double detJ = J.determinant();
    r.dxi_dX[q] = J.inverse();
    r.wdetJ[q] = kTet10QuadratureWeight * detJ;
    r.volume += r.wdetJ[q];
    r.min_jacobian = std::min(r.min_jacobian, detJ);
  }
  return r;
}

/// Shape function gradients dN_a/dX (rows = nodes, 1/m) at quadrature point q.
inline Tet10Gradients tet10_gradients(const Tet10Reference& r, int q) {
  return tet10_shape_derivatives(tet10_quadrature_points()[q]) * r.dxi_dX[q];
}

/// The smallest scaled Jacobian of a TET10 over its quadrature points:
/// det(dX/dxi) / (6 V), V = the element's volume (sum of w det J). The mean
/// of det J over the reference tetrahedron (volume 1/6) is 6 V, so a
/// straight-sided element has 1 at every point, a curved one less where it
/// is squeezed, and <= 0 where its curved edges fold it. Meaningful for V > 0.
struct Tet10ScaledJacobian {
  double value;  ///< smallest det J / (6 V), dimensionless
  int point;     ///< its quadrature point (index into tet10_quadrature_points())
};

inline Tet10ScaledJacobian tet10_min_scaled_jacobian(const Tet10Reference& r) {
  Tet10ScaledJacobian s{HUGE_VAL, 0};
  for (int q = 0; q < 4; ++q) {
    const double scaled = r.wdetJ[q] / kTet10QuadratureWeight / (6.0 * r.volume);
    if (scaled < s.value) s = {scaled, q};
  }
  return s;
}

/// Internal nodal forces dE/dx (columns = nodes), strain energy (J) and the
/// smallest det F over the quadrature points.
struct Tet10Force {
  Eigen::Matrix<double, 3, 10> f;
  double energy;
  double J;
};

/// N TET10 elements side by side in struct-of-arrays layout (lane l = one
/// element), for tet10_neo_hookean_lanes. Units as in tet10_internal_force.
template <int N>
struct Tet10Lanes {
  double x[30][N];          ///< in: node positions, x[3a + i][l] = x_{a,i}, m
  double dxi_dX[4][9][N];   ///< in: per point q, (dX/dxi)^-1 column-major, dxi_dX[q][3j + k][l] = dxi_k/dX_j, 1/m
  double w[4][N];           ///< in: per point, weight x det(dX/dxi), m^3
  double f[30][N];          ///< out: internal nodal forces dE/dx, f[3a + i][l], N
  double energy[N];         ///< out: strain energy, J
  double J[N];              ///< out: smallest det F over the points
  double lnJ[N];            ///< out: ln of that J (for the wave speed without a second log)
};

/// Element e's reference constants (dxi/dX and weights) into lane l.
template <int N>
inline void tet10_reference_into_lanes(const Tet10Reference& ref, Tet10Lanes<N>& L, int l) {
  for (int q = 0; q < 4; ++q) {
    const double* d = ref.dxi_dX[q].data();
    for (int k = 0; k < 9; ++k) L.dxi_dX[q][k][l] = d[k];
    L.w[q][l] = ref.wdetJ[q];
  }
}

/// TET10 Neo-Hookean internal forces of N elements at once, the 4-point rule
/// written lane-wise in scalar IEEE arithmetic with a fixed order of
/// operations (as tet4_neo_hookean_lanes), so the compiler vectorises across
/// elements and every lane is bitwise equal to the one-lane result
/// (tet10_internal_force with NeoHookean is this function with N = 1).
///
/// dN/dX = dN/dxi dxi/dX with dN/dxi constant per point, taken through the
/// barycentrics: at point q, L_q = a and the three others b (the rule's
/// points), dN_a/dL_m is (4 L_i - 1) for corner i (m = i) and 4 L_j, 4 L_i
/// for edge (i, j) (m = i, j), and d/dxi_k = d/dL_k - d/dL_0. Per point:
///   g_m = dx/dL_m = (4 L_m - 1) x_m + sum over the edges (m, j) of 4 L_j x_(m,j),
///   F = [g_1 - g_0, g_2 - g_0, g_3 - g_0] dxi/dX,
///   cof(F) for det F and F^-T, one log (lane_log), w P = w (mu F + ((lambda ln J - mu) / J) cof(F)),
///   [h_1 h_2 h_3] = w P (dxi/dX)^T,  h_0 = -(h_1 + h_2 + h_3),
///   f_i += (4 L_i - 1) h_i (corner i),  f_(i,j) += 4 L_j h_i + 4 L_i h_j (edge (i, j)).
/// About 300 flops per point and 40 reference numbers per element (dN/dX
/// itself would be 120).
template <int N>
inline void tet10_neo_hookean_lanes(Tet10Lanes<N>& L, const NeoHookean& mat) {
  for (int n = 0; n < 30; ++n)
    for (int l = 0; l < N; ++l) L.f[n][l] = 0.0;
  for (int l = 0; l < N; ++l) L.energy[l] = 0.0, L.J[l] = HUGE_VAL, L.lnJ[l] = HUGE_VAL;
  for (int q = 0; q < 4; ++q) {
    double c[4];  // 4 L_m at this point
    for (int m = 0; m < 4; ++m) c[m] = 4.0 * (m == q ? kTet10RuleA : kTet10RuleB);
    double F[9][N], C[9][N], detF[N], lnJ[N];
    for (int l = 0; l < N; ++l) {
      double g[4][3];  // g[m][i] = dx_i/dL_m
      for (int m = 0; m < 4; ++m)
        for (int i = 0; i < 3; ++i) g[m][i] = (c[m] - 1.0) * L.x[3 * m + i][l];
      for (int e = 0; e < 6; ++e) {
        const int m0 = kTet10Edges[e][0], m1 = kTet10Edges[e][1];
        for (int i = 0; i < 3; ++i) {
          g[m0][i] += c[m1] * L.x[3 * (4 + e) + i][l];
          g[m1][i] += c[m0] * L.x[3 * (4 + e) + i][l];
        }
      }
      double D[3][3];  // D[k][i] = dx_i/dxi_k
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i) D[k][i] = g[k + 1][i] - g[0][i];
      // F(i, j) = sum_k dx_i/dxi_k dxi_k/dX_j, F[3j + i]
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
          F[3 * j + i][l] = D[0][i] * L.dxi_dX[q][3 * j][l] + D[1][i] * L.dxi_dX[q][3 * j + 1][l] +
                            D[2][i] * L.dxi_dX[q][3 * j + 2][l];
      detF[l] = cofactor_lane(F, C, l);
    }
    lane_log(detF, lnJ);
    for (int l = 0; l < N; ++l) {
      double P[9];  // w P, column-major
      L.energy[l] += neo_hookean_lane_stress(F, C, detF[l], lnJ[l], L.w[q][l], mat, l, P);
      double h[4][3];  // h[k + 1][i] = sum_j w P(i, j) dxi_k/dX_j
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i)
          h[k + 1][i] = P[i] * L.dxi_dX[q][k][l] + P[3 + i] * L.dxi_dX[q][3 + k][l] +
                        P[6 + i] * L.dxi_dX[q][6 + k][l];
      for (int i = 0; i < 3; ++i) h[0][i] = -(h[1][i] + h[2][i] + h[3][i]);
      for (int m = 0; m < 4; ++m)
        for (int i = 0; i < 3; ++i) L.f[3 * m + i][l] += (c[m] - 1.0) * h[m][i];
      for (int e = 0; e < 6; ++e) {
        const int m0 = kTet10Edges[e][0], m1 = kTet10Edges[e][1];
        for (int i = 0; i < 3; ++i) L.f[3 * (4 + e) + i][l] += c[m1] * h[m0][i] + c[m0] * h[m1][i];
      }
      const bool smaller = detF[l] < L.J[l];  // as std::min: a NaN point is skipped
      L.lnJ[l] = smaller ? lnJ[l] : L.lnJ[l];
      L.J[l] = smaller ? detF[l] : L.J[l];
    }
  }
}

/// Squared stable step of N TET10 elements after tet10_neo_hookean_lanes:
/// h = tet10_stable_length (a quarter of the corner tetrahedron's smallest
/// altitude), c = wave speed at the smallest det F (stable_dt_squared_lanes).
template <int N>
inline void tet10_stable_dt_squared_lanes(const Tet10Lanes<N>& L, const NeoHookean& mat, double (&dt2)[N]) {
  stable_dt_squared_lanes(L, mat, 0.25, dt2);
}

template <class Material>
inline Tet10Force tet10_internal_force(const Tet10Nodes& x, const Tet10Reference& ref, const Material& mat) {
  Tet10Force out;
  if constexpr (std::is_same_v<Material, NeoHookean>) {
    Tet10Lanes<1> L;
    for (int q = 0; q < 30; ++q) L.x[q][0] = x.data()[q];
    tet10_reference_into_lanes(ref, L, 0);
    tet10_neo_hookean_lanes(L, mat);
    for (int q = 0; q < 30; ++q) out.f.data()[q] = L.f[q][0];
    out.energy = L.energy[0];
    out.J = L.J[0];
  } else {
    out.f.setZero();
    out.energy = 0.0;
    out.J = HUGE_VAL;
    for (int q = 0; q < 4; ++q) {
      const Tet10Gradients dNdX = tet10_gradients(ref, q);
      const Mat3 F = x * dNdX;
      Mat3 P;
      double W;
      mat.stress_energy(F, P, W);
      out.f.noalias() += ref.wdetJ[q] * P * dNdX.transpose();
      out.energy += ref.wdetJ[q] * W;
      out.J = std::min(out.J, F.determinant());
    }
  }
  return out;
}

/// HRZ lumped mass fractions of a TET10 (Hinton, Rock & Zienkiewicz, Earthquake
/// Eng. Struct. Dyn. 4 (1976) 245): m_a = M_aa / sum_b M_bb x (rho V), with M the
/// consistent mass matrix. Row-sum lumping gives negative corner masses for
/// TET10 (-1/20 of the element mass), unusable in explicit dynamics; HRZ keeps
/// every mass positive and the total exact. For straight-sided elements the
/// fractions are 1/36 (corners) and 4/27 (edges); curved elements use the
/// same definition evaluated with a collapsed Gauss rule exact to degree 9.
inline Eigen::Matrix<double, 10, 1> tet10_hrz_mass_fractions(const Tet10Nodes& X) {
  // 5-point Gauss-Legendre on [0,1] mapped through the Duffy collapse
  // (u,v,w) -> xi = u, eta = (1-u) v, zeta = (1-u)(1-v) w, Jacobian (1-u)^2 (1-v).
  static const double g[5] = {0.0469100770306680, 0.2307653449471585, 0.5, 0.7692346550528415,
                              0.9530899229693320};
  static const double gw[5] = {0.1184634425280945, 0.2393143352496832, 0.2844444444444444,
                               0.2393143352496832, 0.1184634425280945};
  Eigen::Matrix<double, 10, 1> diag = Eigen::Matrix<double, 10, 1>::Zero();
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 5; ++k) {
        const double u = g[i], v = g[j], w = g[k];
        const Vec3 p(u, (1 - u) * v, (1 - u) * (1 - v) * w);
        const double wt = gw[i] * gw[j] * gw[k] * (1 - u) * (1 - u) * (1 - v);
        const double detJ = (X * tet10_shape_derivatives(p)).determinant();
        diag += (wt * detJ) * tet10_shape(p).cwiseAbs2();
      }
  return diag / diag.sum();
}

}  // namespace shatter

namespace shatter {

/// Characteristic length of a TET10 with HRZ masses for dt = h / c_d: a quarter
/// of the smallest altitude of its corner tetrahedron (the element eigenvalue
/// bound falls to 0.275 x altitude / c_d at nu = 0.49; see test_stable_dt.cpp).
inline double tet10_stable_length(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return 0.25 * tet_min_altitude(a, b, c, d);
}

}  // namespace shatter
