#pragma once
// Loop basis of a patch with one extraordinary corner (valence N != 6), by
// local subdivision (Cirak, Ortiz & Schroeder, IJNME 47 (2000) 2039-2072;
// Stam, SIGGRAPH 1998, also gives the eigenbasis alternative): the patch is
// subdivided until the point falls in one of the three regular sub-triangles
// that surround the corner's sub-triangle, where the regular box-spline
// patch (kernels/loop_basis.hpp) applies.
//
// Patch order (K = N + 6, as mesh/shell_mesh.hpp): 0 the extraordinary
// corner p at (v, w) = (0, 0); 1..N its ring counter-clockwise, 1 at (1, 0)
// and 2 at (0, 1), 3 across the edge 0-2 and N across the edge 0-1; then
// Stam's 6, 10, 11, 12, 9 (kernels/loop_basis.hpp names; lattice offsets
// (2,-1), (2,0), (1,1), (0,2), (-1,2)). Corners 1 and 2 must be regular.
// N = 6 gives the regular basis in this order (the test of the construction).
//
// One subdivision step (Loop's rules; on the extraordinary vertex
// beta = (5/8 - (3/8 + cos(2 pi/N)/4)^2) / N) maps the patch onto the patch
// of the corner's sub-triangle (same order, scaled by 1/2) and the 11
// further vertices the regular sub-triangles need. In half-lattice
// coordinates of the next level, rows of the extended matrix:
//   0 p', 1..N ring edge points (1 at (1,0), 2 at (0,1), 3 at (-1,1), N at (1,-1)),
//   N+1..N+5: (2,-1), (2,0), (1,1), (0,2), (-1,2),
//   N+6..N+11: (3,-1), (3,0), (2,1), (1,2), (-1,3), (0,3).
#include <cmath>
#include <numbers>

#include "kernels/error.hpp"
#include "kernels/loop_basis.hpp"

