#pragma once
// Whole-model numbers for names that the ranks make on their own (the copies
// a node split makes): a name's number is its position in the sorted union of
// every rank's names, as one rank holding them all would number them, found
// without any rank holding the union (docs/parallel.md "Names of new nodes").
#include <span>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

class Decomposition;

struct KeyPositions {
  std::vector<Index> position;  ///< per queried key: its position in the union, -1 when not in it
  Index total = 0;              ///< the union's size
};

/// Collective over dec's ranks. `contributed`: this rank's keys (any order;
/// repeats, and keys other ranks contribute too, allowed); `queried`: the keys
/// whose positions this rank wants. Each rank takes an equal range of the
/// keys' span, receives the keys in it, sorts them and answers the queries:
/// O(keys / ranks) per rank for keys spread over their span, plus counts of
/// O(ranks). On one rank, a sort.
KeyPositions key_positions(std::span<const GlobalId> contributed, std::span<const GlobalId> queried,
                           const Decomposition& dec);

}  // namespace shatter
