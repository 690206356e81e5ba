#pragma once
// Subdivision Kirchhoff-Love thin-shell element (Cirak, Ortiz & Schroeder,
// IJNME 47 (2000) 2039-2072; Cirak & Ortiz, IJNME 51 (2001) 813-833).
//
// The mid-surface of a control triangle is x(v, w) = sum_a N_a(v, w) x_a over
// its NV patch control vertices (kernels/loop_basis.hpp: NV = 12 on a
// regular patch). With theta = (v, w), at a quadrature point:
//   a_alpha = x_{,alpha},  a_3 = a_1 x a_2 / j,  j = |a_1 x a_2|,
//   a_{alpha beta} = a_alpha . a_beta,   b_{alpha beta} = a_3 . x_{,alpha beta}
// (Cirak et al. 2000) and the same of the reference positions X_a: A, B.
// A shell point at theta_3 in [-t/2, t/2] has, to first order in theta_3
// (the thin-shell approximation of the papers),
//   g_{alpha beta} = a_{alpha beta} - 2 theta_3 b_{alpha beta},
//   G_{alpha beta} = A_{alpha beta} - 2 theta_3 B_{alpha beta},
// so E = (g - G)/2 = alpha + theta_3 beta with the membrane strain
// alpha = (a - A)/2 and the bending strain beta = B - b. The material is
// Neo-Hookean in plane stress at each of 3 Gauss-Legendre points through the
// thickness (kernels/shell_plane_stress.hpp); the reference volume element
// is taken as dA dtheta_3 (shifter 1, O(t/R)). The strain energy is
//   Pi = sum_q w_q J0_q sum_k (t/2) w_k W(g_k),   J0 = |A_1 x A_2|,
// and its exact derivative, with the resultants N = sum_k (...) S_k and
// M = sum_k (...) theta_3k S_k (per quadrature point, weights included), is
//   f_a = dPi/dx_a = N_{a,1} (n_1 - a_2 x u) + N_{a,2} (n_2 - u x a_1)
//                    - (M^11 N_{a,11} + 2 M^12 N_{a,12} + M^22 N_{a,22}) a_3,
//   n_alpha = N^{alpha beta} a_beta,
//   u = (v - (a_3 . v) a_3) / j,  v = M^{alpha beta} x_{,alpha beta},
// from delta a_3 = (I - a_3 a_3^T)(delta a_1 x a_2 + a_1 x delta a_2) / j.
// Units: m, Pa, J, N.
#include <array>
#include <cmath>

#include "kernels/loop_basis.hpp"
#include "kernels/loop_extraordinary.hpp"
#include "kernels/shell_plane_stress.hpp"
#include "kernels/types.hpp"

