// Loop regular-patch basis: partition of unity, derivatives against finite
// differences, the Loop limit mask at the corners, and the refinement
// equation (one step of Loop subdivision of the control net leaves the limit
// surface, its first and second derivatives unchanged), which pins the box
// spline down.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <utility>

#include "kernels/loop_basis.hpp"

using namespace shatter;

namespace {
using Point = std::pair<int, int>;

/// Random control values on the lattice points |i|, |j| <= 6.
std::map<Point, double> random_net(unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::map<Point, double> f;
  for (int i = -6; i <= 6; ++i)
    for (int j = -6; j <= 6; ++j) f[{i, j}] = u(rng);
  return f;
}

/// One step of Loop subdivision on the regular lattice (valence 6: vertex
/// rule 10/16 + 1/16 per neighbour; edge rule 3/8 + 3/8 + 1/8 + 1/8), on the
/// level-1 points |I|, |J| <= 6.
std::map<Point, double> loop_refine(const std::map<Point, double>& f) {
  auto at = [&](int i, int j) { return f.at({i, j}); };
  std::map<Point, double> g;
  for (int I = -6; I <= 6; ++I)
    for (int J = -6; J <= 6; ++J) {
      const bool ei = I % 2 == 0, ej = J % 2 == 0;
      double value;
      if (ei && ej) {
        const int i = I / 2, j = J / 2;
        value = 10.0 / 16 * at(i, j) +
                1.0 / 16 *
                    (at(i + 1, j) + at(i - 1, j) + at(i, j + 1) + at(i, j - 1) + at(i + 1, j - 1) + at(i - 1, j + 1));
      } else if (!ei && ej) {  // edge along (1, 0) from P
        const int i = (I - 1) / 2, j = J / 2;
        value = 3.0 / 8 * (at(i, j) + at(i + 1, j)) + 1.0 / 8 * (at(i, j + 1) + at(i + 1, j - 1));
      } else if (ei && !ej) {  // edge along (0, 1)
        const int i = I / 2, j = (J - 1) / 2;
        value = 3.0 / 8 * (at(i, j) + at(i, j + 1)) + 1.0 / 8 * (at(i + 1, j) + at(i - 1, j + 1));
      } else {  // edge along (1, -1) from P = ((I-1)/2, (J+1)/2)
        const int i = (I - 1) / 2, j = (J + 1) / 2;
        value = 3.0 / 8 * (at(i, j) + at(i + 1, j - 1)) + 1.0 / 8 * (at(i + 1, j) + at(i, j - 1));
      }
      g[{I, J}] = value;
    }
  return g;
}

/// Value and derivatives of the patch whose corner 4 sits at lattice point `base`.
std::array<double, 6> patch(const std::map<Point, double>& f, Point base, double v, double w) {
  const SubdivisionBasis<12> B = loop_regular_basis(v, w);
  std::array<double, 6> s{};
  for (int a = 0; a < 12; ++a) {
    const double c = f.at({base.first + kLoopRegularLattice[a][0], base.second + kLoopRegularLattice[a][1]});
    s[0] += c * B.N[a];
    s[1] += c * B.d1[a];
    s[2] += c * B.d2[a];
    s[3] += c * B.d11[a];
    s[4] += c * B.d12[a];
    s[5] += c * B.d22[a];
  }
  return s;
}
}  // namespace

TEST(LoopBasis, PartitionOfUnityAndNonNegative) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  for (int t = 0; t < 200; ++t) {
    double v = u(rng), w = u(rng);
    if (v + w > 1) v = 1 - v, w = 1 - w;
    const auto B = loop_regular_basis(v, w);
    EXPECT_NEAR(B.N.sum(), 1.0, 1e-15);
    EXPECT_GE(B.N.minCoeff(), 0.0);
    for (const auto* d : {&B.d1, &B.d2, &B.d11, &B.d12, &B.d22}) EXPECT_LT(std::abs(d->sum()), 1e-14);
  }
}

TEST(LoopBasis, DerivativesMatchFiniteDifferences) {
  const double v = 0.23, w = 0.41, h = 1e-6;
  const auto B = loop_regular_basis(v, w);
  const auto Bv = loop_regular_basis(v + h, w), Bv_ = loop_regular_basis(v - h, w);
  const auto Bw = loop_regular_basis(v, w + h), Bw_ = loop_regular_basis(v, w - h);
  EXPECT_LT((B.d1 - (Bv.N - Bv_.N) / (2 * h)).norm(), 1e-9);
  EXPECT_LT((B.d2 - (Bw.N - Bw_.N) / (2 * h)).norm(), 1e-9);
  EXPECT_LT((B.d11 - (Bv.d1 - Bv_.d1) / (2 * h)).norm(), 1e-8);
  EXPECT_LT((B.d12 - (Bw.d1 - Bw_.d1) / (2 * h)).norm(), 1e-8);
  EXPECT_LT((B.d12 - (Bv.d2 - Bv_.d2) / (2 * h)).norm(), 1e-8);
  EXPECT_LT((B.d22 - (Bw.d2 - Bw_.d2) / (2 * h)).norm(), 1e-8);
}

TEST(LoopBasis, CornersTakeTheLoopLimitMask) {
  // valence 6: the limit point is 1/2 the vertex + 1/12 each of its 6 neighbours
  const int corner[3] = {3, 6, 7};
  const double vw[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  for (int c = 0; c < 3; ++c) {
    const auto B = loop_regular_basis(vw[c][0], vw[c][1]);
    for (int a = 0; a < 12; ++a) {
      const int dv = kLoopRegularLattice[a][0] - kLoopRegularLattice[corner[c]][0];
      const int dw = kLoopRegularLattice[a][1] - kLoopRegularLattice[corner[c]][1];
      const bool neighbour = (std::abs(dv) + std::abs(dw) == 1) || (dv == -dw && std::abs(dv) == 1);
      EXPECT_NEAR(B.N[a],
                  a == corner[c] ? 0.5
                  : neighbour    ? 1.0 / 12
                                 : 0.0,
                  1e-15)
          << "corner " << c << " vertex " << a;
    }
  }
}

TEST(LoopBasis, OneSubdivisionStepLeavesTheLimitSurface) {
  const auto f0 = random_net(7);
  const auto f1 = loop_refine(f0);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 1);
  // the three upright sub-triangles of level 1 inside the level-0 triangle
  const Point bases[3] = {{0, 0}, {1, 0}, {0, 1}};
  for (const Point& b : bases)
    for (int t = 0; t < 20; ++t) {
      double s = u(rng), r = u(rng);
      if (s + r > 1) s = 1 - s, r = 1 - r;
      const double v = 0.5 * (b.first + s), w = 0.5 * (b.second + r);
      const auto S0 = patch(f0, {0, 0}, v, w);
      const auto S1 = patch(f1, b, s, r);
      EXPECT_NEAR(S1[0], S0[0], 1e-14);
      EXPECT_NEAR(2 * S1[1], S0[1], 1e-13);
      EXPECT_NEAR(2 * S1[2], S0[2], 1e-13);
      for (int k = 3; k < 6; ++k) EXPECT_NEAR(4 * S1[k], S0[k], 1e-12) << "derivative " << k;
    }
}
