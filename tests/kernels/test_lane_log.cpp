// lane_log (Eigen's packet log across the lanes with AVX, glibc's log at
// baseline): error in ulps against a long-double reference over the det F
// range of the kernels, special values, and the same bits for a value in any
// lane and any number of lanes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "kernels/lane_log.hpp"

using namespace shatter;

namespace {
// det F of the kernels: 0.05 .. 20 (log-uniform) and the values next to 1
// (1 +- k ulp, 1 +- 10^-k), where ln J is small and its ulp tiny.
std::vector<double> det_f_samples() {
  std::vector<double> x;
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(std::log(0.05), std::log(20.0));
  for (int i = 0; i < 200000; ++i) x.push_back(std::exp(u(rng)));
  const double eps = std::numeric_limits<double>::epsilon();
  for (int k = 1; k <= 2000; ++k) x.push_back(1.0 + k * eps), x.push_back(1.0 - 0.5 * k * eps);
  for (int k = 1; k <= 15; ++k) x.push_back(1.0 + std::pow(10.0, -k)), x.push_back(1.0 - std::pow(10.0, -k));
  for (double v = 0.05; v <= 20.0; v *= 2) x.push_back(v), x.push_back(std::sqrt(0.5) * v);
  return x;
}

// Largest |y(x) - ln x| over the samples, in ulps of ln x (long-double
// reference: 11 more bits than double).
double max_ulp_error(const std::vector<double>& xs, const std::function<double(double)>& y) {
  double worst = 0.0;
  for (double x : xs) {
    const long double ref = std::log(static_cast<long double>(x));
    if (ref == 0.0L) continue;
    const double r = static_cast<double>(ref);
    const double ulp = std::nextafter(std::abs(r), HUGE_VAL) - std::abs(r);
    worst = std::max(worst, static_cast<double>(std::abs(static_cast<long double>(y(x)) - ref) / ulp));
  }
  return worst;
}

// lane_log of one value alone (N = 1: the other lanes of its call padded).
double lane_log_one(double x) {
  const double in[1] = {x};
  double out[1];
  lane_log(in, out);
  return out[0];
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Within this many ulps of ln x on the samples. Measured (GCC 12): 1.22 ulp
// at avx2 and avx512 (Eigen's packet log); 0.51 at baseline, where lane_log
// is glibc's std::log (Eigen's SSE packet log, not used there: 1.40).
constexpr double kMaxUlp = 1.5;
}  // namespace

TEST(LaneLog, WithinOneAndAHalfUlpOfTheExactLogOverTheDetFRange) {
  const auto xs = det_f_samples();
  const double lane = max_ulp_error(xs, lane_log_one);
  const double libm = max_ulp_error(xs, [](double x) { return std::log(x); });
  RecordProperty("max_ulp_lane_log", std::to_string(lane));
  RecordProperty("max_ulp_std_log", std::to_string(libm));
  EXPECT_LE(lane, kMaxUlp) << "glibc's std::log: " << libm << " ulp";
  EXPECT_EQ(lane_log_one(1.0), 0.0);
  // The measure sees a log wrong by a few ulps (here 3e-16 relative) and by a
  // single bit of a small value near 1.
  EXPECT_GT(max_ulp_error(xs, [](double x) { return std::log(x) * (1 + 3e-16); }), kMaxUlp);
  EXPECT_GT(max_ulp_error({1.0 + 1e-9}, [](double x) { return std::nextafter(std::nextafter(std::log(x), 1.0), 1.0); }),
            kMaxUlp);
}

TEST(LaneLog, SpecialValuesAsStdLog) {
  EXPECT_EQ(lane_log_one(0.0), -HUGE_VAL);
  EXPECT_TRUE(std::isnan(lane_log_one(-1.0)));
  EXPECT_EQ(lane_log_one(-0.0), -HUGE_VAL);
  EXPECT_TRUE(std::isnan(lane_log_one(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_EQ(lane_log_one(HUGE_VAL), HUGE_VAL);
  EXPECT_NEAR(lane_log_one(1e-300), std::log(1e-300), 1e-15 * 700);
  EXPECT_NEAR(lane_log_one(1e300), std::log(1e300), 1e-15 * 700);
}

TEST(LaneLog, SameBitsInAnyLaneAndAnyNumberOfLanes) {
  // A value's log must not depend on its lane group (ranks x threads
  // determinism of the element loop): each value alone against the same
  // value in every lane of 8 and of 16 among other values.
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0.05, 20.0);
  for (int t = 0; t < 200; ++t) {
    double x16[16], y16[16];
    for (double& v : x16) v = u(rng);
    lane_log(x16, y16);
    double x8[8], y8[8];
    for (int l = 0; l < 8; ++l) x8[l] = x16[(l + t) % 16];
    lane_log(x8, y8);
    double x3[3] = {x16[t % 16], x16[(t + 5) % 16], x16[(t + 9) % 16]}, y3[3];
    lane_log(x3, y3);
    for (int l = 0; l < 16; ++l) ASSERT_TRUE(same_bits(y16[l], lane_log_one(x16[l]))) << x16[l];
    for (int l = 0; l < 8; ++l) ASSERT_TRUE(same_bits(y8[l], lane_log_one(x8[l]))) << x8[l];
    for (int l = 0; l < 3; ++l) ASSERT_TRUE(same_bits(y3[l], lane_log_one(x3[l]))) << x3[l];
  }
}