namespace shatter {

/// Triangle quadrature in (v, w) with weights summing to 1/2 (the parameter
/// triangle's area): NQ = 1 (centroid) or NQ = 3 (Strang & Fix, degree 2).
template <int NQ>
struct ShellQuadrature;
template <>
struct ShellQuadrature<1> {
  static constexpr std::array<std::array<double, 2>, 1> point = {{{1.0 / 3, 1.0 / 3}}};
  static constexpr std::array<double, 1> weight = {0.5};
};
template <>
struct ShellQuadrature<3> {
  static constexpr std::array<std::array<double, 2>, 3> point = {
      {{1.0 / 6, 1.0 / 6}, {2.0 / 3, 1.0 / 6}, {1.0 / 6, 2.0 / 3}}};
  static constexpr std::array<double, 3> weight = {1.0 / 6, 1.0 / 6, 1.0 / 6};
};

/// Gauss-Legendre points through the thickness, on [-1, 1] (theta_3 = t/2 xi).
inline constexpr int kShellThicknessPoints = 3;
inline constexpr std::array<double, 3> kShellThicknessXi = {-0.7745966692414834, 0.0, 0.7745966692414834};
inline constexpr std::array<double, 3> kShellThicknessWeight = {5.0 / 9, 8.0 / 9, 5.0 / 9};

/// The regular-patch basis at the quadrature points (the same for every regular element).
template <int NQ>
std::array<SubdivisionBasis<12>, NQ> loop_regular_basis_at_quadrature() {
  std::array<SubdivisionBasis<12>, NQ> out;
  for (int q = 0; q < NQ; ++q)
    out[q] = loop_regular_basis(ShellQuadrature<NQ>::point[q][0], ShellQuadrature<NQ>::point[q][1]);
  return out;
}

/// The basis of a patch with one extraordinary corner of valence N at the
/// quadrature points (the same for every such patch).
template <int N, int NQ>
std::array<SubdivisionBasis<N + 6>, NQ> loop_extraordinary_basis_at_quadrature() {
  std::array<SubdivisionBasis<N + 6>, NQ> out;
  for (int q = 0; q < NQ; ++q)
    out[q] = loop_extraordinary_basis<N>(ShellQuadrature<NQ>::point[q][0], ShellQuadrature<NQ>::point[q][1]);
  return out;
}

/// Mid-surface geometry at one point: tangents a_1, a_2, unit normal a_3,
/// j = |a_1 x a_2|, second derivatives x_{,11}, x_{,12}, x_{,22}, the metric
/// a_{alpha beta} and the curvature b_{alpha beta}.
struct ShellSurfacePoint {
  Vec3 a1, a2, a3, a11, a12, a22;
  double j;
  Mat2 metric, curvature;
};

template <int NV>
ShellSurfacePoint shell_surface_point(const Eigen::Matrix<double, 3, NV>& x, const SubdivisionBasis<NV>& B) {
  ShellSurfacePoint p;
  p.a1 = x * B.d1;
  p.a2 = x * B.d2;
  p.a11 = x * B.d11;
  p.a12 = x * B.d12;
  p.a22 = x * B.d22;
  const Vec3 n = p.a1.cross(p.a2);
  p.j = n.norm();
  p.a3 = n / p.j;
  p.metric << p.a1.dot(p.a1), p.a1.dot(p.a2), p.a1.dot(p.a2), p.a2.dot(p.a2);
  p.curvature << p.a3.dot(p.a11), p.a3.dot(p.a12), p.a3.dot(p.a12), p.a3.dot(p.a22);
  return p;
}

/// Reference constants of one quadrature point: for each thickness point k,
/// G^-1 and ln det G of G = A - 2 theta_3 B, theta_3 (m) and the weight
/// w_q J0 (t/2) w_k (m^3); area_weight = w_q J0 (m^2).
struct ShellReferencePoint {
  std::array<Mat2, kShellThicknessPoints> G_inv;
  std::array<double, kShellThicknessPoints> ln_det_G, theta3, weight;
  double area_weight;
};

template <int NQ>
using ShellReference = std::array<ShellReferencePoint, NQ>;

/// Reference constants of an element from its reference control positions X.
template <int NV, int NQ>
ShellReference<NQ> shell_reference(const Eigen::Matrix<double, 3, NV>& X,
                                   const std::array<SubdivisionBasis<NV>, NQ>& basis, double thickness) {
  ShellReference<NQ> ref;
  for (int q = 0; q < NQ; ++q) {
    const ShellSurfacePoint p = shell_surface_point<NV>(X, basis[q]);
    ShellReferencePoint& r = ref[q];
    r.area_weight = ShellQuadrature<NQ>::weight[q] * p.j;
    for (int k = 0; k < kShellThicknessPoints; ++k) {
      r.theta3[k] = 0.5 * thickness * kShellThicknessXi[k];
      const Mat2 G = p.metric - 2.0 * r.theta3[k] * p.curvature;
      r.G_inv[k] = G.inverse();
      r.ln_det_G[k] = std::log(G.determinant());
      r.weight[k] = r.area_weight * 0.5 * thickness * kShellThicknessWeight[k];
    }
  }
  return ref;
}

/// The stress resultants of one quadrature point q (ref[q]), contravariant in
/// the convected frame, with the point's weights included: N = sum_k w_k S_k,
/// M = sum_k w_k theta_3k S_k (w_k = ShellReferencePoint::weight), and its
/// strain energy sum_k w_k W_k (J).
struct ShellPointResultants {
  Mat2 N, M;
  double energy;
};
inline ShellPointResultants shell_point_resultants(const ShellSurfacePoint& p, const ShellReferencePoint& r,
                                                   const NeoHookean& mat) {
  ShellPointResultants out{Mat2::Zero(), Mat2::Zero(), 0.0};
  for (int k = 0; k < kShellThicknessPoints; ++k) {
    const Mat2 g = p.metric - 2.0 * r.theta3[k] * p.curvature;
    const PlaneStressPoint s = neo_hookean_plane_stress(mat, g, r.G_inv[k], r.ln_det_G[k]);
    out.energy += r.weight[k] * s.energy;
    out.N += r.weight[k] * s.S;
    out.M += (r.weight[k] * r.theta3[k]) * s.S;
  }
  return out;
}

/// Internal forces dPi/dx_a (N, column a = control vertex a) and strain energy Pi (J).
template <int NV>
struct ShellForce {
  Eigen::Matrix<double, 3, NV> f;
  double energy;
};

template <int NV, int NQ>
ShellForce<NV> shell_internal_force(const Eigen::Matrix<double, 3, NV>& x,
                                    const std::array<SubdivisionBasis<NV>, NQ>& basis, const ShellReference<NQ>& ref,
                                    const NeoHookean& mat) {
  ShellForce<NV> out;
  out.f.setZero();
  out.energy = 0.0;
  for (int q = 0; q < NQ; ++q) {
    const SubdivisionBasis<NV>& B = basis[q];
    const ShellSurfacePoint p = shell_surface_point<NV>(x, B);
    const auto [N, M, energy] = shell_point_resultants(p, ref[q], mat);
    out.energy += energy;
    const Vec3 n1 = N(0, 0) * p.a1 + N(0, 1) * p.a2;
    const Vec3 n2 = N(1, 0) * p.a1 + N(1, 1) * p.a2;
    const Vec3 v = M(0, 0) * p.a11 + 2.0 * M(0, 1) * p.a12 + M(1, 1) * p.a22;
    const Vec3 u = (v - p.a3.dot(v) * p.a3) / p.j;
    out.f.noalias() += (n1 - p.a2.cross(u)) * B.d1.transpose();
    out.f.noalias() += (n2 - u.cross(p.a1)) * B.d2.transpose();
    out.f.noalias() -= p.a3 * (M(0, 0) * B.d11 + 2.0 * M(0, 1) * B.d12 + M(1, 1) * B.d22).transpose();
  }
  return out;
}

/// Lumped (row-sum) mass of the element's control vertices, kg:
/// m_a = rho t sum_q w_q J0_q N_a (row sums of the consistent mass; a sum over the
/// elements gives each vertex rho t int N_a dA, total rho t x area).
/// The element's stress resultants in the global frame, averaged over its
/// quadrature points by their reference areas: the membrane force
/// n = N^{alpha beta} a_alpha (x) a_beta (N/m) and the bending moment
/// m = M^{alpha beta} a_alpha (x) a_beta (N m / m), per unit reference area
/// (second Piola-Kirchhoff resultants pushed forward with the current base
/// vectors, i.e. Kirchhoff-type; Cirak & Ortiz 2001).
struct ShellResultants {
  Mat3 n, m;
};
template <int NV, int NQ>
ShellResultants shell_resultants(const Eigen::Matrix<double, 3, NV>& x,
                                 const std::array<SubdivisionBasis<NV>, NQ>& basis, const ShellReference<NQ>& ref,
                                 const NeoHookean& mat) {
  ShellResultants out{Mat3::Zero(), Mat3::Zero()};
  double area = 0;
  for (int q = 0; q < NQ; ++q) {
    const ShellSurfacePoint p = shell_surface_point<NV>(x, basis[q]);
    const ShellPointResultants r = shell_point_resultants(p, ref[q], mat);
    Eigen::Matrix<double, 3, 2> a;
    a << p.a1, p.a2;
    out.n += a * r.N * a.transpose();
    out.m += a * r.M * a.transpose();
    area += ref[q].area_weight;
  }
  out.n /= area;
  out.m /= area;
  return out;
}

template <int NV, int NQ>
Eigen::Matrix<double, NV, 1> shell_lumped_mass(const std::array<SubdivisionBasis<NV>, NQ>& basis,
                                               const ShellReference<NQ>& ref, double thickness, double density) {
  Eigen::Matrix<double, NV, 1> m = Eigen::Matrix<double, NV, 1>::Zero();
  for (int q = 0; q < NQ; ++q) m += (density * thickness * ref[q].area_weight) * basis[q].N;
  return m;
}

}  // namespace shatter
