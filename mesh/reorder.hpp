#pragma once
// Locality reordering of a mesh: elements sorted along a space-filling curve
// (Morton / Z-order of the element centroids), nodes renumbered in order of
// first use by the sorted elements. Consecutive elements then share nodes and
// consecutive blocks of elements touch a compact, mostly cached set of nodes,
// which is what the colored-block force loop (runtime) needs: see
// docs/performance.md, "Element kernels".
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <span>
#include <utility>
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

/// The cube [lo, lo + the largest extent of the points' box] around `points`:
/// a Morton curve in it (one scale for every axis) splits the longest side
/// first, so a run of consecutive points of an elongated body (a bar, a
/// plate) is a compact piece of it. (A box of the body's own proportions
/// split a bar's thickness first: a granule of a 12:1 bar spanned half its
/// length, and at 2 ranks a part's two ghost layers held all but 2 of its
/// 4318 elements.)
std::pair<Vec3, Vec3> bounding_cube(std::span<const Vec3> points);

/// 0 .. n-1 sorted by the Morton code of point(i) in [lo, hi], ties in index
/// order. O(n log n).
template <class Point>
std::vector<Index> morton_order(Index n, Point point, const Vec3& lo, const Vec3& hi) {
  std::vector<std::uint64_t> code(n);
  for (Index i = 0; i < n; ++i) code[i] = morton_code(point(i), lo, hi);
  std::vector<Index> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return code[a] < code[b]; });
  return order;
}

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
