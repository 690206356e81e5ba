#pragma once
// The order in which DCR resolves the pairs found penetrating in a round
// (docs/contact.md "The order of resolution"). Each pair has a priority key,
// a hash of its nodes' whole-model ids and of the round's number (ties,
// which are rare, broken by the ids themselves). The order changes from
// round to round because one fixed order can cycle: a few pairs that undo
// each other found again in every round until the cap. On every node the pairs that share it are resolved one
// after the other in key order, and pairs with no common node in any order:
// the result is that of a Gauss-Seidel pass over the found pairs sorted by
// key, whatever the ranks, threads and grouping (Jones & Plassmann, "A
// parallel graph coloring heuristic", SIAM J. Sci. Comput. 14 (1993) 654-669,
// use random priorities the same way: a pair waits only for its neighbours
// with a higher priority, so the chains of waiting pairs stay short).
#include <array>
#include <compare>
#include <cstdint>
#include <vector>

#include "contact/pairs.hpp"

namespace shatter {

/// A found pair's priority: the smaller key is resolved first.
struct DcrKey {
  std::uint64_t hash = 0;
  ContactPair::Kind kind = ContactPair::VertexFace;
  std::array<std::uint64_t, 4> ids{};  ///< the nodes' whole-model ids
  friend bool operator==(const DcrKey&, const DcrKey&) = default;
  friend auto operator<=>(const DcrKey&, const DcrKey&) = default;
};

/// The key of a pair of the given kind whose nodes have the whole-model ids `ids`, in
/// round `round` of a step's resolution (the order changes from round to round).
DcrKey dcr_key(ContactPair::Kind kind, const std::array<std::uint64_t, 4>& ids, int round);

/// One node of one found pair: a place in that node's list of found pairs.
struct DcrLink {
  std::uint64_t node = 0;  ///< the node (any id every rank gives it alike)
  DcrKey key;              ///< its pair's
  int rank = 0;            ///< the rank resolving the pair
  std::uint64_t tag = 0;   ///< the caller's name for the link
  int pred = -1, succ = -1;  ///< out: the ranks of the links just before and after on the node (-1: none)
};

/// Sorts the links by (node, key) and fills pred and succ of every link.
void order_links(std::vector<DcrLink>& links);

}  // namespace shatter
