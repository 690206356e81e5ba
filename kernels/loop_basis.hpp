#pragma once
// Loop subdivision basis of a regular patch: the 12 quartic box-spline
// shape functions of a triangle whose three corners have valence 6
// (Stam, "Evaluation of Loop subdivision surfaces", SIGGRAPH 1998, appendix;
// Cirak, Ortiz & Schroeder, IJNME 47 (2000) 2039-2072, appendix).
//
// Parametrisation: a point of the triangle is (v, w), u = 1 - v - w, with
// corner 4 at (0, 0), corner 7 at (1, 0) and corner 8 at (0, 1) (Stam's
// 1-based names; array index = name - 1). The 12 control vertices sit on the
// regular triangular lattice at these (v, w) lattice offsets from corner 4:
//
//        name:    1       2       3      4      5       6      7      8       9      10     11     12
//        (v, w): (0,-1) (-1,0)  (1,-1) (0,0)  (-1,1)  (2,-1) (1,0)  (0,1)  (-1,2)  (2,0)  (1,1)  (0,2)
//
//   i.e. the triangle (4, 7, 8), counter-clockwise about its normal
//   a1 x a2, and its 1-ring: 3, 5, 11 across the edges 4-7, 8-4, 7-8; 1, 2
//   beyond corner 4; 6, 10 beyond corner 7; 9, 12 beyond corner 8.
//
// Every shape function is 1/12 x a quartic in (u, v, w); the table below
// gives the integer coefficients of the 15 monomials u^i v^j w^k.
#include <array>

#include <Eigen/Dense>

namespace shatter {

/// Shape functions of NV control vertices and their first and second
/// derivatives with respect to the parameters (theta1, theta2) = (v, w).
template <int NV>
struct SubdivisionBasis {
  using Vector = Eigen::Matrix<double, NV, 1>;
  Vector N, d1, d2, d11, d12, d22;
};

// clang-format off
/// Exponents (i, j, k) of u^i v^j w^k, the columns of kLoopRegularCoefficients.
inline constexpr std::array<std::array<int, 3>, 15> kLoopMonomials = {{
    {4, 0, 0}, {3, 1, 0}, {3, 0, 1}, {2, 2, 0}, {2, 1, 1}, {2, 0, 2}, {1, 3, 0}, {1, 2, 1},
    {1, 1, 2}, {1, 0, 3}, {0, 4, 0}, {0, 3, 1}, {0, 2, 2}, {0, 1, 3}, {0, 0, 4},
}};

/// 12 x the box-spline shape functions, row = vertex (Stam's name - 1),
/// column = monomial of kLoopMonomials.
inline constexpr std::array<std::array<int, 15>, 12> kLoopRegularCoefficients = {{
    //u4 u3v u3w u2v2 u2vw u2w2 uv3 uv2w uvw2 uw3 v4 v3w v2w2 vw3 w4
    {1, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {1, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {1, 6, 2, 12, 6, 0, 6, 6, 0, 0, 1, 2, 0, 0, 0},
    {6, 24, 24, 24, 60, 24, 8, 36, 36, 8, 1, 6, 12, 6, 1},
    {1, 2, 6, 0, 6, 12, 0, 0, 6, 6, 0, 0, 0, 2, 1},
    {0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 0},
    {1, 8, 6, 24, 36, 12, 24, 60, 36, 6, 6, 24, 24, 8, 1},
    {1, 6, 8, 12, 36, 24, 6, 36, 60, 24, 1, 8, 24, 24, 6},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 0, 0, 0},
    {0, 0, 0, 0, 0, 0, 2, 6, 6, 2, 1, 6, 12, 6, 1},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 1},
}};

/// Lattice offsets (v, w) of the 12 control vertices from corner 4 (index 3).
inline constexpr std::array<std::array<int, 2>, 12> kLoopRegularLattice = {{
    {0, -1}, {-1, 0}, {1, -1}, {0, 0}, {-1, 1}, {2, -1}, {1, 0}, {0, 1}, {-1, 2}, {2, 0}, {1, 1}, {0, 2},
}};

// clang-format on

namespace detail {

/// d^(p+q+r) / du^p dv^q dw^r of u^i v^j w^k at (u, v, w), as if u, v, w were independent.
inline double monomial_partial(const std::array<int, 3>& e, int p, int q, int r, double u, double v, double w) {
  const int d[3] = {p, q, r};
  const double x[3] = {u, v, w};
  double value = 1.0;
  for (int c = 0; c < 3; ++c) {
    if (e[c] < d[c]) return 0.0;
    for (int m = 0; m < d[c]; ++m) value *= e[c] - m;
    for (int m = 0; m < e[c] - d[c]; ++m) value *= x[c];
  }
  return value;
}

}  // namespace detail

/// The 12 regular-patch shape functions at (v, w) and their derivatives in
/// v and w (u = 1 - v - w, so d/dv = D_v - D_u and d/dw = D_w - D_u with D
/// the partial derivatives of the (u, v, w) polynomial).
inline SubdivisionBasis<12> loop_regular_basis(double v, double w) {
  const double u = 1.0 - v - w;
  SubdivisionBasis<12> B;
  for (int a = 0; a < 12; ++a) {
    double N = 0, d1 = 0, d2 = 0, d11 = 0, d12 = 0, d22 = 0;
    for (int m = 0; m < 15; ++m) {
      const int c = kLoopRegularCoefficients[a][m];
      if (c == 0) continue;
      const auto& e = kLoopMonomials[m];
      auto D = [&](int p, int q, int r) { return detail::monomial_partial(e, p, q, r, u, v, w); };
      N += c * D(0, 0, 0);
      d1 += c * (D(0, 1, 0) - D(1, 0, 0));
      d2 += c * (D(0, 0, 1) - D(1, 0, 0));
      d11 += c * (D(0, 2, 0) - 2 * D(1, 1, 0) + D(2, 0, 0));
      d12 += c * (D(0, 1, 1) - D(1, 1, 0) - D(1, 0, 1) + D(2, 0, 0));
      d22 += c * (D(0, 0, 2) - 2 * D(1, 0, 1) + D(2, 0, 0));
    }
    B.N[a] = N / 12;
    B.d1[a] = d1 / 12;
    B.d2[a] = d2 / 12;
    B.d11[a] = d11 / 12;
    B.d12[a] = d12 / 12;
    B.d22[a] = d22 / 12;
  }
  return B;
}

}  // namespace shatter
