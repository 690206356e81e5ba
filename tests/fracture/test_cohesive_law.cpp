// Ortiz-Pandolfi cohesive law: envelope, work of separation, irreversibility,
// energy split, compression, and the facet criterion.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>
#include <random>

#include "expect_close.hpp"
#include "kernels/cohesive.hpp"

using namespace shatter;

namespace {

const Vec3 kNormal = Vec3(1, 2, 2) / 3.0;
const Vec3 kShear = Vec3(2, -2, 1) / 3.0;  // unit, orthogonal to kNormal

/// delta_c = 2.67e-5 m; the penalty puts delta_0 at delta_c / 1000, on a
/// panel boundary of the midpoint rules below (the envelope's kinks are then
/// panel ends, where the rule stays exact).
CohesiveLaw test_law(double beta) {
  const double sigma_c = 3.0e6, gc = 40.0, delta_c = 2 * gc / sigma_c;
  return make_cohesive_law(sigma_c, gc, beta, 1000 * sigma_c / delta_c);
}

/// Work of the traction along the straight path lambda -> lambda * direction,
/// 0 <= lambda <= lambda_end, midpoint rule on n panels (the integrand
/// T . direction is piecewise linear in lambda, so the rule is exact up to the
/// panel containing delta_c), carrying the irreversible state along.
double path_work(const CohesiveLaw& law, const Vec3& direction, double lambda_end, int n,
                 double& delta_max) {
  double work = 0;
  const double h = lambda_end / n;
  for (int i = 0; i < n; ++i) {
    const double lm = (i + 0.5) * h;
    work += h * cohesive_traction(law, lm * direction, kNormal, delta_max).traction.dot(direction);
    delta_max = cohesive_traction(law, (i + 1) * h * direction, kNormal, delta_max).delta_max;
  }
  return work;
}

}  // namespace

TEST(CohesiveLaw, ModeIEnvelope) {
  const CohesiveLaw law = test_law(0.8);
  EXPECT_CLOSE(law.delta_c, 2 * 40.0 / 3.0e6, 1e-15, 0);
  EXPECT_CLOSE(law.fracture_energy(), 40.0, 1e-15, 0);
  const double d0 = law.delta_0();
  EXPECT_CLOSE(d0, 1e-3 * law.delta_c, 1e-14, 0);
  // Elastic rise k_p delta up to sigma_c at delta_0, no dissipation there.
  for (double s : {1e-12, 0.3, 1.0}) {
    const CohesiveTraction t = cohesive_traction(law, s * d0 * kNormal, kNormal, 0.0);
    EXPECT_LT((t.traction - law.sigma_c * s * kNormal).norm(), 1e-12 * law.sigma_c);
    EXPECT_EQ(t.dissipated, 0.0);
    EXPECT_CLOSE(t.stored, 0.5 * law.sigma_c * s * s * d0, 1e-13, 0);
  }
  // Linear softening from (delta_0, sigma_c) to (delta_c, 0).
  for (double s : {0.25, 0.5, 0.999}) {
    const double d = s * law.delta_c;
    const CohesiveTraction t = cohesive_traction(law, d * kNormal, kNormal, 0.0);
    const Vec3 expected = law.sigma_c * (law.delta_c - d) / (law.delta_c - d0) * kNormal;
    EXPECT_LT((t.traction - expected).norm(), 1e-12 * law.sigma_c);
    EXPECT_CLOSE(t.delta_max, d, 1e-15, 0);
  }
  // Continuous at delta_0.
  EXPECT_CLOSE(cohesive_envelope(law, d0 * (1 + 1e-12)), law.sigma_c, 1e-10, 0);
  // Past delta_c nothing is left, also on the way back.
  const CohesiveTraction past = cohesive_traction(law, 1.5 * law.delta_c * kNormal, kNormal, 0.0);
  EXPECT_EQ(past.traction.norm(), 0.0);
  EXPECT_EQ(
      cohesive_traction(law, 0.5 * law.delta_c * kNormal, kNormal, past.delta_max).traction.norm(),
      0.0);
  // Zero opening after insertion: no traction, no state.
  EXPECT_EQ(cohesive_traction(law, Vec3::Zero(), kNormal, 0.0).traction.norm(), 0.0);
}

