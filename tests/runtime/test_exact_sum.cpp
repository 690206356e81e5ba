// Exact summation (kernels/exact_sum.hpp, runtime/global_sum.hpp): the sum of any doubles, in any
// order and any grouping, is the same integer and so the same double; it is
// the correctly rounded sum where that is known; and split over 1, 2 or 3
// MPI ranks it gives the serial bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "mpi_environment.hpp"
#include "runtime/global_sum.hpp"

namespace shatter {
namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Terms over the whole exponent range with heavy cancellation: x, -x pairs
/// of huge values around small ones, subnormals, and a known exact part.
std::vector<double> hostile_terms(unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> expo(-1070, 1000);
  std::vector<double> t;
  for (int i = 0; i < 3000; ++i) {
    const double x = std::ldexp(mant(rng), expo(rng));
    t.push_back(x);
    t.push_back(-x);  // cancels exactly
  }
  for (int i = 0; i < 500; ++i) t.push_back(std::ldexp(mant(rng), -1074 + i % 40));  // subnormals
  for (int i = 0; i < 1000; ++i) t.push_back(0.1 * i);
  return t;
}

double sum_in_order(const std::vector<double>& t) {
  ExactSum s;
  for (double x : t) s += x;
  return s.value();
}

TEST(ExactSum, SmallIntegersAndFractionsAreExact) {
  ExactSum s;
  for (int i = 1; i <= 1000; ++i) s += 0.25 * i;
  EXPECT_EQ(s.value(), 0.25 * 500500);
  ExactSum t;
  t += 1e300;
  t += 1.0;
  t += -1e300;
  EXPECT_EQ(t.value(), 1.0);  // a naive sum gives 0
  ExactSum z;
  EXPECT_EQ(z.value(), 0.0);
  z += std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(z.value(), std::numeric_limits<double>::denorm_min());
  z += -std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(z.value(), 0.0);
  ExactSum big;
  big += std::numeric_limits<double>::max();
  big += -0.5 * std::numeric_limits<double>::max();
  EXPECT_EQ(big.value(), 0.5 * std::numeric_limits<double>::max());
}

TEST(ExactSum, NegativeSumsAndRounding) {
  ExactSum s;
  s += -3.0;
  s += 1e-20;
  // -3 + 1e-20 rounds to -3 (1e-20 is far below half an ulp of 3).
  EXPECT_EQ(s.value(), -3.0);
  ExactSum u;
  u += 1.0;
  u += std::ldexp(1.0, -60);
  u += -1.0;
  EXPECT_EQ(u.value(), std::ldexp(1.0, -60));
  // The sum of 0.1 ten times against the long-double sum: within 2 ulp.
  ExactSum d;
  long double ref = 0;
  for (int i = 0; i < 10; ++i) d += 0.1, ref += 0.1L;
  EXPECT_LE(std::abs(d.value() - static_cast<double>(ref)), 2 * std::ldexp(1.0, -52));
}

TEST(ExactSum, AnyOrderAndGroupingGivesTheSameBits) {
  std::vector<double> t = hostile_terms(7);
  const double reference = sum_in_order(t);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    std::shuffle(t.begin(), t.end(), rng);
    EXPECT_TRUE(same_bits(sum_in_order(t), reference));
    // Split into uneven groups, summed apart and combined in reverse.
    std::vector<ExactSum> parts(7);
    for (size_t i = 0; i < t.size(); ++i) parts[(i * i) % 7] += t[i];
    ExactSum all;
    for (int k = 6; k >= 0; --k) all += parts[k];
    EXPECT_TRUE(same_bits(all.value(), reference));
  }
  // The exactly cancelling pairs leave the rest: 0.1 * (0 + ... + 999) plus the subnormals.
  EXPECT_NEAR(reference, 0.1 * 499500, 1e-9);
}

TEST(ExactSum, InfinityAndNanAreSummedApart) {
  ExactSum s;
  s += 1.0;
  s += HUGE_VAL;
  EXPECT_EQ(s.value(), HUGE_VAL);
  s += -HUGE_VAL;
  EXPECT_TRUE(std::isnan(s.value()));
  ExactSum n;
  n += std::nan("");
  n += 2.0;
  EXPECT_TRUE(std::isnan(n.value()));
}

TEST(ExactSumMpi, EveryRankSplitGivesTheSerialBits) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const std::vector<double> t = hostile_terms(11);
  const double serial = sum_in_order(t);
  // Two accumulators: the terms, and their squares.
  ExactSum mine[2];
  for (size_t i = rank; i < t.size(); i += size) mine[0] += t[i], mine[1] += t[i] * t[i];
  ExactSum all[2] = {mine[0], mine[1]};
  allreduce(all, MPI_COMM_WORLD);
  EXPECT_TRUE(same_bits(all[0].value(), serial));
  ExactSum squares;
  for (double x : t) squares += x * x;
  EXPECT_TRUE(same_bits(all[1].value(), squares.value()));
  reduce_to_root(mine, MPI_COMM_WORLD);
  if (rank == 0) {
    EXPECT_TRUE(same_bits(mine[0].value(), serial));
  }
}

TEST(ExactSumMpi, MaximaAndSpecialsTravelWithTheSums) {
  // One message carries the digits, the specials and the maxima: each arrives whole
  // (a lost or misplaced word shows in one of the three).
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const std::vector<double> t = hostile_terms(7);
  ExactSum mine[3];
  for (size_t i = rank; i < t.size(); i += size) mine[0] += t[i];
  if (rank == size - 1) mine[1] += HUGE_VAL;  // one rank's infinity makes the sum infinite
  mine[2] += 0.5 * rank;
  long most[3] = {7L * rank - 3, -rank, std::numeric_limits<long>::min() + rank};
  allreduce(mine, MPI_COMM_WORLD, most);
  EXPECT_TRUE(same_bits(mine[0].value(), sum_in_order(t)));
  EXPECT_EQ(mine[1].value(), HUGE_VAL);
  EXPECT_EQ(mine[2].value(), 0.25 * size * (size - 1));
  EXPECT_EQ(most[0], 7L * (size - 1) - 3);
  EXPECT_EQ(most[1], 0);
  EXPECT_EQ(most[2], std::numeric_limits<long>::min() + size - 1);
}

}  // namespace
}  // namespace shatter
