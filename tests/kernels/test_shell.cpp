// Subdivision Kirchhoff-Love shell element: rigid motions give no energy and
// no force, the force is the energy gradient, it carries no net force or
// torque, pure bending to a cylinder gives D / (2 R^2), in-plane stretch
// gives the plane-stress Neo-Hookean membrane energy.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "expect_close.hpp"
#include "kernels/shell_kl.hpp"

using namespace shatter;

namespace {
using Patch = Eigen::Matrix<double, 3, 12>;
constexpr double kYoung = 2.1e11, kPoisson = 0.3, kDensity = 7850;
const NeoHookean kMat = NeoHookean::from_young_poisson(kYoung, kPoisson, kDensity);
const auto kBasis = loop_regular_basis_at_quadrature<3>();

/// A flat regular patch of equilateral triangles of edge `edge` in the
/// plane z = 0, corner 4 at the origin, edge 4-7 along x rotated by `angle`.
Patch flat_patch(double edge, double angle = 0.0) {
  const Vec3 e1 = edge * Vec3(std::cos(angle), std::sin(angle), 0);
  const Vec3 e2 = edge * Vec3(std::cos(angle + M_PI / 3), std::sin(angle + M_PI / 3), 0);
  Patch X;
  for (int a = 0; a < 12; ++a) X.col(a) = kLoopRegularLattice[a][0] * e1 + kLoopRegularLattice[a][1] * e2;
  return X;
}

/// A curved, slightly irregular patch (reference) and a deformed copy.
Patch curved_patch(unsigned seed, double amplitude) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Patch X = flat_patch(0.1);
  for (int a = 0; a < 12; ++a) {
    const Vec3 p = X.col(a);
    X.col(a) += Vec3(0, 0, 0.8 * (p.x() * p.x() - 0.5 * p.y() * p.y() + 0.3 * p.x() * p.y()));
    X.col(a) += amplitude * 0.1 * Vec3(u(rng), u(rng), u(rng));
  }
  return X;
}

double element_area(const ShellReference<3>& ref) {
  double area = 0;
  for (const auto& r : ref) area += r.area_weight;
  return area;
}

/// Plane-stress Neo-Hookean energy density per reference area of the in-plane
/// stretches l1, l2 (thickness t), with the normal stretch found by bisection.
double membrane_energy_density(double l1, double l2, double t) {
  const double mu = kMat.mu, lambda = kMat.lambda;
  auto S33 = [&](double c) { return mu * (c - 1) + 0.5 * lambda * std::log(l1 * l1 * l2 * l2 * c); };
  double lo = 1e-3, hi = 1e3;
  for (int i = 0; i < 200; ++i) (S33(0.5 * (lo + hi)) > 0 ? hi : lo) = 0.5 * (lo + hi);
  const double c = 0.5 * (lo + hi);
  const double lnJ = 0.5 * std::log(l1 * l1 * l2 * l2 * c);
  return t * (0.5 * mu * (l1 * l1 + l2 * l2 + c - 3) - mu * lnJ + 0.5 * lambda * lnJ * lnJ);
}
}  // namespace

TEST(Shell, RigidMotionsGiveNoEnergyAndNoForce) {
  const double t = 0.004;
  const Patch X = curved_patch(1, 0.3);
  const auto ref = shell_reference<12, 3>(X, kBasis, t);
  // force and energy scales: a 1 % stretch
  const Patch x1 = 1.01 * X;
  const auto scale = shell_internal_force<12, 3>(x1, kBasis, ref, kMat);
  ASSERT_GT(scale.energy, 0);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  for (const Patch& x : {Patch(X.colwise() + Vec3(3, -1, 2)), Patch((R * X).colwise() + Vec3(-1, 0.5, 4))}) {
    const auto out = shell_internal_force<12, 3>(x, kBasis, ref, kMat);
    EXPECT_LT(std::abs(out.energy), 1e-12 * scale.energy);
    EXPECT_LT(out.f.norm(), 1e-10 * scale.f.norm());
  }
}

TEST(Shell, ForceIsEnergyGradientAndBalanced) {
  const double t = 0.01;
  const Patch X = curved_patch(2, 0.3);
  const auto ref = shell_reference<12, 3>(X, kBasis, t);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Patch x = X;  // a finite deformation: ~10 % strains and bending
  for (int a = 0; a < 12; ++a) x.col(a) += 0.01 * Vec3(u(rng), u(rng), u(rng));
  const auto out = shell_internal_force<12, 3>(x, kBasis, ref, kMat);
  const double h = 1e-7;
  for (int a = 0; a < 12; ++a)
    for (int k = 0; k < 3; ++k) {
      Patch xp = x, xm = x;
      xp(k, a) += h;
      xm(k, a) -= h;
      const double fd = (shell_internal_force<12, 3>(xp, kBasis, ref, kMat).energy -
                         shell_internal_force<12, 3>(xm, kBasis, ref, kMat).energy) /
                        (2 * h);
      EXPECT_NEAR(out.f(k, a), fd, 1e-6 * out.f.norm()) << "vertex " << a << " component " << k;
    }
  // no net force, no net torque
  EXPECT_LT(out.f.rowwise().sum().norm(), 1e-13 * out.f.norm());
  Vec3 torque = Vec3::Zero();
  for (int a = 0; a < 12; ++a) torque += Vec3(x.col(a)).cross(Vec3(out.f.col(a)));
  EXPECT_LT(torque.norm(), 1e-13 * out.f.norm() * x.norm());
}

