#pragma once
// Deterministic parallel reductions: the range is cut into fixed blocks that
// do not depend on the thread count, partial results are computed in
// parallel and combined serially in block order, so sums are bitwise equal
// for any number of threads.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

inline constexpr Index kReduceBlock = 4096;

/// sum over i in [0, n) of term(i), for term returning double, Vec3 or any
/// type with operator+= and a zero given as `zero`.
template <class T, class Term>
T deterministic_sum(Index n, const T& zero, Term term) {
  const Index blocks = (n + kReduceBlock - 1) / kReduceBlock;
  std::vector<T> partial(blocks, zero);
  tbb::parallel_for(tbb::blocked_range<Index>(0, blocks), [&](const tbb::blocked_range<Index>& r) {
    for (Index b = r.begin(); b < r.end(); ++b) {
      T acc = zero;
      const Index end = std::min(n, (b + 1) * kReduceBlock);
      for (Index i = b * kReduceBlock; i < end; ++i) acc += term(i);
      partial[b] = acc;
    }
  });
  T total = zero;
  for (const T& p : partial) total += p;
  return total;
}

/// The i in [0, n) with keep(i), ascending: blocks of kReduceBlock filtered
/// in parallel and concatenated in block order (the same list for any thread count).
template <class Keep>
std::vector<Index> parallel_select(Index n, Keep keep) {
  const Index blocks = (n + kReduceBlock - 1) / kReduceBlock;
  std::vector<std::vector<Index>> partial(blocks);
  tbb::parallel_for(tbb::blocked_range<Index>(0, blocks), [&](const tbb::blocked_range<Index>& r) {
    for (Index b = r.begin(); b < r.end(); ++b) {
      const Index end = std::min(n, (b + 1) * kReduceBlock);
      for (Index i = b * kReduceBlock; i < end; ++i)
        if (keep(i)) partial[b].push_back(i);
    }
  });
  std::vector<Index> out;
  size_t total = 0;
  for (const auto& p : partial) total += p.size();
  out.reserve(total);
  for (const auto& p : partial) out.insert(out.end(), p.begin(), p.end());
  return out;
}

/// Apply body(i) for i in [0, n) in parallel (no reduction; any order).
template <class Body>
void parallel_for_each(Index n, Body body) {
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, 1024), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i < r.end(); ++i) body(i);
  });
}

}  // namespace shatter
