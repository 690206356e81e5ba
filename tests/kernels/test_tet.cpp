// TET4 and TET10 kernels: partition of unity, gradients, quadratic exactness,
// internal force = dE/dx, patch tests, HRZ mass fractions, lanes = one element.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "expect_close.hpp"
#include "kernels/tet10.hpp"
#include "kernels/tet4.hpp"

using namespace shatter;

namespace {
const NeoHookean kMat = NeoHookean::from_young_poisson(1e9, 0.3, 1000);

Tet10Nodes straight_tet10(const std::array<Vec3, 4>& c) {
  Tet10Nodes X;
  for (int i = 0; i < 4; ++i) X.col(i) = c[i];
  for (int e = 0; e < 6; ++e) X.col(4 + e) = 0.5 * (c[kTet10Edges[e][0]] + c[kTet10Edges[e][1]]);
  return X;
}
const std::array<Vec3, 4> kCorners = {Vec3(0.1, 0, 0), Vec3(1.2, 0.1, 0), Vec3(0.2, 0.9, 0.1),
                                      Vec3(0.3, 0.2, 1.1)};
}  // namespace

TEST(Tet10, PartitionOfUnityAndNodalInterpolation) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int t = 0; t < 50; ++t) {
    Vec3 p(u(rng), u(rng), u(rng));
    p /= std::max(1.0, p.sum() * 1.01);
    EXPECT_NEAR(tet10_shape(p).sum(), 1.0, 1e-14);
    EXPECT_LT(tet10_shape_derivatives(p).colwise().sum().norm(), 1e-14);
  }
  // N_a(node b) = delta_ab
  const Tet10Nodes ref = straight_tet10({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)});
  for (int b = 0; b < 10; ++b) {
    const auto N = tet10_shape(ref.col(b));
    for (int a = 0; a < 10; ++a) EXPECT_NEAR(N[a], a == b ? 1.0 : 0.0, 1e-15);
  }
}

TEST(Tet10, ShapeDerivativesMatchFiniteDifferences) {
  const Vec3 p(0.2, 0.3, 0.1);
  const auto d = tet10_shape_derivatives(p);
  for (int k = 0; k < 3; ++k) {
    Vec3 dp = Vec3::Zero();
    dp[k] = 1e-6;
    const Eigen::Matrix<double, 10, 1> fd = (tet10_shape(p + dp) - tet10_shape(p - dp)) / 2e-6;
    EXPECT_LT((d.col(k) - fd).norm(), 1e-9);
  }
}

TEST(Tet10, ExactForQuadraticFields) {
  // u(X) = X^T A X + b.X: interpolated from nodes, value and gradient exact.
  Mat3 A;
  A << 1, 0.5, -0.3, 0.5, 2, 0.1, -0.3, 0.1, -1;
  const Vec3 b(0.3, -0.7, 1.1);
  auto u = [&](const Vec3& X) { return X.dot(A * X) + b.dot(X); };
  const Tet10Nodes X = straight_tet10(kCorners);
  Eigen::Matrix<double, 10, 1> un;
  for (int a = 0; a < 10; ++a) un[a] = u(X.col(a));
  const Tet10Reference ref = tet10_reference(X);
  const auto& pts = tet10_quadrature_points();
  for (int q = 0; q < 4; ++q) {
    const Vec3 Xq = X * tet10_shape(pts[q]);
    EXPECT_NEAR(un.dot(tet10_shape(pts[q])), u(Xq), 1e-13);
    const Vec3 grad = tet10_gradients(ref, q).transpose() * un;
    EXPECT_LT((grad - (2 * A * Xq + b)).norm(), 1e-12);
  }
  EXPECT_CLOSE(ref.volume, tet_signed_volume(kCorners[0], kCorners[1], kCorners[2], kCorners[3]), 1e-14, 0);
}

TEST(Tet10, HrzMassFractionsOfAStraightElement) {
  const auto m = tet10_hrz_mass_fractions(straight_tet10(kCorners));
  for (int a = 0; a < 4; ++a) EXPECT_NEAR(m[a], 1.0 / 36.0, 1e-14);
  for (int a = 4; a < 10; ++a) EXPECT_NEAR(m[a], 4.0 / 27.0, 1e-14);
}

