// Loop basis of a patch with one extraordinary corner, by local subdivision:
// at valence 6 it is the regular basis (reordered), down to points next to
// the corner (many subdivision steps); at other valences a partition of
// unity with consistent derivatives that keeps planar control nets planar;
// the shell element on such a patch is rigid-motion free and its force is
// the energy gradient.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "kernels/shell_kl.hpp"

using namespace shatter;

namespace {

/// Largest difference of two bases at (v, w), each derivative order scaled by
/// (v + w)^order: a point at v + w ~ 2^-n is reached after n subdivision
/// steps, which scale its k-th derivatives, and their round-off, by 2^(n k).
template <int K>
double scaled_difference(const SubdivisionBasis<K>& a, const SubdivisionBasis<K>& b, double v, double w) {
  const double r = v + w;
  return std::max({(a.N - b.N).cwiseAbs().maxCoeff(), r * (a.d1 - b.d1).cwiseAbs().maxCoeff(),
                   r * (a.d2 - b.d2).cwiseAbs().maxCoeff(), r * r * (a.d11 - b.d11).cwiseAbs().maxCoeff(),
                   r * r * (a.d12 - b.d12).cwiseAbs().maxCoeff(), r * r * (a.d22 - b.d22).cwiseAbs().maxCoeff()});
}

/// Points of the triangle, some very near the extraordinary corner.
std::vector<std::array<double, 2>> sample_points() {
  std::vector<std::array<double, 2>> pts = {
      {1.0 / 6, 1.0 / 6}, {2.0 / 3, 1.0 / 6}, {1.0 / 6, 2.0 / 3}, {1.0 / 3, 1.0 / 3}, {0.01, 0.02},
      {1e-4, 3e-5},       {0.3, 0.0},         {0.0, 0.7},         {0.25, 0.25},       {0.5, 0.5}};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (int t = 0; t < 20; ++t) {
    double v = u(rng), w = u(rng);
    if (v + w > 1) v = 1 - v, w = 1 - w;
    pts.push_back({v, w});
  }
  return pts;
}

template <int N>
void check_valence() {
  constexpr int K = N + 6;
  std::mt19937_64 rng(N);
  std::uniform_real_distribution<double> u(-1, 1);
  // A planar control net: x, y anywhere, z = 0.3 x - 0.7 y + 0.2.
  Eigen::Matrix<double, 3, K> X;
  for (int a = 0; a < K; ++a) {
    X(0, a) = u(rng), X(1, a) = u(rng);
    X(2, a) = 0.3 * X(0, a) - 0.7 * X(1, a) + 0.2;
  }
  for (const auto& [v, w] : sample_points()) {
    const auto B = loop_extraordinary_basis<N>(v, w);
    // tolerances scaled as in scaled_difference
    const double r = v + w;
    EXPECT_NEAR(B.N.sum(), 1.0, 1e-14) << "N " << N;
    for (const auto* d : {&B.d1, &B.d2}) EXPECT_LT(r * std::abs(d->sum()), 1e-14) << "N " << N;
    for (const auto* d : {&B.d11, &B.d12, &B.d22}) EXPECT_LT(r * r * std::abs(d->sum()), 1e-14) << "N " << N;
    const Vec3 x = X * B.N, a1 = X * B.d1, a2 = X * B.d2, a12 = X * B.d12;
    EXPECT_NEAR(x.z(), 0.3 * x.x() - 0.7 * x.y() + 0.2, 1e-14) << "N " << N;
    EXPECT_LT(r * std::abs(a1.z() - 0.3 * a1.x() + 0.7 * a1.y()), 1e-14) << "N " << N;
    EXPECT_LT(r * std::abs(a2.z() - 0.3 * a2.x() + 0.7 * a2.y()), 1e-14) << "N " << N;
    EXPECT_LT(r * r * std::abs(a12.z() - 0.3 * a12.x() + 0.7 * a12.y()), 1e-14) << "N " << N;
  }
  // derivatives against finite differences, away from the level boundaries
  const double v = 0.3, w = 0.35, h = 1e-6;
  const auto B = loop_extraordinary_basis<N>(v, w);
  const auto Bv = loop_extraordinary_basis<N>(v + h, w), Bv_ = loop_extraordinary_basis<N>(v - h, w);
  const auto Bw = loop_extraordinary_basis<N>(v, w + h), Bw_ = loop_extraordinary_basis<N>(v, w - h);
  EXPECT_LT((B.d1 - (Bv.N - Bv_.N) / (2 * h)).norm(), 1e-8);
  EXPECT_LT((B.d2 - (Bw.N - Bw_.N) / (2 * h)).norm(), 1e-8);
  EXPECT_LT((B.d11 - (Bv.d1 - Bv_.d1) / (2 * h)).norm(), 1e-7);
  EXPECT_LT((B.d12 - (Bw.d1 - Bw_.d1) / (2 * h)).norm(), 1e-7);
  EXPECT_LT((B.d22 - (Bw.d2 - Bw_.d2) / (2 * h)).norm(), 1e-7);
  // the limit surface is continuous across the level boundary v + w = 1/2
  const auto below = loop_extraordinary_basis<N>(0.2, 0.3 - 1e-9), above = loop_extraordinary_basis<N>(0.2, 0.3 + 1e-9);
  EXPECT_LT((below.N - above.N).norm(), 1e-8);
  EXPECT_LT((below.d1 - above.d1).norm(), 1e-7);
}

/// An extraordinary patch around a corner of valence N: the ring on a
/// slightly wavy cone, Stam's 6, 10, 11, 12, 9 beyond corners 1 and 2.
template <int N>
Eigen::Matrix<double, 3, N + 6> patch_positions() {
  Eigen::Matrix<double, 3, N + 6> X;
  X.col(0) = Vec3(0, 0, 0.05);
  for (int i = 1; i <= N; ++i) {
    const double a = 2 * std::numbers::pi * (i - 1) / N;
    X.col(i) = Vec3(std::cos(a), std::sin(a), 0.1 * std::cos(2 * a));
  }
  const Vec3 b = X.col(1), c = X.col(2), r3 = X.col(3), rN = X.col(N), p = X.col(0);
  X.col(N + 1) = b + rN - p;  // 6
  X.col(N + 2) = 2 * b - p;   // 10
  X.col(N + 3) = b + c - p;   // 11
  X.col(N + 4) = 2 * c - p;   // 12
  X.col(N + 5) = c + r3 - p;  // 9
  return X;
}

template <int N>
void check_shell_on_patch() {
  constexpr int K = N + 6;
  const auto basis = loop_extraordinary_basis_at_quadrature<N, 3>();
  const NeoHookean mat = NeoHookean::from_young_poisson(1e9, 0.3, 1000);
  const auto X = patch_positions<N>();
  const auto ref = shell_reference<K, 3>(X, basis, 0.02);
  std::mt19937_64 rng(N + 100);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Matrix<double, 3, K> x = X;
  for (int a = 0; a < K; ++a) x.col(a) += 0.05 * Vec3(u(rng), u(rng), u(rng));
  const auto out = shell_internal_force<K, 3>(x, basis, ref, mat);
  ASSERT_GT(out.energy, 0);
  const double h = 1e-7;
  for (int a = 0; a < K; ++a)
    for (int k = 0; k < 3; ++k) {
      auto xp = x, xm = x;
      xp(k, a) += h;
      xm(k, a) -= h;
      const double fd = (shell_internal_force<K, 3>(xp, basis, ref, mat).energy -
                         shell_internal_force<K, 3>(xm, basis, ref, mat).energy) /
                        (2 * h);
      EXPECT_NEAR(out.f(k, a), fd, 1e-6 * out.f.norm()) << "N " << N << " vertex " << a;
    }
  const Mat3 R = Eigen::AngleAxisd(1.1, Vec3(0.2, 1, -0.4).normalized()).toRotationMatrix();
  const Eigen::Matrix<double, 3, K> moved = (R * X).colwise() + Vec3(1, 2, 3);
  const auto rigid = shell_internal_force<K, 3>(moved, basis, ref, mat);
  EXPECT_LT(std::abs(rigid.energy), 1e-12 * out.energy);
  EXPECT_LT(rigid.f.norm(), 1e-10 * out.f.norm());
}

}  // namespace