TEST(CohesiveLaw, WorkOfSeparationIsGcForEveryMixity) {
  for (double beta : {1.0, 0.8, 0.5, 2.0}) {
    const CohesiveLaw law = test_law(beta);
    for (double angle : {0.0, 0.3, 0.9, 1.4, M_PI / 2}) {
      // Unit effective opening direction: beta^2 s^2 + n^2 = 1.
      Vec3 dir = std::cos(angle) * kNormal + std::sin(angle) / beta * kShear;
      double delta_max = 0;
      // Panels aligned with delta_c: the rule is exact, so round-off only.
      const double work = path_work(law, dir, 1.25 * law.delta_c, 100000, delta_max);
      EXPECT_CLOSE(work, law.fracture_energy(), 1e-10, 0) << "beta " << beta << " angle " << angle;
      const CohesiveTraction end =
          cohesive_traction(law, 1.25 * law.delta_c * dir, kNormal, delta_max);
      EXPECT_CLOSE(end.dissipated, law.fracture_energy(), 1e-15, 0);
      EXPECT_EQ(end.stored, 0.0);
    }
  }
}

TEST(CohesiveLaw, UnloadingAndReloadingFollowTheSecant) {
  const CohesiveLaw law = test_law(0.7);
  const Vec3 dir = 0.6 * kNormal + 0.8 / law.beta * kShear;  // unit effective opening
  const double d1 = 0.4 * law.delta_c;
  const CohesiveTraction peak = cohesive_traction(law, d1 * dir, kNormal, 0.0);
  const double t1 = cohesive_envelope(law, d1);
  EXPECT_CLOSE(peak.dissipated, 0.5 * (law.sigma_c * d1 - t1 * law.delta_0()), 1e-14, 0);
  EXPECT_CLOSE(peak.stored, 0.5 * t1 * d1, 1e-14, 0);
  // Work to reach d1 = stored + dissipated.
  double dm = 0;
  const double work = path_work(law, dir, d1, 20000, dm);
  EXPECT_CLOSE(work, peak.stored + peak.dissipated, 1e-10, 0);

  for (double s : {0.75, 0.5, 0.1}) {
    const CohesiveTraction back = cohesive_traction(law, s * d1 * dir, kNormal, peak.delta_max);
    EXPECT_EQ(back.delta_max, peak.delta_max);  // no damage growth while unloading
    EXPECT_CLOSE(back.dissipated, peak.dissipated, 1e-15, 0);
    EXPECT_CLOSE(back.stored, 0.5 * t1 * d1 * s * s, 1e-13, 0);
    // Effective traction on the secant: t = t1 s.
    const Vec3 T = back.traction;
    const double tn = T.dot(kNormal), ts = (T - tn * kNormal).norm();
    EXPECT_CLOSE(std::sqrt(tn * tn + ts * ts / (law.beta * law.beta)), t1 * s, 1e-13, 0);
  }
  // Unload to zero then reload to d1: the secant path returns all the stored
  // energy, so the cycle does no net work.
  double dm2 = peak.delta_max;
  const double reload = path_work(law, dir, d1, 20000, dm2);
  EXPECT_CLOSE(reload, peak.stored, 1e-10, 0);
  EXPECT_EQ(dm2, peak.delta_max);
  // Past d1 the envelope is followed again.
  const CohesiveTraction further = cohesive_traction(law, 1.5 * d1 * dir, kNormal, peak.delta_max);
  EXPECT_CLOSE(further.delta_max, 1.5 * d1, 1e-15, 0);
  EXPECT_CLOSE(further.dissipated,
               0.5 * (law.sigma_c * 1.5 * d1 - cohesive_envelope(law, 1.5 * d1) * law.delta_0()),
               1e-14, 0);
}