TEST(Tet4, InternalForceIsEnergyGradientAndBalanced) {
  const Tet4Reference ref = tet4_reference(kCorners[0], kCorners[1], kCorners[2], kCorners[3]);
  Eigen::Matrix<double, 3, 4> x;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int a = 0; a < 4; ++a) x.col(a) = kCorners[a] + Vec3(u(rng), u(rng), u(rng));
  auto run = [&](const Eigen::Matrix<double, 3, 4>& y) {
    return tet4_internal_force(y.col(0), y.col(1), y.col(2), y.col(3), ref.Dm_inv, ref.volume, kMat);
  };
  const auto out = run(x);
  const double h = 1e-7;
  for (int a = 0; a < 4; ++a)
    for (int k = 0; k < 3; ++k) {
      auto xp = x, xm = x;
      xp(k, a) += h;
      xm(k, a) -= h;
      EXPECT_NEAR(out.f(k, a), (run(xp).energy - run(xm).energy) / (2 * h), 1e-5 * out.f.norm());
    }
  // linear and angular momentum balance of internal forces
  EXPECT_LT(out.f.rowwise().sum().norm(), 1e-12 * out.f.norm());
  Vec3 torque = Vec3::Zero();
  for (int a = 0; a < 4; ++a) torque += Vec3(x.col(a)).cross(Vec3(out.f.col(a)));
  EXPECT_LT(torque.norm(), 1e-12 * out.f.norm());
}

TEST(Tet10, InternalForceIsEnergyGradientAndBalanced) {
  Tet10Nodes X = straight_tet10(kCorners);
  X.col(5) += Vec3(0.02, 0.03, -0.01);  // a curved edge
  const Tet10Reference ref = tet10_reference(X);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  Tet10Nodes x = X;
  for (int a = 0; a < 10; ++a) x.col(a) += Vec3(u(rng), u(rng), u(rng));
  const auto out = tet10_internal_force(x, ref, kMat);
  const double h = 1e-7;
  for (int a = 0; a < 10; ++a)
    for (int k = 0; k < 3; ++k) {
      Tet10Nodes xp = x, xm = x;
      xp(k, a) += h;
      xm(k, a) -= h;
      const double fd = (tet10_internal_force(xp, ref, kMat).energy - tet10_internal_force(xm, ref, kMat).energy) / (2 * h);
      EXPECT_NEAR(out.f(k, a), fd, 1e-5 * out.f.norm());
    }
  EXPECT_LT(out.f.rowwise().sum().norm(), 1e-12 * out.f.norm());
  Vec3 torque = Vec3::Zero();
  for (int a = 0; a < 10; ++a) torque += Vec3(x.col(a)).cross(Vec3(out.f.col(a)));
  EXPECT_LT(torque.norm(), 1e-12 * out.f.norm());
}

TEST(Tet, AffineMotionGivesUniformStressAndZeroNetForce) {
  // Patch test at element level: an affine deformation gives F exactly.
  Mat3 G;
  G << 1.05, 0.02, -0.01, 0.03, 0.97, 0.04, 0.0, -0.02, 1.01;
  const Vec3 t(0.3, -0.2, 0.5);
  const Tet4Reference r4 = tet4_reference(kCorners[0], kCorners[1], kCorners[2], kCorners[3]);
  std::array<Vec3, 4> x;
  for (int a = 0; a < 4; ++a) x[a] = G * kCorners[a] + t;
  EXPECT_LT((tet4_deformation_gradient(x[0], x[1], x[2], x[3], r4.Dm_inv) - G).norm(), 1e-14);
  const Tet10Nodes X = straight_tet10(kCorners);
  const Tet10Reference r10 = tet10_reference(X);
  const Tet10Nodes x10 = (G * X).colwise() + t;
  for (int q = 0; q < 4; ++q) EXPECT_LT((x10 * tet10_gradients(r10, q) - G).norm(), 1e-14);
}

TEST(Tet4, MinAltitude) {
  // unit right tetrahedron: altitude to the slanted face = 1/sqrt(3)
  EXPECT_NEAR(tet_min_altitude(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)), 1 / std::sqrt(3.0), 1e-15);
}

