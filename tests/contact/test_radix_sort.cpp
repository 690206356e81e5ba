// The sparse bucket's radix sort (contact/radix_sort.hpp): the order of a
// stable comparison sort, for any thread count, on keys that vary in few or
// in all of their bits, across several counting chunks.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "contact/radix_sort.hpp"

using namespace shatter;

namespace {

std::vector<RadixRecord> stable_sorted(std::vector<RadixRecord> r) {
  std::stable_sort(r.begin(), r.end(),
                   [](const RadixRecord& a, const RadixRecord& b) { return a.hi != b.hi ? a.hi < b.hi : a.lo < b.lo; });
  return r;
}

void expect_same(const std::vector<RadixRecord>& a, const std::vector<RadixRecord>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].hi, b[k].hi) << "at " << k;
    ASSERT_EQ(a[k].lo, b[k].lo) << "at " << k;
    ASSERT_EQ(a[k].id, b[k].id) << "at " << k;
  }
}

/// n records whose hi keeps the bits of hi_mask and lo those of lo_mask, drawn
/// from `values` distinct values each (ties: the stable order is checked).
std::vector<RadixRecord> random_records(size_t n, std::uint64_t hi_mask, std::uint32_t lo_mask, int values,
                                        unsigned seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::uint64_t> his(values);
  std::vector<std::uint32_t> los(values);
  for (int k = 0; k < values; ++k) his[k] = rng() & hi_mask, los[k] = static_cast<std::uint32_t>(rng()) & lo_mask;
  std::uniform_int_distribution<int> pick(0, values - 1);
  std::vector<RadixRecord> r(n);
  for (size_t k = 0; k < n; ++k) r[k] = {his[pick(rng)], los[pick(rng)], static_cast<Index>(k)};
  return r;
}

/// n records whose every 4-bit group of the 96-bit key lo | hi << 32 is 0, 1 or
/// 2: every radix digit varies, and records tie on the high digits, so the
/// order depends on every digit.
std::vector<RadixRecord> every_digit_records(size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, 2);
  std::vector<RadixRecord> r(n);
  for (size_t k = 0; k < n; ++k) {
    RadixRecord& x = r[k];
    x = {0, 0, static_cast<Index>(k)};
    for (int g = 0; g < 8; ++g) x.lo |= static_cast<std::uint32_t>(pick(rng)) << (4 * g);
    for (int g = 0; g < 16; ++g) x.hi |= static_cast<std::uint64_t>(pick(rng)) << (4 * g);
  }
  return r;
}

}  // namespace

TEST(RadixSort, StableComparisonOrderForAnyKeyBitsAndThreads) {
  struct Case {
    size_t n;
    std::uint64_t hi_mask;
    std::uint32_t lo_mask;
    int values;
  };
  // 70 000 records: five counting chunks. Keys that vary in every digit, in
  // every bit, in a few bits in the middle of a digit, across the 32-bit
  // seam, and not at all; 3, 1 and 0 records.
  const Case cases[] = {{70000, ~std::uint64_t(0), ~std::uint32_t(0), 60000},
                        {70000, 0x0003f00000000000ull, 0x000ff000u, 300},
                        {70000, 0x7ull, 0xc0000000u, 50},
                        {70000, 0, 0, 1},
                        {3, ~std::uint64_t(0), ~std::uint32_t(0), 2},
                        {1, 1, 1, 1},
                        {0, 1, 1, 1}};
  std::vector<std::vector<RadixRecord>> inputs{every_digit_records(70000, 1)};
  unsigned seed = 2;
  for (const Case& c : cases) inputs.push_back(random_records(c.n, c.hi_mask, c.lo_mask, c.values, seed++));
  for (const std::vector<RadixRecord>& input : inputs) {
    const std::vector<RadixRecord> expected = stable_sorted(input);
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      std::vector<RadixRecord> sorted = input;
      radix_sort(sorted);
      SCOPED_TRACE(testing::Message() << "input " << &input - inputs.data() << ", " << threads << " threads");
      expect_same(sorted, expected);
    }
  }
}

TEST(RadixSort, FloatOrderKeyFollowsTheFloatOrder) {
  const float inf = std::numeric_limits<float>::infinity();
  const float ordered[] = {-inf,
                           -std::numeric_limits<float>::max(),
                           -1.5f,
                           -1.0f,
                           -std::numeric_limits<float>::denorm_min(),
                           -0.0f,
                           0.0f,
                           std::numeric_limits<float>::denorm_min(),
                           std::numeric_limits<float>::min(),
                           1.0f,
                           std::nextafter(1.0f, 2.0f),
                           std::numeric_limits<float>::max(),
                           inf};
  for (size_t k = 1; k < std::size(ordered); ++k)
    EXPECT_LT(float_order_key(ordered[k - 1]), float_order_key(ordered[k])) << ordered[k - 1] << " < " << ordered[k];
}
