#pragma once
// Locality reordering of a mesh: elements sorted along a space-filling curve
// (Morton / Z-order of the element centroids), nodes renumbered in order of
// first use by the sorted elements. Consecutive elements then share nodes and
// consecutive blocks of elements touch a compact, mostly cached set of nodes,
// which is what the colored-block force loop (runtime) needs: see
// docs/performance.md, "Element kernels".
#include <cstdint>
#include <vector>

#include "mesh/mesh.hpp"

namespace shatter {

/// The permutations applied by reorder_for_locality, as old -> new local ids,
/// so that arrays the mesh does not hold can be permuted the same way.
struct MeshPermutation {
  std::vector<Index> node_new_of_old;
  std::vector<Index> elem_new_of_old;
};

/// Morton code (21 bits per axis, interleaved x,y,z) of p inside the box
/// [lo, hi]; points outside are clamped. Equal points give equal codes.
std::uint64_t morton_code(const Vec3& p, const Vec3& lo, const Vec3& hi);

/// What happens to the global ids when reordering.
enum class GlobalIdPolicy {
  keep,      ///< ids move with their entities (Gmsh tags stay attached)
  renumber,  ///< the same set of ids, handed out in ascending order along the
             ///< new local order: ascending gid == new order, so anything that
             ///< sorts by gid inherits the locality on every rank
};

/// Reorder elements along the Morton curve of their reference centroids (in
/// the cube of the mesh's largest extent, from its lower corner)
/// (ties keep the old order) and nodes by first use in the new element order
/// (nodes used by no element keep their relative order, at the end).
/// Every per-node and per-element array of the mesh is permuted, global ids
/// per `gids`, node_elem is rebuilt and revision bumped. Deterministic;
/// O((n + e) log e). Apply to the global mesh before partitioning with
/// GlobalIdPolicy::renumber, or to one rank's mesh with keep.
MeshPermutation reorder_for_locality(Mesh& mesh, GlobalIdPolicy gids = GlobalIdPolicy::keep);

}  // namespace shatter