TEST(Tet, LaneKernelsGiveEachElementItsOneElementBits) {
  // The element loop runs groups of 8 elements through the lane kernels and
  // the others one by one (runtime/element_forces.cpp): an element's forces,
  // energy and det F (hence ln J, lane_log) must have the same bits in any
  // lane as alone, or ranks x threads would change the results. Eight
  // different deformations, det F from ~0.3 to ~3.
  constexpr int N = 8;
  auto same = [](const double* a, const double* b, int n) { return std::memcmp(a, b, n * sizeof(double)) == 0; };
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  const Tet4Reference r4 = tet4_reference(kCorners[0], kCorners[1], kCorners[2], kCorners[3]);
  const Tet10Nodes X = straight_tet10(kCorners);
  std::array<Tet10Reference, N> r10;  // lane l: one curved edge, so dxi/dX differs by point and lane
  std::array<Tet10Nodes, N> x;
  Tet4Lanes<N> L4;
  Tet10Lanes<N> L10;
  for (int l = 0; l < N; ++l) {
    Tet10Nodes Xl = X;
    Xl.col(4 + l % 6) += Vec3(u(rng), u(rng), u(rng));
    r10[l] = tet10_reference(Xl);
    const double s = std::pow(1.45, l - 3);  // volume ratio s^3
    x[l] = s * Xl;
    for (int a = 0; a < 10; ++a) x[l].col(a) += Vec3(u(rng), u(rng), u(rng));
    for (int q = 0; q < 12; ++q) L4.x[q][l] = x[l].data()[q];
    for (int q = 0; q < 9; ++q) L4.Dm_inv[q][l] = r4.Dm_inv.data()[q];
    L4.V0[l] = r4.volume;
    for (int q = 0; q < 30; ++q) L10.x[q][l] = x[l].data()[q];
    tet10_reference_into_lanes(r10[l], L10, l);
  }
  tet4_neo_hookean_lanes(L4, kMat);
  tet10_neo_hookean_lanes(L10, kMat);
  EXPECT_LT(L4.J[0], 0.5);
  EXPECT_GT(L4.J[N - 1], 2.0);
  for (int l = 0; l < N; ++l) {
    const auto one4 = tet4_internal_force(x[l].col(0), x[l].col(1), x[l].col(2), x[l].col(3), r4.Dm_inv, r4.volume, kMat);
    double f4[12], f10[30];
    for (int q = 0; q < 12; ++q) f4[q] = L4.f[q][l];
    for (int q = 0; q < 30; ++q) f10[q] = L10.f[q][l];
    EXPECT_TRUE(same(f4, one4.f.data(), 12)) << "TET4 lane " << l;
    EXPECT_TRUE(same(&L4.energy[l], &one4.energy, 1) && same(&L4.J[l], &one4.J, 1)) << "TET4 lane " << l;
    const auto one10 = tet10_internal_force(x[l], r10[l], kMat);
    EXPECT_TRUE(same(f10, one10.f.data(), 30)) << "TET10 lane " << l;
    EXPECT_TRUE(same(&L10.energy[l], &one10.energy, 1) && same(&L10.J[l], &one10.J, 1)) << "TET10 lane " << l;
  }
}

TEST(Tet10, LaneKernelIsTheGradientFormula) {
  // The lane kernel takes dN/dX = dN/dxi dxi/dX through the barycentrics
  // (kernels/tet10.hpp); the textbook form f_a = sum_q w_q P(F_q) dN_a/dX,
  // F_q = x dN/dX (Eigen, NeoHookean::stress) must agree to round-off, on a
  // curved element under a large deformation.
  Tet10Nodes X = straight_tet10(kCorners);
  X.col(5) += Vec3(0.02, 0.03, -0.01);
  X.col(7) += Vec3(-0.015, 0.01, 0.02);
  const Tet10Reference ref = tet10_reference(X);
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  Tet10Nodes x = 1.3 * X;
  for (int a = 0; a < 10; ++a) x.col(a) += Vec3(u(rng), u(rng), u(rng));
  Eigen::Matrix<double, 3, 10> f = Eigen::Matrix<double, 3, 10>::Zero();
  double energy = 0, J = HUGE_VAL;
  for (int q = 0; q < 4; ++q) {
    const Tet10Gradients dNdX = tet10_gradients(ref, q);
    const Mat3 F = x * dNdX;
    f += ref.wdetJ[q] * kMat.stress(F) * dNdX.transpose();
    energy += ref.wdetJ[q] * kMat.energy(F);
    J = std::min(J, F.determinant());
  }
  const Tet10Force lanes = tet10_internal_force(x, ref, kMat);
  EXPECT_LT((lanes.f - f).norm(), 1e-13 * f.norm());
  EXPECT_NEAR(lanes.energy, energy, 1e-13 * std::abs(energy));
  EXPECT_NEAR(lanes.J, J, 1e-14 * J);
}
