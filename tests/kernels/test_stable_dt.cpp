// The stable-step lengths are safe: for lumped TET4 and HRZ-lumped TET10, on
// regular, right, sliver and needle shapes and Poisson ratios up to 0.499,
// h / c_d <= 2 / omega_max of the element (element eigenvalue inequality:
// the global omega_max is not above the largest element one).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "kernels/tet10.hpp"
#include "kernels/tet4.hpp"

using namespace shatter;

namespace {

using Shape = std::array<Vec3, 4>;
const std::array<Shape, 5> kShapes = {{
    {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)},        // regular
    {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)},              // right
    {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, 0.5, 0.05)},     // sliver
    {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0, 0.1, 0), Vec3(0, 0, 3)},          // needle
    {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.33, 0.33, 1e-3)},     // flat
}};

// Largest eigenvalue of M^-1/2 K M^-1/2 with K from central differences of the
// kernel's internal force at the reference state.
template <int N, class Force>
double omega_max(const Eigen::Matrix<double, 3, N>& X, const Eigen::Matrix<double, N, 1>& mass, Force force) {
  constexpr int D = 3 * N;
  Eigen::Matrix<double, D, D> K;
  const double h = 1e-7;
  for (int j = 0; j < D; ++j) {
    Eigen::Matrix<double, 3, N> xp = X, xm = X;
    xp(j % 3, j / 3) += h;
    xm(j % 3, j / 3) -= h;
    const Eigen::Matrix<double, 3, N> df = (force(xp) - force(xm)) / (2 * h);
    K.col(j) = Eigen::Map<const Eigen::Matrix<double, D, 1>>(df.data());
  }
  Eigen::Matrix<double, D, 1> s;
  for (int i = 0; i < D; ++i) s[i] = 1.0 / std::sqrt(mass[i / 3]);
  const Eigen::Matrix<double, D, D> A = s.asDiagonal() * (0.5 * (K + K.transpose())) * s.asDiagonal();
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>>(A).eigenvalues().maxCoeff());
}

}  // namespace

TEST(StableStep, LengthsAreBelowTheElementEigenvalueBound) {
  for (double nu : {0.0, 0.3, 0.45, 0.49, 0.499}) {
    const NeoHookean mat = NeoHookean::from_young_poisson(1.0, nu, 1.0);
    const double c = mat.wave_speed();
    for (Shape s : kShapes) {
      if (tet_signed_volume(s[0], s[1], s[2], s[3]) < 0) std::swap(s[2], s[3]);
      Eigen::Matrix<double, 3, 4> X;
      for (int a = 0; a < 4; ++a) X.col(a) = s[a];
      const Tet4Reference r4 = tet4_reference(s[0], s[1], s[2], s[3]);
      const double w4 = omega_max<4>(X, Eigen::Matrix<double, 4, 1>::Constant(r4.volume / 4), [&](const auto& x) {
        return tet4_internal_force(x.col(0), x.col(1), x.col(2), x.col(3), r4.Dm_inv, r4.volume, mat).f;
      });
      const double h4 = tet4_stable_length(s[0], s[1], s[2], s[3]);
      EXPECT_LE(h4 / c, 2.0 / w4) << "TET4 nu " << nu;
      // and not needlessly small: within a factor 3 of the bound
      EXPECT_GT(h4 / c, (2.0 / w4) / 3) << "TET4 nu " << nu;

      Tet10Nodes X10;
      for (int a = 0; a < 4; ++a) X10.col(a) = s[a];
      for (int e = 0; e < 6; ++e) X10.col(4 + e) = 0.5 * (s[kTet10Edges[e][0]] + s[kTet10Edges[e][1]]);
      const Tet10Reference r10 = tet10_reference(X10);
      const Eigen::Matrix<double, 10, 1> m10 = tet10_hrz_mass_fractions(X10) * r10.volume;
      const double w10 = omega_max<10>(X10, m10, [&](const auto& x) { return tet10_internal_force(x, r10, mat).f; });
      const double h10 = tet10_stable_length(s[0], s[1], s[2], s[3]);
      EXPECT_LE(h10 / c, 2.0 / w10) << "TET10 nu " << nu;
      EXPECT_GT(h10 / c, (2.0 / w10) / 3) << "TET10 nu " << nu;
    }
  }
}
