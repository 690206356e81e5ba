#pragma once
// Parallel loops of the runtime: exact sums (bitwise equal for any number of
// threads, since exact addition is associative) and plain loops.
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <array>

#include "kernels/exact_sum.hpp"
#include "kernels/types.hpp"

namespace shatter {

/// K exact sums over i in [0, n): term(i, sums) adds i's terms to
/// sums[0..K) (ExactSum, kernels/exact_sum.hpp). The range is split over the
/// threads in any way; the sums are exact, so the result does not depend on
/// the split.
template <int K, class Term>
std::array<ExactSum, K> exact_sums(Index n, Term term) {
  tbb::combinable<std::array<ExactSum, K>> partial;
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, 16), [&](const tbb::blocked_range<Index>& r) {
    std::array<ExactSum, K>& sums = partial.local();
    for (Index i = r.begin(); i < r.end(); ++i) term(i, sums);
  });
  std::array<ExactSum, K> total;
  partial.combine_each([&](const std::array<ExactSum, K>& p) {
    for (int c = 0; c < K; ++c) total[c] += p[c];
  });
  return total;
}

/// Apply body(i) for i in [0, n) in parallel (no reduction; any order).
template <class Body>
void parallel_for_each(Index n, Body body) {
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, 1024), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i < r.end(); ++i) body(i);
  });
}

}  // namespace shatter