namespace shatter {

/// The (N + 12) x (N + 6) matrix of one Loop subdivision step of an
/// extraordinary patch (rows: the next level's vertices in the order above).
template <int N>
Eigen::Matrix<double, N + 12, N + 6> loop_extraordinary_subdivision() {
  static_assert(N >= 3, "a corner has valence 3 or more");
  constexpr int K = N + 6;
  Eigen::Matrix<double, N + 12, K> S = Eigen::Matrix<double, N + 12, K>::Zero();
  const int p = 0, b = 1, c = 2, r3 = 3, rN = N, v6 = N + 1, v10 = N + 2, v11 = N + 3, v12 = N + 4, v9 = N + 5;
  auto edge = [&](int row, int e0, int e1, int o0, int o1) {
    S(row, e0) += 3.0 / 8;
    S(row, e1) += 3.0 / 8;
    S(row, o0) += 1.0 / 8;
    S(row, o1) += 1.0 / 8;
  };
  auto regular_vertex = [&](int row, int centre, std::array<int, 6> ring) {
    S(row, centre) += 10.0 / 16;
    for (int r : ring) S(row, r) += 1.0 / 16;
  };
  const double cosine = 3.0 / 8 + 0.25 * std::cos(2 * std::numbers::pi / N);
  const double beta = (5.0 / 8 - cosine * cosine) / N;
  S(0, p) = 1 - N * beta;
  for (int i = 1; i <= N; ++i) {
    S(0, i) = beta;
    edge(i, p, i, i == 1 ? N : i - 1, i == N ? 1 : i + 1);
  }
  edge(N + 1, b, rN, p, v6);                           // (2,-1)
  regular_vertex(N + 2, b, {c, p, rN, v6, v10, v11});  // (2,0)
  edge(N + 3, b, c, p, v11);                           // (1,1)
  regular_vertex(N + 4, c, {p, b, v11, v12, v9, r3});  // (0,2)
  edge(N + 5, c, r3, p, v9);                           // (-1,2)
  edge(N + 6, b, v6, rN, v10);                         // (3,-1)
  edge(N + 7, b, v10, v6, v11);                        // (3,0)
  edge(N + 8, b, v11, v10, c);                         // (2,1)
  edge(N + 9, c, v11, b, v12);                         // (1,2)
  edge(N + 10, c, v9, v12, r3);                        // (-1,3)
  edge(N + 11, c, v12, v11, v9);                       // (0,3)
  return S;
}

namespace detail {

/// Row of the extended next-level patch at half-lattice point (i, j) (one
/// of the points listed above).
template <int N>
int loop_extended_row(int i, int j) {
  // clang-format off
  constexpr int table[][3] = {{0, 0, 0},       {1, 0, 1},       {0, 1, 2},       {-1, 1, 3},      {1, -1, N},
                              {2, -1, N + 1},  {2, 0, N + 2},   {1, 1, N + 3},   {0, 2, N + 4},   {-1, 2, N + 5},
                              {3, -1, N + 6},  {3, 0, N + 7},   {2, 1, N + 8},   {1, 2, N + 9},   {-1, 3, N + 10},
                              {0, 3, N + 11}};
  // clang-format on
  for (const auto& t : table)
    if (t[0] == i && t[1] == j) return t[2];
  SHATTER_ASSERT(false);
  return -1;
}

}  // namespace detail

/// Shape functions of the K = N + 6 patch vertices at (v, w), v, w >= 0,
/// 0 < v + w <= 1, with first and second derivatives in (v, w).
template <int N>
SubdivisionBasis<N + 6> loop_extraordinary_basis(double v, double w) {
  constexpr int K = N + 6;
  SHATTER_REQUIRE(
      v >= 0 && w >= 0 && v + w > 0 && v + w <= 1 + 1e-12,
      "loop_extraordinary_basis: (v, w) = (" << v << ", " << w << ") is not in the triangle or is its corner");
  const Eigen::Matrix<double, N + 12, K> S = loop_extraordinary_subdivision<N>();
  Eigen::Matrix<double, K, K> C = Eigen::Matrix<double, K, K>::Identity();
  double scale = 2;  // d(parameter of the regular sub-triangle) / d(v, w), up to sign
  while (v + w < 0.5) {
    C = S.template topRows<K>() * C;
    v *= 2;
    w *= 2;
    scale *= 2;
  }
  const Eigen::Matrix<double, N + 12, K> E = S * C;
  // The regular sub-triangle holding (v, w): its corner 4 and the sign of
  // its lattice directions (inverted: the central triangle, a half turn).
  int base_i, base_j, sign;
  double vl, wl;
  if (v >= 0.5) {
    base_i = 1, base_j = 0, sign = 1, vl = 2 * v - 1, wl = 2 * w;
  } else if (w >= 0.5) {
    base_i = 0, base_j = 1, sign = 1, vl = 2 * v, wl = 2 * w - 1;
  } else {
    base_i = 1, base_j = 1, sign = -1, vl = 1 - 2 * v, wl = 1 - 2 * w;
  }
  const SubdivisionBasis<12> R = loop_regular_basis(vl, wl);
  SubdivisionBasis<K> B;
  B.N.setZero();
  B.d1.setZero();
  B.d2.setZero();
  B.d11.setZero();
  B.d12.setZero();
  B.d22.setZero();
  for (int a = 0; a < 12; ++a) {
    const int row = detail::loop_extended_row<N>(base_i + sign * kLoopRegularLattice[a][0],
                                                 base_j + sign * kLoopRegularLattice[a][1]);
    const auto e = E.row(row).transpose();
    B.N += R.N[a] * e;
    B.d1 += (sign * scale * R.d1[a]) * e;
    B.d2 += (sign * scale * R.d2[a]) * e;
    B.d11 += (scale * scale * R.d11[a]) * e;
    B.d12 += (scale * scale * R.d12[a]) * e;
    B.d22 += (scale * scale * R.d22[a]) * e;
  }
  return B;
}

}  // namespace shatter