TEST(CohesiveLaw, CompressionActsOnShearOnlyWithNormalPenalty) {
  const CohesiveLaw law = test_law(0.5);
  const double dn = -0.1 * law.delta_c, ds = 0.3 * law.delta_c;
  const CohesiveTraction t = cohesive_traction(law, dn * kNormal + ds * kShear, kNormal, 0.0);
  const double delta = law.beta * ds;  // the normal part does not count
  EXPECT_CLOSE(t.delta_max, delta, 1e-15, 0);
  const double t_eff = cohesive_envelope(law, delta);
  const Vec3 expected =
      t_eff / delta * law.beta * law.beta * ds * kShear + law.penalty * dn * kNormal;
  EXPECT_LT((t.traction - expected).norm(), 1e-13 * expected.norm());
  EXPECT_CLOSE(t.stored, 0.5 * t_eff * delta + 0.5 * law.penalty * dn * dn, 1e-13, 0);
  // Around the switch delta_n = 0 the traction is continuous.
  const Vec3 a =
      cohesive_traction(law, 1e-12 * law.delta_c * kNormal + ds * kShear, kNormal, 0.0).traction;
  const Vec3 b =
      cohesive_traction(law, -1e-12 * law.delta_c * kNormal + ds * kShear, kNormal, 0.0).traction;
  EXPECT_LT((a - b).norm(), 1e-6 * law.sigma_c);
}

TEST(CohesiveLaw, StiffnessNeverExceedsTheBound) {
  // dT/dDelta by central differences at random openings and states, on every
  // branch (rise, softening, unloading, compression, past delta_c): its
  // spectral norm stays within cohesive_stiffness_bound, which the stable
  // step uses. Before the elastic rise the unloading secant sigma_c /
  // delta_max was unbounded as delta_max -> 0.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), mag(-6.0, 0.2);
  for (double beta : {0.5, 1.0, 2.0}) {
    const CohesiveLaw law = test_law(beta);
    const double bound = cohesive_stiffness_bound(law);
    double largest = 0;
    for (int trial = 0; trial < 2000; ++trial) {
      const double scale = law.delta_c * std::pow(10.0, mag(rng));
      const Vec3 opening = scale * Vec3(u(rng), u(rng), u(rng));
      const double state = std::max(0.0, u(rng)) * law.delta_c * std::pow(10.0, mag(rng));
      const double h = 1e-7 * scale;
      Mat3 J;
      for (int c = 0; c < 3; ++c) {
        Vec3 d = Vec3::Zero();
        d[c] = h;
        // Hold the state fixed: the traction at the perturbed openings with
        // the same delta_max as the centre (a branch switch inside [-h, h]
        // shows as a bounded jump of order h, not as stiffness).
        const double dm = cohesive_traction(law, opening, kNormal, state).delta_max;
        J.col(c) = (cohesive_traction(law, opening + d, kNormal, dm).traction -
                    cohesive_traction(law, opening - d, kNormal, dm).traction) /
                   (2 * h);
      }
      const double norm = J.jacobiSvd().singularValues()[0];
      largest = std::max(largest, norm);
      EXPECT_LE(norm, bound * (1 + 1e-5)) << "beta " << beta << " trial " << trial;
    }
    // The bound is reached (on the rise and in compression), not just safe.
    EXPECT_GT(largest, 0.9 * bound);
  }
  // The secant of the envelope never exceeds k_p, even for a tiny delta_max.
  const CohesiveLaw law = test_law(1.0);
  for (double dm : {0.0, 1e-30, 1e-15, 0.5 * law.delta_0(), law.delta_0(), 2 * law.delta_0()})
    EXPECT_LE(cohesive_secant(law, dm), law.penalty);
}

TEST(CohesiveLaw, FacetCriterion) {
  const double s = 2.0e6, beta = 0.5;
  // Uniaxial tension along the normal: t_eff = s.
  Mat3 sigma = s * kNormal * kNormal.transpose();
  EXPECT_CLOSE(facet_effective_traction(sigma, kNormal, beta), s, 1e-14, 0);
  // Pure compression does not open.
  EXPECT_LT(facet_effective_traction(-sigma, kNormal, beta), 1e-9 * s);
  // Pure shear on the facet: t_eff = tau / beta.
  sigma = s * (kNormal * kShear.transpose() + kShear * kNormal.transpose());
  EXPECT_CLOSE(facet_effective_traction(sigma, kNormal, beta), s / beta, 1e-14, 0);
}
