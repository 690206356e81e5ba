#pragma once
// Volume decomposition (DESIGN.md "Parallel model", docs/parallel.md): a
// METIS k-way partition of the granule graph, the ranks touching each node,
// and the node lists ranks exchange (runtime/decomposition.hpp uses them).
#include <algorithm>
#include <cstddef>
#include <map>
#include <span>
#include <vector>

#include "mesh/mesh.hpp"

namespace shatter {

/// Part of every granule of `granule` consecutive elements (granule g =
/// elements [g granule, (g+1) granule)): METIS_PartGraphKway on the granule
/// graph, two granules adjacent when they share nodes, edge weight = number
/// of shared nodes, vertex weight = elements. METIS options are the defaults
/// (load imbalance tolerance 1.03) except METIS_OPTION_SEED = `seed`: the
/// result depends only on the mesh (in its given element order), `granule`,
/// `parts` and `seed`, so every rank computing it gets the same answer. Needs
/// the node -> element CSR. For parts = 1 all zeros, without calling METIS.
/// No part is empty (a part METIS leaves empty takes a granule of the
/// largest). Layout: part[g] in [0, parts) for granule g.
/// Throws Error when parts < 1, or parts > 1 and parts > granules.
std::vector<int> partition_granules(const Mesh& mesh, Index granule, int parts, int seed = 1);

/// Part of every granule of `granule` consecutive items (granule g = items
/// [g granule, (g+1) granule)) of `items` items linked by groups of `width`
/// item ids (-1: none), such as the control vertices of shell patches:
/// METIS_PartGraphKway as partition_granules, two granules adjacent when a
/// group holds items of both, edge weight = number of such groups, vertex
/// weight = items. Deterministic in the same way; no part is empty.
/// Throws Error when parts < 1, or parts > 1 and parts > granules.
std::vector<int> partition_item_granules(Index items, std::span<const Index> groups, int width, Index granule,
                                         int parts, int seed = 1);

/// CSR of the sorted, distinct parts of the elements around each node
/// (the ranks touching it): ranks of node n are ranks[offsets[n] .. offsets[n+1]).
struct NodeRanks {
  std::vector<Index> offsets;
  std::vector<int> ranks;

  std::span<const int> of(Index n) const {
    return {ranks.data() + offsets[n], static_cast<size_t>(offsets[n + 1] - offsets[n])};
  }
};

/// The ranks touching each node (owning an element that uses it), from the
/// mesh's node -> element CSR and the part of every element.
NodeRanks touching_ranks(const Mesh& mesh, std::span<const int> elem_part);

/// Appends to `out` the parts part_of(e) of the elements e around node n,
/// ascending and distinct: node n's entry of touching_ranks.
template <class PartOf>
void append_star_ranks(const Mesh& mesh, Index n, PartOf part_of, std::vector<int>& out) {
  const auto first = static_cast<std::ptrdiff_t>(out.size());
  for (Index p = mesh.node_elem_offsets[n]; p < mesh.node_elem_offsets[n + 1]; ++p)
    out.push_back(part_of(mesh.node_elem[p]));
  std::sort(out.begin() + first, out.end());
  out.erase(std::unique(out.begin() + first, out.end()), out.end());
}

/// Nodes exchanged with other ranks, grouped by rank: the nodes for ranks[i]
/// are nodes[offsets[i] .. offsets[i+1]) (local node ids, in an order both
/// ranks agree on, e.g. ascending global id). ranks is ascending and holds
/// only ranks with at least one node.
struct NodeExchange {
  std::vector<int> ranks;
  std::vector<Index> offsets{0};
  std::vector<Index> nodes;

  int num_ranks() const { return static_cast<int>(ranks.size()); }
  std::span<const Index> nodes_of(int i) const {
    return {nodes.data() + offsets[i], static_cast<size_t>(offsets[i + 1] - offsets[i])};
  }
};

/// Flatten nodes grouped by rank (each group ascending) into a NodeExchange.
NodeExchange exchange_from(const std::map<int, std::vector<Index>>& by_rank);

}  // namespace shatter
