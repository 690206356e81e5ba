#pragma once
// Broad phase of the contact search: swept boxes of the surface primitives
// over one step, and the candidate vertex-face and edge-edge pairs whose
// boxes overlap (DESIGN.md "The physics", step 2; the DCR narrow phase
// decides which of them really penetrate).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "contact/pairs.hpp"
#include "contact/sparse_bucket.hpp"
#include "contact/surface.hpp"
#include "kernels/dcr.hpp"

namespace shatter {

/// Relative inflation of a swept box: each box grows by
/// kBoxInflation x (largest side of the un-inflated swept box) on every side,
/// so it is a fixed fraction of the primitive's size plus its motion. A
/// vertex's box is its displacement (a point when it does not move); the
/// closed-interval overlap test still finds it on a face's box.
inline constexpr double kBoxInflation = 1e-3;

/// Swept boxes, one per primitive, in the surface's order:
///   triangles[t]  box of the 3 nodes at x_old and at x_new, inflated
///   edges[e]      box of the 2 nodes at x_old and at x_new, inflated
///   vertices[v]   box of the node at x_old and at x_new, inflated
/// x_old, x_new: positions x(n), x(n+1) indexed by mesh node id, m.
struct SweptBoxes {
  std::vector<Box> triangles;
  std::vector<Box> edges;
  std::vector<Box> vertices;
};

SweptBoxes swept_boxes(const ContactSurface& surface, std::span<const Vec3> x_old,
                       std::span<const Vec3> x_new);

/// The vertex-face pair of surface vertex v and triangle t, nodes
/// {vertex, tri0, tri1, tri2}; none when the vertex is a node of the triangle.
std::optional<ContactPair> vertex_face_pair(const ContactSurface& surface, Index v, Index t);

/// The edge-edge pair of surface edges e < f, nodes {e0, e1, f0, f1} with
/// e0 < e1, f0 < f1, (e0, e1) < (f0, f1); none when the edges share a node.
std::optional<ContactPair> edge_edge_pair(const ContactSurface& surface, Index e, Index f);

/// Whether the swept boxes (as swept_boxes makes them) of the two primitives of
/// `pair` overlap: the test find_candidates applies, for one pair. Filtering a
/// superset of candidates with it gives exactly find_candidates' list.
bool pair_boxes_overlap(const ContactPair& pair, std::span<const Vec3> x_old, std::span<const Vec3> x_new);
/// The same on the pair's points already gathered (columns in ContactPair::nodes order), the
/// first primitive's box grown by `reach` (m) on every side: a thick pair's h (PairThickness),
/// whose primitives touch at that distance.
bool pair_boxes_overlap(ContactPair::Kind kind, const PairPoints& X_old, const PairPoints& X_new,
                        double reach = 0.0);

/// Sort by ContactPair's operator< and drop duplicates (a radix sort of the
/// pairs packed into 96 bits, or oneTBB's parallel sort where node ids pass
/// 2^23: the result does not depend on the thread count).
void canonicalize(ContactPairs& pairs);

/// Candidate pairs of a surface moving from x_old to x_new: every vertex-face
/// pair (vertex not a node of the face) and edge-edge pair (no shared node)
/// whose swept boxes overlap, self contact included, in canonical order.
/// Two sparse buckets (triangles, edges) are built and queried by the
/// vertices and edges as oneTBB tasks; the list is identical for any thread count.
ContactPairs find_candidates(const ContactSurface& surface, std::span<const Vec3> x_old,
                             std::span<const Vec3> x_new);

/// find_candidates on boxes already computed by swept_boxes.
ContactPairs find_candidates(const ContactSurface& surface, const SweptBoxes& boxes);

/// Candidates with the primitive each belongs to: the face of a vertex-face pair (triangle t
/// as t), the first edge of an edge-edge pair (edge e as the number of triangles + e).
struct OwnedPairs {
  ContactPairs pairs;            ///< canonical order
  std::vector<Index> primitive;  ///< per pair
};

/// find_candidates on boxes, with each pair's primitive, and only the edge-edge pairs whose
/// first edge is kept (kept_edges: per edge, 1 to keep; empty: all): a rank's patch keeps
/// the pairs of its own edges and never makes those of two ghosts.
OwnedPairs find_owned_candidates(const ContactSurface& surface, const SweptBoxes& boxes,
                                 std::span<const std::uint8_t> kept_edges);

/// The definition find_candidates must equal: every pair of boxes tested,
/// O(vertices x triangles + edges^2). For tests and small benchmarks.
ContactPairs find_candidates_brute_force(const ContactSurface& surface, const SweptBoxes& boxes);

}  // namespace shatter
