#pragma once
// DCR sweeps: the decomposition contact response of Cirak & West, "Decomposition
// contact response (DCR) for explicit finite element dynamics", IJNME 64 (2005)
// 1078-1110, over all candidate pairs of a step. The per-pair physics is in
// kernels/dcr.hpp; this module runs it Gauss-Seidel fashion over colored pairs:
// each sweep visits the colors in order, and the pairs of one color (which share
// no node) in a tbb::parallel_for. Every node receives its updates in the fixed
// order (sweep, color, pair), so results are bitwise identical for any number of
// threads.
#include <span>
#include <vector>

#include "contact/pairs.hpp"
#include "kernels/dcr.hpp"

namespace shatter {

/// Contact law and sweep control (scene keys contact.restitution, contact.friction).
struct DcrOptions {
  double restitution = 1.0;  ///< e in [0, 1]
  double friction = 0.0;     ///< Coulomb mu >= 0
  double gap = 1e-6;         ///< separation after projection, fraction of the pair's longest edge
  int max_sweeps = 100;      ///< cap on Gauss-Seidel sweeps; reaching it sets DcrResult::capped
  bool mid_step = false;     ///< collision in the middle of the step (DcrLaw::mid_step)
};

/// Summary of one call of resolve_contacts.
struct DcrResult {
  Index contacts = 0;       ///< pairs found penetrating in at least one sweep (history "contacts")
  int sweeps = 0;           ///< sweeps run, the last one included
  double dissipated = 0.0;  ///< kinetic energy lost by the impacts and friction, J
  bool capped = false;      ///< max_sweeps reached with penetrations still being resolved
  Index unresolved = -1;    ///< when capped: the first pair (in pair order) still penetrating in the last sweep
};

/// Pairs grouped by color, as built by greedy_coloring (runtime/coloring.hpp) over the
/// CSR of contact_pair_nodes: the pairs of color k are items[offsets[k] .. offsets[k+1]),
/// and no two of them share a node. Every pair index appears exactly once.
struct DcrPairColors {
  std::span<const Index> offsets;
  std::span<const Index> items;
};

/// The pair -> node CSR to color: the nodes of pair i are
/// nodes[offsets[i] .. offsets[i+1]) (four per pair, in ContactPair::nodes order).
void contact_pair_nodes(const ContactPairs& pairs, std::vector<Index>& offsets, std::vector<Index>& nodes);

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
/// Run inside the caller's tbb::task_arena to choose the thread count.
DcrResult resolve_contacts(const ContactPairs& pairs, std::span<Vec3> x_new, std::span<const Vec3> x_old,
                           std::span<Vec3> v, std::span<const double> inv_mass, double dt,
                           const DcrOptions& options, const DcrPairColors& colors);

}  // namespace shatter
