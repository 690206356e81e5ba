#pragma once
// Stable least-significant-digit radix sort of keyed records, for the
// sparse bucket's entries (contact/sparse_bucket.cpp) and the canonical order
// of the candidates (contact/candidates.cpp). Digits of 11 bits; a
// digit that is the same in every key is skipped, so keys that use few of
// their bits (cell indices, floats of one sign) cost few passes. Each pass
// counts and scatters fixed chunks of the input in parallel (oneTBB); the
// chunks do not depend on the thread count, and the sort is stable, so the
// result is the same for any number of threads.
#include <bit>
#include <cstdint>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

/// A record sorted by (hi, lo), ascending; `id` is carried along.
struct RadixRecord {
  std::uint64_t hi;
  std::uint32_t lo;
  Index id;
};

/// Sort by (hi, lo); records with equal keys keep their order.
void radix_sort(std::vector<RadixRecord>& records);

/// A key for a float whose unsigned order is the float's order (-0 just
/// below +0; no NaN).
inline std::uint32_t float_order_key(float f) {
  const auto b = std::bit_cast<std::uint32_t>(f);
  return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}

}  // namespace shatter
