#pragma once
// Executor of the bulk element loop (STYLE.md level 3): elements are cut into
// consecutive blocks, blocks that share a node get different colors, and the
// blocks run as oneTBB tasks, each scattering its elements' forces straight
// into the nodal array. A block waits only for the blocks of lower colors that
// share a node with it (a graph of blocks, not a barrier per color), so a node
// receives its contributions in a fixed order (color, element), and forces are
// bitwise identical for any thread count.
//
// Under MPI (runtime/decomposition.hpp) a rank computes only a subset of the
// elements (its owned granules and its ghost layer) with the SAME blocks and
// colors: a node whose whole element star is in the subset receives the same
// contributions in the same order as in a serial run, i.e. the same bits. The
// strain energy is summed per granule of kGranule consecutive elements, the
// unit of ownership between ranks, in element order; exact sums of the
// granules' energies (ExactSum) then do not depend on the decomposition.
#include <array>
#include <functional>
#include <span>
#include <vector>

#include "mesh/coloring.hpp"
#include "runtime/model.hpp"

namespace shatter {

struct ElementLoopResult {
  double strain_energy = 0;       ///< J
  double stable_dt = HUGE_VAL;    ///< min over elements of h_e / c_d(e), s (no safety factor)
  Index worst_element = -1;       ///< element with the smallest det F (J)
  double min_jacobian = HUGE_VAL; ///< smallest det F over all elements/points
};

class ElementForces {
 public:
  /// Elements per block: large enough to amortise task overhead and reuse the
  /// block's nodes from cache, small enough to leave ~20 blocks per color at
  /// 300k elements (docs/performance.md, "Element kernels": 1024 and 4096
  /// equal within noise, 256 is 15 % slower).
  static constexpr Index kBlock = 1024;
  /// Elements per granule (a block holds kBlock / kGranule of them).
  static constexpr Index kGranule = 256;
  static_assert(kBlock % kGranule == 0 && kGranule % 4 == 0);

  explicit ElementForces(const Model& model);

  /// Recolor after a topology change (node splitting).
  void rebuild();

  /// Compute only `elements` (ascending) from now on, and zero only `nodes`
  /// (ascending: the nodes of those elements) in f_int. Blocks without one
  /// of them are skipped. Without a call: every element and node. The
  /// elements of rigid bodies (BodySpec::any_rigid) are never computed.
  ///
  /// `late_nodes` (any order): nodes whose positions arrive while compute()
  /// runs (a halo exchange between its two phases, see compute). The blocks
  /// are split into an early phase that reads none of them and a late phase,
  /// such that no node gets a late contribution before an early one of a
  /// higher color: the late set is the blocks touching a late node, closed
  /// under "an early block whose color is above that of a late block sharing
  /// a node turns late". Every node thus still receives its contributions in
  /// color order, the same bits as in one phase.
  void restrict_to(std::span<const Index> elements, std::span<const Index> nodes,
                   std::span<const Index> late_nodes = {});

  /// Blocks of the early phase and of the late phase (restrict_to).
  Index early_blocks() const { return static_cast<Index>(phase_items_[0].size()); }
  Index late_blocks() const { return static_cast<Index>(phase_items_[1].size()); }

  /// Strain energy of the computed elements of granule `granule` (of the
  /// whole model) in the last compute(), J; 0 for a granule not held here.
  double granule_energy(Index granule) const;

  /// f_int = dE/dx at positions x (overwrites f_int, size = nodes). The
  /// result's strain_energy is the exact sum of granule_energy(),
  /// stable_dt and min_jacobian are over the computed elements. When
  /// stress6 is not empty, also writes each element's Cauchy stress there
  /// (6 per element, as element_cauchy_stress6) for the fracture check.
  /// `between` (if any) runs after the early blocks and before the late ones
  /// (restrict_to): it must complete the late nodes' positions in x.
  ElementLoopResult compute(std::span<const Vec3> x, std::span<Vec3> f_int, std::span<double> stress6 = {},
                            const std::function<void()>& between = {}) const;

  int num_colors() const { return coloring_.num_colors(); }
  /// Elements compute() computes: those of restrict_to (all without it), less rigid bodies'.
  Index computed_elements() const { return static_cast<Index>(subset_.size()); }

 private:
  void split_phases(const std::vector<char>& late);
  /// The block (index into blocks_) of element e.
  Index block_of(Index e) const;
  /// Compute `elements` (ascending), grouped by block.
  void set_subset(std::span<const Index> elements);

  const Model& model_;
  /// The whole model's blocks of kBlock and granules of kGranule elements
  /// that hold elements of this model, ascending (all of them on the whole model).
  std::vector<Index> blocks_, granules_;
  Coloring coloring_;  ///< of blocks_: the whole model's coloring
  std::vector<Index> subset_offsets_, subset_;  ///< CSR per block: its elements to compute
  std::vector<Index> zero_nodes_;               ///< nodes to zero after restrict_to (empty: all)
  /// Per phase (early, late): the blocks in color order.
  std::array<std::vector<Index>, 2> phase_items_;
  /// Per phase, its blocks (positions in phase_items_) as a graph: a block's successors are the
  /// blocks of the phase that next touch one of its nodes, by color (CSR); `waits` counts each
  /// block's predecessors, `first` lists the blocks with none.
  struct BlockGraph {
    std::vector<Index> first, successor_offsets, successors;
    std::vector<int> waits;
  };
  std::array<BlockGraph, 2> graphs_;
  mutable std::vector<double> granule_energy_;  ///< per granules_
  mutable std::vector<double> block_dt_, block_min_J_;
  mutable std::vector<Index> block_worst_;
};

/// The colors of the whole mesh's blocks of ElementForces::kBlock consecutive
/// elements: greedy, in block order, blocks sharing a node differ. A part
/// of the model keeps these (Model::Part::block_color), so a node receives
/// its contributions in the same order on every rank.
std::vector<int> block_colors(const Mesh& mesh);

/// One element's stable step at positions x, as ElementForces::compute takes
/// it (its minimum over the elements is ElementLoopResult::stable_dt), and its
/// det F (TET10: the smallest over its points). For diagnoses, not the loop.
struct ElementStep {
  double dt = 0;  ///< s, without the safety factor
  double J = 0;
};
ElementStep element_stable_step(const Model& model, std::span<const Vec3> x, Index e);

/// Cauchy stress of element e at positions x, averaged over its points, as 6
/// Voigt components xx yy zz yz xz xy (Pa) written to out[0..5].
void element_cauchy_stress6(const Model& model, std::span<const Vec3> x, Index e, double* out);


}  // namespace shatter
