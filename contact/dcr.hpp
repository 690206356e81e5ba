#pragma once
// DCR sweeps: the decomposition contact response of Cirak & West, "Decomposition
// contact response (DCR) for explicit finite element dynamics", IJNME 64 (2005)
// 1078-1110, over all candidate pairs of a step. The per-pair physics is in
// kernels/dcr.hpp; this module runs it Gauss-Seidel fashion over colored pairs:
// each sweep visits the colors in order, and the pairs of one color (which share
// no node) in a tbb::parallel_for. Every node receives its updates in the fixed
// order (sweep, color, pair), so results are bitwise identical for any number of
// threads.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "contact/pairs.hpp"
#include "contact/surface.hpp"
#include "kernels/dcr.hpp"

namespace shatter {

/// Contact law and sweep control (scene keys contact.restitution, contact.friction).
struct DcrOptions {
  double restitution = 1.0;  ///< e in [0, 1]
  double friction = 0.0;     ///< Coulomb mu >= 0
  double gap = 1e-6;         ///< separation after projection, fraction of the pair's longest edge
  int max_sweeps = 100;      ///< cap on Gauss-Seidel sweeps; reaching it sets DcrResult::capped
  DcrPlacement placement = DcrPlacement::End;  ///< where in the step a collision is placed (DcrLaw)
};

/// Summary of one call of resolve_contacts.
struct DcrResult {
  Index contacts = 0;       ///< pairs found penetrating in at least one sweep (history "contacts")
  int sweeps = 0;           ///< sweeps run, the last one included
  double dissipated = 0.0;  ///< kinetic energy lost by the impacts and friction, J
  bool capped = false;      ///< max_sweeps reached with penetrations still being resolved
  Index unresolved = -1;    ///< when capped: the first pair (in pair order) still penetrating in the last sweep
  int exchanges = 0;        ///< DcrRemote::exchange calls
};

/// Pairs grouped by color, as built by greedy_coloring (runtime/coloring.hpp) over the
/// CSR of contact_pair_nodes: the pairs of color k are items[offsets[k] .. offsets[k+1]),
/// and no two of them share a node. Every pair index appears exactly once.
/// slots: the CSR's compact node numbers (four per pair), num_slots of them, so that the
/// sweeps' per-node bookkeeping is sized by the pairs' nodes, not by the mesh.
/// normals: two per pair, the outward surface normals at the start of the step by which DCR
/// tells touching from penetrating (contact_pair_normals, kernels/dcr.hpp PairNormals).
struct DcrPairColors {
  std::span<const Index> offsets;
  std::span<const Index> items;
  std::span<const Index> slots;
  Index num_slots = 0;
  std::span<const Vec3> normals;
};

/// The pair -> node CSR to color, the nodes numbered compactly: pair i's nodes are
/// slots[offsets[i] .. offsets[i+1]) (four per pair, in ContactPair::nodes order), a node's
/// slot being its index among the pairs' distinct nodes in order of first appearance.
/// node_slot: scratch indexed by node id (larger than every node of the pairs) holding -1,
/// and left so: the cost is O(pairs), whatever the mesh size. Returns the number of slots.
Index contact_pair_nodes(const ContactPairs& pairs, std::vector<Index>& offsets, std::vector<Index>& slots,
                         std::vector<Index>& node_slot);

/// The outward surface normals of each pair at x (surface_normal), two per pair in pair order,
/// for DcrPairColors::normals: a vertex-face pair's vertex normal (and 0), an edge-edge pair's
/// normals of edge a and edge b (the sums over their triangles). O(pairs).
std::vector<Vec3> contact_pair_normals(const ContactPairs& pairs, const ContactSurface& surface,
                                       const VertexTriangles& around, std::span<const Vec3> x);

/// The pairs resolved elsewhere (other MPI ranks: runtime/contact_stage.cpp). Pair i belongs
/// to rank owner[i]; resolve_contacts resolves the pairs of `rank` and hands the ones it found
/// penetrating (in sweep, color, pair order) with their dissipation in that sweep to exchange,
/// which must write x_new and v of the nodes of the pairs found penetrating elsewhere since the
/// last exchange and list them (in the order of their rank's list, ranks in turn) with their
/// dissipation in `there`. An exchange is made at the end of each sweep and before every color
/// with a pair whose node a pair of another rank touched since the last exchange (a schedule the
/// same on every rank, from the coloring and owner only). The pairs of one color share no node,
/// so each pair reads the states the serial sweeps would give it: the result is the serial one
/// bit for bit, on every rank.
struct DcrRemote {
  struct Moves {
    std::vector<Index> pairs;
    std::vector<double> dissipated;
  };
  std::span<const int> owner;
  int rank = 0;
  std::function<void(const Moves& here, Moves& there)> exchange;
};

/// Resolves the penetrations of one step (DESIGN.md step 2). Nodal arrays are indexed by
/// the local node ids of the pairs:
///   x_new     positions at the end of the step (m), projected in place;
///   x_old     positions at the start of the step (m), the motion is linear in between;
///   v         velocities (m/s), changed in place by the impulses;
///   inv_mass  inverse lumped masses (1/kg), 0 for a fixed node (never moved);
///   dt        the step length (s): x_new = x_old + dt v before contact.
/// Each sweep re-checks every pair (dcr_detect) and resolves the penetrating ones
/// (dcr_project, dcr_impulse); sweeps repeat until one finds no penetration or
/// options.max_sweeps is reached. Pairs whose four nodes are not distinct are skipped.
/// Run inside the caller's tbb::task_arena to choose the thread count. With `remote`, only
/// the pairs of remote->rank are resolved here (above); the result is the same on every rank.
DcrResult resolve_contacts(const ContactPairs& pairs, std::span<Vec3> x_new, std::span<const Vec3> x_old,
                           std::span<Vec3> v, std::span<const double> inv_mass, double dt,
                           const DcrOptions& options, const DcrPairColors& colors,
                           const DcrRemote* remote = nullptr);

}  // namespace shatter