TEST(LoopExtraordinary, ValenceSixIsTheRegularBasis) {
  // ring order -> Stam's names - 1: p = 4, ring 7, 8, 5, 2, 1, 3, then 6, 10, 11, 12, 9
  const int stam[12] = {3, 6, 7, 4, 1, 0, 2, 5, 9, 10, 11, 8};
  for (const auto& [v, w] : sample_points()) {
    const auto R = loop_regular_basis(v, w);
    SubdivisionBasis<12> P;
    for (int a = 0; a < 12; ++a) {
      P.N[a] = R.N[stam[a]];
      P.d1[a] = R.d1[stam[a]];
      P.d2[a] = R.d2[stam[a]];
      P.d11[a] = R.d11[stam[a]];
      P.d12[a] = R.d12[stam[a]];
      P.d22[a] = R.d22[stam[a]];
    }
    EXPECT_LT(scaled_difference<12>(loop_extraordinary_basis<6>(v, w), P, v, w), 1e-14) << v << " " << w;
  }
}

TEST(LoopExtraordinary, PartitionOfUnityDerivativesAndPlanarity) {
  check_valence<3>();
  check_valence<4>();
  check_valence<5>();
  check_valence<7>();
  check_valence<8>();
  check_valence<12>();
}

TEST(LoopExtraordinary, ShellForceIsEnergyGradientAndRigidMotionFree) {
  check_shell_on_patch<3>();
  check_shell_on_patch<5>();
  check_shell_on_patch<7>();
  check_shell_on_patch<9>();
}
