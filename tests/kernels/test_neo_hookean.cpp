// Neo-Hookean material: zero stress at F = I, P = dW/dF, frame indifference.
#include <gtest/gtest.h>

#include <random>

#include "expect_close.hpp"
#include "kernels/neo_hookean.hpp"

using namespace shatter;

namespace {
Mat3 random_deformation(std::mt19937_64& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Mat3 F = Mat3::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F(i, j) += u(rng);
  return F;
}
Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}
const NeoHookean kSteel = NeoHookean::from_young_poisson(210e9, 0.3, 7850);
}  // namespace

TEST(NeoHookean, ZeroStressAndEnergyAtIdentity) {
  EXPECT_LT(kSteel.stress(Mat3::Identity()).norm(), 1e-16 * kSteel.mu);
  EXPECT_EQ(kSteel.energy(Mat3::Identity()), 0.0);
}

TEST(NeoHookean, StressIsEnergyDerivative) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 F = random_deformation(rng, 0.3);
    ASSERT_GT(F.determinant(), 0.1);
    const Mat3 P = kSteel.stress(F);
    const double h = 1e-6;
    Mat3 P_fd;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        Mat3 Fp = F, Fm = F;
        Fp(i, j) += h;
        Fm(i, j) -= h;
        P_fd(i, j) = (kSteel.energy(Fp) - kSteel.energy(Fm)) / (2 * h);
      }
    // central difference error ~ h^2 |W'''| ~ 1e-12 mu; round-off ~ eps W / h
    EXPECT_LT((P - P_fd).norm(), 1e-6 * P.norm() + 1e-5 * kSteel.mu * 1e-3);
  }
}

TEST(NeoHookean, FrameIndifference) {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 F = random_deformation(rng, 0.4), Q = random_rotation(rng);
    const Mat3 P = kSteel.stress(F);
    EXPECT_LT((kSteel.stress(Q * F) - Q * P).norm(), 1e-13 * P.norm());
    EXPECT_CLOSE(kSteel.energy(Q * F), kSteel.energy(F), 1e-12, 0.0);
  }
}

TEST(NeoHookean, SmallStrainLimitIsHooke) {
  // sigma = lambda tr(eps) I + 2 mu eps for |eps| -> 0
  Mat3 eps;
  eps << 1, 0.3, 0, 0.3, -0.5, 0.2, 0, 0.2, 0.7;
  eps *= 1e-7;
  const Mat3 sigma = kSteel.cauchy_stress(Mat3::Identity() + eps);
  const Mat3 hooke = kSteel.lambda * eps.trace() * Mat3::Identity() + 2 * kSteel.mu * eps;
  EXPECT_LT((sigma - hooke).norm(), 1e-6 * hooke.norm());
}

TEST(NeoHookean, WaveSpeedGrowsUnderCompression) {
  EXPECT_DOUBLE_EQ(kSteel.wave_speed(1.0), kSteel.wave_speed());
  EXPECT_GT(kSteel.wave_speed(0.8), kSteel.wave_speed());
  EXPECT_DOUBLE_EQ(kSteel.wave_speed(1.2), kSteel.wave_speed());
  // c = sqrt(E (1 - nu) / ((1 + nu)(1 - 2 nu) rho)) = 6001 m/s for steel
  EXPECT_CLOSE(kSteel.wave_speed(), std::sqrt(210e9 * 0.7 / (1.3 * 0.4 * 7850)), 1e-14, 0.0);
}

TEST(NeoHookean, VonMisesOfUniaxialStressIsTheStress) {
  Mat3 s = Mat3::Zero();
  s(0, 0) = 3e8;
  EXPECT_CLOSE(von_mises(s), 3e8, 1e-15, 0.0);
  EXPECT_LT(von_mises(Mat3::Identity() * 5e8), 1e-6);
}
