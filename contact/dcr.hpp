#pragma once
// DCR over all candidate pairs of a step: the decomposition contact response of
// Cirak & West, "Decomposition contact response (DCR) for explicit finite element
// dynamics", IJNME 64 (2005) 1078-1110. The per-pair physics is in kernels/dcr.hpp;
// this module finds the penetrating pairs (a read-only, parallel detection) and
// resolves them Gauss-Seidel fashion in the order of contact/dcr_order.hpp: on each
// node the pairs sharing it in key order, pairs with no common node in parallel
// (threads) or on different MPI ranks. Every pair is detected and resolved by the
// rank that owns it; the states of shared nodes pass from rank to rank along each
// node's list (DcrRanks). Every node receives its updates in the same order on any
// number of threads and ranks, so the results are bitwise identical.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "contact/candidates.hpp"
#include "contact/dcr_order.hpp"
#include "contact/pairs.hpp"
#include "contact/surface.hpp"
#include "kernels/dcr.hpp"
#include "kernels/exact_sum.hpp"

namespace shatter {

/// Contact law and round control (scene keys contact.restitution, contact.friction, ...).
struct DcrOptions {
  double restitution = 1.0;  ///< e in [0, 1]
  double friction = 0.0;     ///< Coulomb mu >= 0
  double gap = 1e-6;         ///< separation after projection, fraction of the pair's longest edge
  int max_sweeps = 100;      ///< cap on the rounds; reaching it with pairs still found sets DcrResult::capped
  DcrPlacement placement = DcrPlacement::End;  ///< where in the step a collision is placed (DcrLaw)
};

/// The free rigid bodies (bodies[i].rigid: free) among the nodes: DCR moves each as one
/// particle with mass and inertia (PairMobility), and reports what it gave each one.
struct DcrRigidBodies {
  struct Body {
    double inv_mass = 0;              ///< 1/M, 1/kg
    Mat3 inv_inertia = Mat3::Zero();  ///< J^-1 in the world frame, 1/(kg m^2)
    Vec3 centre = Vec3::Zero();       ///< c, m (the arms r = x - c)
  };
  std::span<const std::int32_t> node_body;  ///< per node: its body (index into bodies), -1: deformable
  std::span<const Body> bodies;
};

/// Per rigid body, what the pairs gave it (DcrResult::rigid), about the origin: impulse
/// sum J_a (N s), angular impulse sum x_a x J_a (N m s), mass-weighted shift sum S_a (kg m)
/// and its moment sum x_a x S_a (kg m^2), x_a the node's position after its pair.
enum DcrRigidSum { kRigidImpulse = 0, kRigidAngularImpulse = 3, kRigidShift = 6, kRigidShiftMoment = 9, kRigidSums = 12 };

/// Summary of one call of resolve_contacts.
struct DcrResult {
  // On several ranks contacts, dissipated, support_work, work, unresolved and detected are this
  // rank's part (its pairs); sweeps and capped are the same on every rank.
  Index contacts = 0;       ///< distinct pairs resolved in the step (history "contacts")
  int sweeps = 0;           ///< rounds run, the last one (which found nothing, unless capped) included
  ExactSum dissipated;      ///< kinetic energy lost by the impacts and friction, J
  /// The work of the conditions that hold components moving at a non-zero velocity on the
  /// pairs, through the impulses (the kinetic energy the free components gained beyond the
  /// dissipation), J; 0 when every held component is at rest.
  ExactSum support_work;
  /// The kinetic energy the projections' angular-momentum counterpart took out
  /// (kernels/dcr.hpp dcr_keep_angular_momentum), J, signed: the ledger's contact_work.
  ExactSum work;
  bool capped = false;      ///< max_sweeps reached with penetrations still being found
  std::optional<ContactPair> unresolved;  ///< when capped: the first pair (canonical order) found in the last round
  Index detected = 0;       ///< pair detections (dcr_detect) run on this rank, summed over the rounds
  /// Per rigid body (DcrRigidBodies::bodies; empty without), this rank's pairs' DcrRigidSum terms.
  std::vector<std::array<ExactSum, kRigidSums>> rigid;
};

/// A pair found penetrating, with the outward normals that orient it (pair_normals at x_old,
/// computed by the rank that found it, which holds the triangles around its nodes).
struct FoundPair {
  ContactPair pair;
  PairNormals normals;
};

/// A node's state as it passes between ranks during a resolution round.
struct DcrNodeState {
  Index node = 0;  ///< node id of the nodal arrays (this rank's)
  Vec3 x_new, v;
  bool moved = false;  ///< a pair moved the node in this round (this or an earlier one on the node)
};

/// The other ranks' part in resolve_contacts (runtime/patch_ranks.hpp; none on one rank).
/// Each found pair is resolved by the rank that found it; on each of its nodes it waits
/// for the pair just before it in the node's list (the rank that resolved that one posts
/// the node's state), and then posts the state to the rank of the pair just after it.
class DcrRanks {
 public:
  virtual ~DcrRanks() = default;
  virtual int rank() const = 0;
  /// The node's whole-model id (the pairs' keys are made of them).
  virtual std::uint64_t id(Index node) const = 0;
  /// The sum of count over the ranks (collective).
  virtual long total(long count) = 0;
  /// Orders this rank's links (node = node id of the arrays, rank = rank()) with every rank's, as
  /// order_links would the union: pred and succ are set (the order of `links` may change;
  /// collective).
  virtual void link(std::vector<DcrLink>& links) = 0;
  /// Sends the states to rank r (nonblocking: they are copied).
  virtual void post(int r, std::span<const DcrNodeState> states) = 0;
  /// The states other ranks posted here (node ids are this rank's): with wait, at least one;
  /// without, those that have arrived.
  virtual std::vector<DcrNodeState> receive(bool wait) = 0;
  /// Ends a round's posts: waits until they are sent. Then brings the final states of the
  /// nodes that moved in the round to every rank that reads them (their volume owners and
  /// the ranks whose patches hold them): `last` lists the moved nodes whose last pair was
  /// resolved here. Writes the states received into x_new and v and returns their nodes
  /// (collective).
  virtual std::vector<Index> settle(std::span<const Index> last, std::span<Vec3> x_new, std::span<Vec3> v) = 0;
};

/// Per-node bookkeeping kept between calls, so that a call costs O(pairs), not O(mesh nodes).
struct DcrScratch {
  std::vector<long> moved;  ///< per node: the last round stamp in which a pair moved it
  std::vector<Index> slot;  ///< per node: -1 (a round's compact numbering of the found pairs' nodes, reset after use)
  long stamp = 0;           ///< rounds started so far, over all calls
  std::vector<Index> overlapping;  ///< out: the pairs of mine (indices) whose swept boxes overlap (last call)
  TriangleNormals normals;         ///< the triangle normals at x_old (DcrSurface::triangles of them)
  /// The first round's screen without the pairs' points (the caller's, kept between calls):
  /// per pair of mine (empty: no screen), its box gap at the last search (pair_gaps); per
  /// node, how far (max norm) its x_old and x_new are from its position then. A pair whose
  /// gap exceeds kGapDrift x (the largest drift of a node of its first primitive + that of
  /// its second's) cannot pass pair_boxes_overlap, so its points are not read.
  std::vector<double> gaps;
  std::vector<double> drift;
};

/// The factor on the drifts d_A + d_B of a pair's two primitives under which its gap
/// (pair_gaps) keeps their swept boxes apart: each one's swept box stays within its d of its
/// box at the search and grows by at most kBoxInflation x (its side there + 2 d)
/// (candidates.hpp), so (d_A + d_B) (1 + 2 kBoxInflation); and a relative slack of 1e-9
/// for the rounding of the boxes' arithmetic.
inline constexpr double kGapDrift = (1.0 + 2.0 * kBoxInflation) * (1.0 + 1e-9);

/// The surface whose outward normals at x_old orient the pairs (kernels/dcr.hpp
/// dcr_orientation, surface_normal); without one (null) no pair has normals.
struct DcrSurface {
  const ContactSurface* surface = nullptr;
  const VertexTriangles* around = nullptr;
  /// The triangles whose normals the pairs read (those around the pairs' nodes); empty: all.
  std::span<const Index> triangles = {};
  /// Per node (empty: none), the half-thickness r of a shell's mid-surface node, m (0 for a
  /// solid's): a pair with a shell side is thick (PairThickness, pair_thickness).
  std::span<const double> reach = {};
};

/// The thickness of a pair (kernels/dcr.hpp PairThickness) from surface.reach: h = r of the
/// vertex + r of the face / r of edge a + r of edge b (a primitive's nodes are of one body).
PairThickness pair_thickness(const ContactPair& pair, const DcrSurface& surface);

/// Per pair, a lower bound on the gap between the boxes of its two primitives at positions
/// x: the largest separation along an axis of the boxes of their nodes (<= 0 when they
/// overlap), less kBoxInflation x the boxes' largest sides, the pair's thickness h
/// (pair_thickness) and a rounding slack of 1e-9 x (the largest coordinate's magnitude + the
/// sides). While every node stays within D of x (max norm) at x_old and x_new, a pair with
/// gap > kGapDrift D fails pair_boxes_overlap (tests/contact/test_dcr_screen.cpp).
std::vector<double> pair_gaps(std::span<const ContactPair> pairs, std::span<const Vec3> x, const DcrSurface& surface);

/// The outward normals of a pair (surface_normal, from the triangle normals tn of the
/// configuration wanted): a vertex-face pair's vertex normal (and 0), an edge-edge pair's
/// normals of edge a and edge b and of their triangles in which they run a0 -> a1, b0 -> b1
/// (edge_face_normal); all 0 without a surface.
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
///   rigid     (null: none) the free rigid bodies: a pair's nodes of one body move with it
///             (PairMobility; their inv_mass is not read), and DcrResult::rigid gets the
///             impulses and shifts the body takes. A pair may hold nodes of one rigid body only.
/// mine: the candidate pairs this rank checks (on one rank, all of them), in canonical order.
/// The work goes in rounds:
///   1. detection, in parallel, reading only: in the first round each pair of mine whose swept
///      boxes overlap (pair_boxes_overlap: the pairs a fresh search would give, kept in
///      scratch.overlapping) is checked by dcr_detect; in later rounds each of those with a
///      node moved in the previous round (the others would be found clean again);
///   2. the pairs found are linked on their nodes in key order (dcr_order.hpp; with ranks,
///      over all ranks' pairs);
///   3. resolution: each found pair, once the pairs before it on its nodes are resolved, is
///      re-detected and resolved by dcr_resolve_pair; the pairs ready together run in parallel.
///      With ranks, the states of a node pass from the rank of one pair on it to the next's.
/// Rounds repeat until a detection finds nothing on any rank; when round options.max_sweeps
/// still finds pairs, they are resolved and the result is capped. The result is that of one
/// rank and one thread resolving the found pairs one by one in key order, bit for bit. With
/// ranks, each node a pair moved ends with its final state on every rank that reads it
/// (DcrRanks::settle). Pairs whose four nodes are not distinct are skipped. Run inside the
/// caller's tbb::task_arena to choose the thread count.
DcrResult resolve_contacts(std::span<const ContactPair> mine, std::span<Vec3> x_new,
                           std::span<const Vec3> x_old, std::span<Vec3> v, std::span<const double> inv_mass,
                           double dt, const DcrOptions& options, const DcrSurface& surface, DcrScratch& scratch,
                           DcrRanks* ranks = nullptr, std::span<const std::uint8_t> held = {},
                           const DcrRigidBodies* rigid = nullptr);

}  // namespace shatter
