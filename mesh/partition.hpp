#pragma once
// Volume decomposition (DESIGN.md "Parallel model"): a METIS k-way partition
// of the element dual graph, and the part of the mesh one rank holds — its
// owned elements plus one ghost layer — with the node lists it exchanges.
#include <cstdint>
#include <map>
#include <span>
#include <vector>

#include "mesh/mesh.hpp"

namespace shatter {

/// Part (rank) of every element: METIS_PartGraphKway on the element dual
/// graph, two elements being adjacent when they share a face (METIS_MeshToDual
/// on the 4 corner nodes with ncommon = 3, so TET10 gives the same graph).
/// METIS options are the defaults (load imbalance tolerance 1.03) except
/// METIS_OPTION_SEED = `seed`: the result depends only on the mesh (in its
/// given element order), `parts` and `seed`, so every rank computing it gets
/// the same partition. For parts = 1 all zeros, without calling METIS.
/// Layout: part[e] in [0, parts) for element e of `mesh`.
/// Throws Error when parts < 1, parts > elements, or METIS fails.
std::vector<int> partition_elements(const Mesh& mesh, int parts, int seed = 1);

/// Part of every granule of `granule` consecutive elements (granule g =
/// elements [g granule, (g+1) granule)): METIS_PartGraphKway on the granule
/// graph, two granules adjacent when they share nodes, edge weight = number
/// of shared nodes, vertex weight = elements; seeded like partition_elements,
/// so every rank computing it gets the same answer. Needs the node -> element
/// CSR. For parts = 1 all zeros. No part is empty (a part METIS leaves empty
/// takes a granule of the largest). Throws Error when parts < 1 or parts > granules.
std::vector<int> partition_granules(const Mesh& mesh, Index granule, int parts, int seed = 1);

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

/// Nodes exchanged with other ranks, grouped by rank: the nodes for ranks[i]
/// are nodes[offsets[i] .. offsets[i+1]) (local node ids, ascending global
/// id). ranks is ascending and holds only ranks with at least one node.
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

/// The part of a global mesh that rank `rank` holds.
///
/// Elements: the owned ones (elem_part[e] == rank) plus one ghost layer,
/// every other element that shares a node with an owned element. Nodes: all
/// nodes of those elements. Every node of an owned element therefore has its
/// whole element star locally (node splitting, owner-computes forces).
/// Ordering is canonical: local elements by ascending elem_gid, local nodes by
/// ascending node_gid, element node order as in the global mesh, so the
/// LocalMesh does not depend on the order of the global mesh's arrays.
///
/// Ranks touching a node = ranks owning an element that uses it. The owner of
/// a node is the smallest rank touching it.
///
/// Layouts (n = local nodes, e = local elements):
///   mesh            local Mesh; global ids in mesh.node_gid, mesh.elem_gid;
///                   node_elem CSR built (ascending local = ascending gid)
///   elem_owner[e]   rank owning the element (== rank: owned, else ghost)
///   node_owner[n]   rank owning the node
///   node_touched[n] 1 when an owned element uses the node, else 0
///   shared          nodes touched here and by another rank, per such rank:
///                   the partial sums of halo summation go both ways
///   ghost_send      nodes owned here, per other rank holding them
///   ghost_recv      nodes held here and owned elsewhere, per owner
///   ghost_only_send the part of ghost_send that the receiving rank does not
///                   touch (it holds them only through ghost elements)
///   ghost_only_recv the part of ghost_recv not touched here
/// shared.nodes_of(q) on rank r lists the same global nodes, in the same order,
/// as shared.nodes_of(r) on rank q; likewise ghost_send on r and ghost_recv on
/// q, and ghost_only_send on r and ghost_only_recv on q.
struct LocalMesh {
  int rank = 0;
  Mesh mesh;
  std::vector<int> elem_owner;
  std::vector<int> node_owner;
  std::vector<std::uint8_t> node_touched;
  NodeExchange shared;
  NodeExchange ghost_send;
  NodeExchange ghost_recv;
  NodeExchange ghost_only_send;
  NodeExchange ghost_only_recv;

  bool owns_element(Index e) const { return elem_owner[e] == rank; }
  bool owns_node(Index n) const { return node_owner[n] == rank; }
};

/// The LocalMesh of `rank` (see LocalMesh). `global` must have its node_elem
/// CSR built and unique global ids; elem_part[e] is the part of global element e
/// (e.g. from partition_elements). Costs O(global elements x nodes per
/// element x ranks per node); every rank can call it on the same global mesh.
/// Throws Error on a size mismatch or duplicate global ids.
LocalMesh extract_subdomain(const Mesh& global, std::span<const int> elem_part, int rank);

}  // namespace shatter
