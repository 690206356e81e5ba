#pragma once
// Consistent nodal forces of surface loads on one boundary face: a 3-node
// triangle (TET4) or a 6-node one (TET10: corners 0..2, then the mid-edge
// nodes of edges (0,1), (1,2), (2,0)), oriented so that (x1 - x0) x (x2 - x0)
// points out of the body. With shape functions N_a on the face:
//   pressure p (Pa, positive pushing into the body), a follower load on the
//   current face x:                  f_a = -p  int N_a n da
//   traction t (N per m^2 of reference area, global frame), a dead load on
//   the reference face X:            f_a =  t  int N_a dA
// 3-node: int N_a n da = (x1 - x0) x (x2 - x0) / 6 exactly. 6-node:
// quadrature, the 6-point degree-4 rule of Dunavant (Int. J. Numer. Meth.
// Eng. 21, 1985, table I), exact for the degree-4 integrand N_a (x_xi x x_eta).
#include <array>

#include "kernels/types.hpp"

namespace shatter {

namespace detail {

/// The 6-point rule: barycentrics (L1, L2) and weights on the unit triangle (summing to 1/2).
inline constexpr std::array<std::array<double, 3>, 6> kTri6Rule = {{
    {0.445948490915965, 0.445948490915965, 0.5 * 0.223381589678011},
    {0.445948490915965, 0.108103018168070, 0.5 * 0.223381589678011},
    {0.108103018168070, 0.445948490915965, 0.5 * 0.223381589678011},
    {0.091576213509771, 0.091576213509771, 0.5 * 0.109951743655322},
    {0.091576213509771, 0.816847572980459, 0.5 * 0.109951743655322},
    {0.816847572980459, 0.091576213509771, 0.5 * 0.109951743655322},
}};

/// 6-node triangle at (xi, eta): shape functions N and their derivatives.
inline void tri6_basis(double xi, double eta, double* N, double* dxi, double* deta) {
  const double L0 = 1.0 - xi - eta, L1 = xi, L2 = eta;
  N[0] = L0 * (2 * L0 - 1), N[1] = L1 * (2 * L1 - 1), N[2] = L2 * (2 * L2 - 1);
  N[3] = 4 * L0 * L1, N[4] = 4 * L1 * L2, N[5] = 4 * L2 * L0;
  dxi[0] = -(4 * L0 - 1), dxi[1] = 4 * L1 - 1, dxi[2] = 0, dxi[3] = 4 * (L0 - L1), dxi[4] = 4 * L2, dxi[5] = -4 * L2;
  deta[0] = -(4 * L0 - 1), deta[1] = 0, deta[2] = 4 * L2 - 1, deta[3] = -4 * L1, deta[4] = 4 * L1,
  deta[5] = 4 * (L0 - L2);
}

/// int N_a (x_xi x x_eta) dxi deta over the face (`nodes` = 3 or 6): the
/// area vector each node takes, m^2; or with `magnitude`, int N_a |x_xi x x_eta|.
inline void face_area_shares(const Vec3* x, int nodes, bool magnitude, Vec3* share_vec, double* share) {
  if (nodes == 3) {
    const Vec3 n = (x[1] - x[0]).cross(x[2] - x[0]) / 6.0;
    for (int a = 0; a < 3; ++a) {
      if (share_vec) share_vec[a] = n;
      if (share) share[a] = n.norm();
    }
    return;
  }
  for (int a = 0; a < 6; ++a) {
    if (share_vec) share_vec[a] = Vec3::Zero();
    if (share) share[a] = 0.0;
  }
  for (const auto& [xi, eta, w] : kTri6Rule) {
    double N[6], dxi[6], deta[6];
    tri6_basis(xi, eta, N, dxi, deta);
    Vec3 gxi = Vec3::Zero(), geta = Vec3::Zero();
    for (int a = 0; a < 6; ++a) gxi += dxi[a] * x[a], geta += deta[a] * x[a];
    const Vec3 n = gxi.cross(geta);
    for (int a = 0; a < 6; ++a) {
      if (share_vec) share_vec[a] += (w * N[a]) * n;
      if (share) share[a] += w * N[a] * (magnitude ? n.norm() : 0.0);
    }
  }
}

}  // namespace detail

/// Pressure p (Pa) on the current face x[0..nodes): nodal forces f[0..nodes), N.
inline void pressure_forces(const Vec3* x, int nodes, double p, Vec3* f) {
  Vec3 share[6];
  detail::face_area_shares(x, nodes, false, share, nullptr);
  for (int a = 0; a < nodes; ++a) f[a] = -p * share[a];
}

/// Traction t (Pa, global frame) on the reference face X[0..nodes): nodal forces f, N.
inline void traction_forces(const Vec3* X, int nodes, const Vec3& t, Vec3* f) {
  double share[6];
  detail::face_area_shares(X, nodes, true, nullptr, share);
  for (int a = 0; a < nodes; ++a) f[a] = share[a] * t;
}

}  // namespace shatter