TEST(Shell, BendingToACylinderGivesTheBendingEnergy) {
  // A flat patch (edge l) rolled onto a cylinder of radius R: the energy per
  // unit area is D / (2 R^2), D = E t^3 / (12 (1 - nu^2)), up to the limit
  // surface's distance from the cylinder (curvature and membrane strain of
  // relative order (l/R)^2 = 1e-4) and the material's nonlinearity (bending
  // strains t / 2R = 0.5 %: relative order (t/R)^2 = 1e-4). Measured 9.2e-5 at
  // every angle (4.7e-4 at l = 0.02, 5.4e-3 at l = 0.04: the membrane part goes
  // as l^4 / (R t)^2). Bound: 1e-3.
  const double t = 0.01, R = 1.0, l = 0.01;
  const double D = kYoung * t * t * t / (12 * (1 - kPoisson * kPoisson));
  for (double angle : {0.0, 0.3, M_PI / 2}) {  // the axis at any angle to the lattice
    const Patch X = flat_patch(l, angle);
    const auto ref = shell_reference<12, 3>(X, kBasis, t);
    Patch x;
    for (int a = 0; a < 12; ++a) {
      const Vec3 p = X.col(a);
      x.col(a) = Vec3(R * std::sin(p.x() / R), p.y(), R * (1 - std::cos(p.x() / R)));
    }
    const auto out = shell_internal_force<12, 3>(x, kBasis, ref, kMat);
    EXPECT_CLOSE(out.energy / element_area(ref), D / (2 * R * R), 1e-3, 0) << "angle " << angle;
  }
}

TEST(Shell, QuadraticBendingGivesThePlateBendingEnergy) {
  // Control net on z = (k1 x^2 + k2 y^2) / 2 + k12 x y: the limit surface has
  // the same second derivatives, so the energy density is the plate's
  // D/2 (k1^2 + k2^2 + 2 nu k1 k2 + 2 (1 - nu) k12^2), synclastic,
  // anticlastic and twisted alike, up to the membrane strains of a
  // non-developable surface and the material's nonlinearity (both ~1e-4 of
  // it here; measured 2.4e-5 to 2.8e-5). Bound: 2e-4.
  const double t = 0.01, l = 0.01;
  const double D = kYoung * t * t * t / (12 * (1 - kPoisson * kPoisson));
  Patch X = flat_patch(l);
  X.colwise() -= X.rowwise().mean();
  const auto ref = shell_reference<12, 3>(X, kBasis, t);
  for (const auto& k :
       {std::array{1.0, 1.0, 0.0}, std::array{1.0, -1.0, 0.0}, std::array{0.0, 0.0, 1.0}, std::array{0.5, -0.2, 0.7}}) {
    Patch x = X;
    for (int a = 0; a < 12; ++a) {
      const double px = X(0, a), py = X(1, a);
      x(2, a) = 0.5 * (k[0] * px * px + k[1] * py * py) + k[2] * px * py;
    }
    const double plate =
        0.5 * D * (k[0] * k[0] + k[1] * k[1] + 2 * kPoisson * k[0] * k[1] + 2 * (1 - kPoisson) * k[2] * k[2]);
    const auto out = shell_internal_force<12, 3>(x, kBasis, ref, kMat);
    EXPECT_CLOSE(out.energy / element_area(ref), plate, 2e-4, 0) << k[0] << " " << k[1] << " " << k[2];
  }
}

TEST(Shell, InPlaneStretchGivesTheMembraneEnergy) {
  const double t = 0.002;
  const Patch X = flat_patch(0.05, 0.2);
  const auto ref = shell_reference<12, 3>(X, kBasis, t);
  for (const auto& [l1, l2] :
       {std::pair{1.2, 1.0}, std::pair{1.1, 0.9}, std::pair{0.8, 0.7}, std::pair{1.0 + 1e-4, 1.0}}) {
    Patch x = X;
    x.row(0) *= l1;
    x.row(1) *= l2;
    const auto out = shell_internal_force<12, 3>(x, kBasis, ref, kMat);
    // the Loop basis reproduces affine maps: the stretch is uniform, exactly;
    // the energy density's terms (~mu t) cancel at small strain: atol 1e-14 mu t
    EXPECT_CLOSE(out.energy / element_area(ref), membrane_energy_density(l1, l2, t), 1e-12, 1e-14 * kMat.mu * t)
        << l1 << " " << l2;
  }
  // small strain: the plane-stress linear membrane energy t E/(2(1-nu^2)) (e1^2 + e2^2 + 2 nu e1 e2)
  const double e1 = 3e-5, e2 = -1.2e-5;
  Patch x = X;
  x.row(0) *= 1 + e1;
  x.row(1) *= 1 + e2;
  const auto out = shell_internal_force<12, 3>(x, kBasis, ref, kMat);
  const double linear = t * kYoung / (2 * (1 - kPoisson * kPoisson)) * (e1 * e1 + e2 * e2 + 2 * kPoisson * e1 * e2);
  EXPECT_CLOSE(out.energy / element_area(ref), linear, 1e-4, 0);
}

TEST(Shell, LumpedMassSumsToTheElementMass) {
  const double t = 0.003;
  const Patch X = curved_patch(4, 0.2);
  const auto ref = shell_reference<12, 3>(X, kBasis, t);
  const auto m = shell_lumped_mass<12, 3>(kBasis, ref, t, kDensity);
  EXPECT_CLOSE(m.sum(), kDensity * t * element_area(ref), 1e-14, 0);
  EXPECT_GE(m.minCoeff(), 0.0);
}
