#include "runtime/key_positions.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>

#include "runtime/decomposition.hpp"
#include "runtime/sort_unique.hpp"

namespace shatter {

KeyPositions key_positions(std::span<const GlobalId> contributed, std::span<const GlobalId> queried,
                           const Decomposition& dec) {
  KeyPositions out;
  out.position.assign(queried.size(), -1);
  // The keys' span over the ranks (exact: integer extrema).
  long lo = std::numeric_limits<long>::max(), hi = std::numeric_limits<long>::min();
  for (const GlobalId k : contributed) lo = std::min<long>(lo, k), hi = std::max<long>(hi, k);
  lo = -dec.max(-lo);
  hi = dec.max(hi);
  if (hi < lo) return out;  // no rank contributed a key
  const int ranks = dec.size();
  const std::uint64_t width = static_cast<std::uint64_t>(hi - lo) / static_cast<std::uint64_t>(ranks) + 1;
  auto range_rank = [&](GlobalId k) { return static_cast<int>(static_cast<std::uint64_t>(k - lo) / width); };

  std::vector<std::vector<GlobalId>> to(ranks);
  for (const GlobalId k : contributed) to[range_rank(k)].push_back(k);
  std::vector<GlobalId> range;
  for (const std::vector<GlobalId>& from : dec.alltoall(to)) range.insert(range.end(), from.begin(), from.end());
  sort_unique(range);
  // This range's first position: the sizes of the ranges below it.
  const Index size = static_cast<Index>(range.size());
  const std::vector<Index> sizes = dec.allgather(std::span<const Index>(&size, 1));
  Index first = 0;
  for (int r = 0; r < ranks; ++r) {
    if (r < dec.rank()) first += sizes[r];
    out.total += sizes[r];
  }

  std::vector<std::vector<GlobalId>> ask(ranks);
  std::vector<std::vector<size_t>> asked_for(ranks);
  for (size_t q = 0; q < queried.size(); ++q)
    if (queried[q] >= lo && queried[q] <= hi) {
      const int r = range_rank(queried[q]);
      ask[r].push_back(queried[q]);
      asked_for[r].push_back(q);
    }
  std::vector<std::vector<GlobalId>> answer = dec.alltoall(ask);
  for (std::vector<GlobalId>& keys : answer)
    for (GlobalId& k : keys) {
      const auto it = std::lower_bound(range.begin(), range.end(), k);
      k = it != range.end() && *it == k ? first + (it - range.begin()) : -1;
    }
  const std::vector<std::vector<GlobalId>> answered = dec.alltoall(answer);
  for (int r = 0; r < ranks; ++r)
    for (size_t j = 0; j < answered[r].size(); ++j) out.position[asked_for[r][j]] = static_cast<Index>(answered[r][j]);
  return out;
}

}  // namespace shatter
