#pragma once
// DCR over all candidate pairs of a step: the decomposition contact response of
// Cirak & West, "Decomposition contact response (DCR) for explicit finite element
// dynamics", IJNME 64 (2005) 1078-1110. The per-pair physics is in kernels/dcr.hpp;
// this module finds the penetrating pairs (a read-only, parallel detection that MPI
// ranks divide among themselves) and resolves them Gauss-Seidel fashion over colored
// pairs: the colors in order, the pairs of one color (which share no node) in a
// tbb::parallel_for. Every node receives its updates in the fixed order (round,
// color, pair), so results are bitwise identical for any number of threads and ranks.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "contact/pairs.hpp"
#include "contact/surface.hpp"
#include "kernels/dcr.hpp"

namespace shatter {

/// Contact law and round control (scene keys contact.restitution, contact.friction, ...).
struct DcrOptions {
  double restitution = 1.0;  ///< e in [0, 1]
  double friction = 0.0;     ///< Coulomb mu >= 0
  double gap = 1e-6;         ///< separation after projection, fraction of the pair's longest edge
  int max_sweeps = 100;      ///< cap on the rounds; reaching it with pairs still found sets DcrResult::capped
  DcrPlacement placement = DcrPlacement::End;  ///< where in the step a collision is placed (DcrLaw)
};

/// Summary of one call of resolve_contacts.
struct DcrResult {
  Index contacts = 0;       ///< distinct pairs resolved in the step (history "contacts")
  int sweeps = 0;           ///< rounds run, the last one (which found nothing, unless capped) included
  double dissipated = 0.0;  ///< kinetic energy lost by the impacts and friction, J
  /// The work of the conditions that hold components moving at a non-zero velocity on the
  /// pairs, through the impulses (the kinetic energy the free components gained beyond the
  /// dissipation), J; 0 when every held component is at rest (summed in pair order).
  double support_work = 0.0;
  bool capped = false;      ///< max_sweeps reached with penetrations still being found
  std::optional<ContactPair> unresolved;  ///< when capped: the first pair (canonical order) found in the last round
  Index detected = 0;       ///< pair detections (dcr_detect) run on this rank, summed over the rounds
};

/// A pair found penetrating, with the outward normals that orient it (pair_normals at x_old,
/// computed by the rank that found it, which holds the triangles around its nodes).
struct FoundPair {
  ContactPair pair;
  PairNormals normals;
};

/// Hands the pairs one rank found penetrating in a round to every rank: `found` (this rank's,
/// in the order of its pairs) is replaced by the union over the ranks in canonical pair order,
/// and the states x_old, x_new, v of their nodes, as the finders hold them, are written into
/// the arrays resolve_contacts works on. Empty on one rank.
using DcrGather = std::function<void(std::vector<FoundPair>& found)>;

/// Per-node bookkeeping kept between calls, so that a call costs O(pairs), not O(mesh nodes).
struct DcrScratch {
  std::vector<long> moved;  ///< per node: the last round stamp in which a pair moved it
  std::vector<Index> slot;  ///< per node: -1 (the coloring's compact numbering, reset after use)
  long stamp = 0;           ///< rounds started so far, over all calls
  std::vector<Index> overlapping;  ///< out: the pairs of mine (indices) whose swept boxes overlap (last call)
  TriangleNormals normals;         ///< the triangle normals at x_old (DcrSurface::triangles of them)
};

/// The surface whose outward normals at x_old orient the pairs (kernels/dcr.hpp
/// dcr_orientation, surface_normal); without one (null) no pair has normals.
struct DcrSurface {
  const ContactSurface* surface = nullptr;
  const VertexTriangles* around = nullptr;
  /// The triangles whose normals the pairs read (those around the pairs' nodes); empty: all.
  std::span<const Index> triangles = {};
};

/// The outward normals of a pair (surface_normal, from the triangle normals tn of the
/// configuration wanted): a vertex-face pair's vertex normal (and 0), an edge-edge pair's
/// normals of edge a and edge b; all 0 without a surface.
PairNormals pair_normals(const ContactPair& pair, const DcrSurface& surface, const TriangleNormals& tn);

/// Resolves the penetrations of one step (DESIGN.md step 2). Nodal arrays are indexed by
/// the node ids of the pairs:
///   x_new     positions at the end of the step (m), projected in place;
///   x_old     positions at the start of the step (m), the motion is linear in between;
///   v         velocities (m/s), changed in place by the impulses;
///   inv_mass  inverse lumped masses (1/kg), 0 for a fixed node (never moved);
///   dt        the step length (s): x_new = x_old + dt v before contact;
///   surface   the outward normals at x_old that orient the pairs (DcrSurface);
///   held      per node (empty: none), bit k set = component k held by a boundary condition:
///             such a node moves only in its free components (its mass counts as infinite
///             in the held ones: weighted() in kernels/dcr.hpp); held in all three, never.
/// mine: the candidate pairs this rank checks (on one rank, all of them), in canonical order.
/// The work goes in rounds:
///   1. detection, in parallel, reading only: in the first round each pair of mine whose swept
///      boxes overlap (pair_boxes_overlap: the pairs a fresh search would give, kept in
///      scratch.overlapping) is checked by dcr_detect; in later rounds each of those with a
///      node moved in the previous round (the others would be found clean again);
///   2. the pairs found penetrating on every rank (gather), in canonical order, are colored
///      greedily in that order (pairs of one color share no node);
///   3. resolution: one Gauss-Seidel pass over the found pairs, color after color, the pairs of
///      one color in parallel, each re-detected at its turn and resolved by dcr_resolve_pair.
/// Rounds repeat until a detection finds nothing; when round options.max_sweeps still finds
/// pairs, they are resolved and the result is capped. Every rank resolves the same pairs in
/// the same order from the same states (the gather brings them), so the result is the same
/// bits on every rank and for any thread count, and every rank ends with the final states of
/// every node a pair moved. The dissipation is summed per round in pair order. Pairs whose
/// four nodes are not distinct are skipped. Run inside the caller's tbb::task_arena to choose
/// the thread count.
DcrResult resolve_contacts(std::span<const ContactPair> mine, std::span<Vec3> x_new,
                           std::span<const Vec3> x_old, std::span<Vec3> v, std::span<const double> inv_mass,
                           double dt, const DcrOptions& options, const DcrSurface& surface, DcrScratch& scratch,
                           const DcrGather& gather = {}, std::span<const std::uint8_t> held = {});

}  // namespace shatter
