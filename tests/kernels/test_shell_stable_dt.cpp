// The shell's stable step against the largest frequency of M^-1 K, with K
// from the exact internal forces (central differences) and the lumped mass,
// on a flat 12 x 12 lattice of regular patches: conservative, and within
// a factor 0.6 of the bound 2 / omega_max, from membrane- to
// bending-dominated thicknesses.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <vector>

#include "kernels/shell_kl.hpp"
#include "kernels/shell_stable_dt.hpp"

using namespace shatter;

namespace {
using Patch = Eigen::Matrix<double, 3, 12>;

/// Largest angular frequency, rad/s, of the flat lattice i e1 + j e2
/// (0 <= i, j < n) carrying every upright and inverted triangle whose
/// 12-vertex patch lies inside it; each vertex has the lumped mass of the
/// infinite lattice, rho t |e1 x e2| (fewer elements only lower the spectrum).
double largest_frequency(const Vec3& e1, const Vec3& e2, int n, double t, const NeoHookean& mat) {
  const auto basis = loop_regular_basis_at_quadrature<3>();
  std::vector<Vec3> X;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) X.push_back(i * e1 + j * e2);
  std::vector<std::array<int, 12>> elems;
  std::vector<ShellReference<3>> refs;
  for (int s : {1, -1})  // upright patches at (i, j); inverted ones: offsets negated (a half turn)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        std::array<int, 12> e;
        bool inside = true;
        for (int a = 0; a < 12; ++a) {
          const int ii = i + s * kLoopRegularLattice[a][0], jj = j + s * kLoopRegularLattice[a][1];
          inside = inside && ii >= 0 && jj >= 0 && ii < n && jj < n;
          e[a] = ii + n * jj;
        }
        if (!inside) continue;
        Patch P;
        for (int a = 0; a < 12; ++a) P.col(a) = X[e[a]];
        elems.push_back(e);
        refs.push_back(shell_reference<12, 3>(P, basis, t));
      }
  const int dofs = 3 * n * n;
  auto force = [&](const std::vector<Vec3>& x) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs);
    for (std::size_t k = 0; k < elems.size(); ++k) {
      Patch P;
      for (int a = 0; a < 12; ++a) P.col(a) = x[elems[k][a]];
      const auto out = shell_internal_force<12, 3>(P, basis, refs[k], mat);
      for (int a = 0; a < 12; ++a) f.segment<3>(3 * elems[k][a]) += out.f.col(a);
    }
    return f;
  };
  const double h = 1e-6 * e1.norm();
  const double mass = mat.density * t * e1.cross(e2).norm();
  Eigen::MatrixXd K(dofs, dofs);
  for (int d = 0; d < dofs; ++d) {
    auto xp = X, xm = X;
    xp[d / 3][d % 3] += h;
    xm[d / 3][d % 3] -= h;
    K.col(d) = (force(xp) - force(xm)) / (2 * h * mass);
  }
  const Eigen::MatrixXd S = 0.5 * (K + K.transpose());
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(S, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff());
}
}  // namespace

TEST(ShellStableDt, PlateWaveSpeed) {
  const NeoHookean mat = NeoHookean::from_young_poisson(2e11, 0.3, 8000);
  EXPECT_NEAR(shell_wave_speed(mat), std::sqrt(2e11 / (8000 * (1 - 0.09))), 1e-12 * shell_wave_speed(mat));
}

TEST(ShellStableDt, BoundsTheLargestFrequencyOfALattice) {
  const NeoHookean mat = NeoHookean::from_young_poisson(1e9, 0.3, 1000);
  const Vec3 e1(1, 0, 0);
  for (const Vec3& e2 : {Vec3(0.5, std::sqrt(3.0) / 2, 0), Vec3(0.25, 0.7, 0)}) {
    const double h = shell_stable_length(Vec3::Zero(), e1, e2);
    for (double t_over_h : {0.03, 1.0, 3.0}) {
      const double t = t_over_h * h;
      const double bound = 2.0 / largest_frequency(e1, e2, 12, t, mat);
      const double dt = shell_stable_dt(h, t, mat);
      EXPECT_LE(dt, bound) << "e2 " << e2.transpose() << " t/h " << t_over_h;
      EXPECT_GE(dt, 0.6 * bound) << "e2 " << e2.transpose() << " t/h " << t_over_h;
    }
  }
}
