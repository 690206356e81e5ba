#pragma once
// Candidate contact pairs: the hand-off from the search (broad phase) to the
// DCR response (narrow phase and sweeps). Node ids are the volume mesh's
// local node ids, so DCR reads and writes the nodal arrays directly.
#include <array>
#include <cstdint>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

/// One candidate: a vertex against a triangle, or an edge against an edge.
///   VertexFace: nodes = {vertex, tri0, tri1, tri2}   (triangle counter-clockwise
///               seen from outside the body, so its normal points outward)
///   EdgeEdge:   nodes = {a0, a1, b0, b1}             (edge a = a0-a1, edge b = b0-b1)
/// Canonical order of a candidate list: sorted by (kind, nodes) lexicographically,
/// no duplicates; downstream work in that order is deterministic.
struct ContactPair {
  enum Kind : std::uint8_t { VertexFace = 0, EdgeEdge = 1 };
  Kind kind;
  std::array<Index, 4> nodes;
  friend bool operator==(const ContactPair&, const ContactPair&) = default;
  friend auto operator<=>(const ContactPair&, const ContactPair&) = default;
};

using ContactPairs = std::vector<ContactPair>;

}  // namespace shatter
