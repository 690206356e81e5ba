#pragma once
// Step 5 of the time loop (DESIGN.md): the facet check, extrinsic insertion
// of cohesive elements with node splitting, cohesive forces and fragments,
// for scenes with a material that has a fracture block.
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <string>
#include <vector>

#include "fracture/cohesive_elements.hpp"
#include "fracture/fragments.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/key_positions.hpp"
#include "runtime/fragment_labels.hpp"
#include "runtime/model.hpp"

namespace shatter {

/// Node slots per cohesive element in CohesiveElements::side_local and
/// side_nodes: 2 sides x 6 (fracture/cohesive_elements.hpp).
inline constexpr int kCohesiveSlots = 2 * 6;

/// What fracture changed in a run since its model was built, between two
/// steps: the part of a checkpoint (runtime/checkpoint.hpp, /fracture) that
/// lets a restarted run continue bitwise. Layouts (n = nodes now: split
/// copies follow the built nodes; e = elements, k = nodes per element,
/// f = facets of the Topology):
///   mesh_revision  Mesh::revision these arrays are of
///   reference[n] (m), node_gid[n], node_body[n], conn[e k]: the mesh after splits
///   mass[n] (kg), bc_mask[n], bc_velocity[n], bc_condition[n], initial_velocity[n] (m/s):
///                  the model's per-node arrays, grown with the mesh
///   facet_gid[o], facet_state[o]: the interior facets that are not intact
///                  (o of them: cohesive or freed), by Topology::facet_gid,
///                  ascending, and their states: named as on any rank
///   cohesive       every cohesive element with its delta_max; its facet ids
///                  are not kept (local to a topology): cohesive_facet_gid[c]
///                  names each one's facet
/// On parts (Model::holds_two_layers) a rank saves its part's state, node ids
/// local, with whole_nodes, whole_cohesive and cohesive_whole to place it in
/// the whole model's; a checkpoint holds the whole model's state, each row
/// written by its owner (checkpoint.hpp CheckpointRows).
struct FractureState {
  std::uint64_t mesh_revision = ~std::uint64_t{0};  ///< none copied yet
  std::vector<Vec3> reference;
  std::vector<GlobalId> node_gid;
  std::vector<int> node_body;
  std::vector<Index> conn;
  std::vector<double> mass;
  std::vector<std::uint8_t> bc_mask;
  std::vector<Vec3> bc_velocity, initial_velocity;
  std::vector<std::array<std::int32_t, 3>> bc_condition;
  std::vector<GlobalId> facet_gid;
  std::vector<FacetState> facet_state;
  CohesiveElements cohesive;
  std::vector<GlobalId> cohesive_facet_gid;
  Index whole_nodes = 0, whole_cohesive = 0;  ///< the whole model's counts
  std::vector<Index> cohesive_whole;           ///< [c]: index among the whole model's cohesive elements
  /// The facet stamp (FractureStage::save) facet_gid, facet_state and
  /// cohesive_facet_gid were listed at; 0: never.
  std::uint64_t facet_stamp = 0;
  /// A part's read of a checkpoint (read_checkpoint; FractureStage::part_of): the
  /// node rows are those of the part's elements, node_rows their whole indices
  /// (ascending), conn the part's elements' rows in whole indices, bc_rows each
  /// prescribed row's rank among the whole model's whole_bc_nodes such nodes.
  std::vector<Index> node_rows, bc_rows;
  Index whole_bc_nodes = 0;
};

/// The state's per-node arrays, in the order of the model's (node_arrays(Model&)).
inline auto node_arrays(FractureState& s) {
  return std::tie(s.reference, s.node_gid, s.node_body, s.mass, s.bc_mask, s.bc_velocity, s.bc_condition,
                  s.initial_velocity);
}
inline auto node_arrays(const FractureState& s) {
  return std::tie(s.reference, s.node_gid, s.node_body, s.mass, s.bc_mask, s.bc_velocity, s.bc_condition,
                  s.initial_velocity);
}

class FractureStage {
 public:
  /// The penalty of each material's cohesive law (the steepest unloading
  /// slope and the normal stiffness in compression) is k_p = E / h_min
  /// (h_min: smallest element altitude of that material), as stiff as the
  /// adjacent elements, not a user knob; stable_dt() accounts for it. With
  /// strength scatter, each facet's strength is drawn here from its global id
  /// (facet_strengths).
  /// `dec`: how the ranks share the model (the penalty's h_min and the
  /// cohesive-zone warning are over the whole model; the cohesive elements
  /// and fragments are divided, share()).
  FractureStage(Model& model, const Decomposition& dec);

  /// Elements the cohesive zone should span at least (Falk, Needleman & Rice,
  /// J. Phys. IV 11 (2001) Pr5-43: 2-5 elements for converged crack speeds).
  static constexpr int kCohesiveZoneElements = 3;
  /// One warning per fracturing material whose cohesive zone length
  /// l_cz = E Gc / sigma_c^2 (Rice's estimate up to a factor of order 1) is
  /// shorter than kCohesiveZoneElements x its mean longest element edge h,
  /// with both lengths; the run goes on. Collective.
  std::vector<std::string> cohesive_zone_warnings() const;

  /// This rank's share of the cohesive elements (docs/parallel.md "Cohesive
  /// elements on ranks"): it computes those with a node it touches and owns
  /// those whose facet's first element (smaller global id) it owns. Call
  /// after every insertion, split or restore, once the decomposition knows
  /// the nodes.
  void share();
  /// share() after `ins`, the last insertion (the decomposition updated):
  /// only the cohesive elements around its changed nodes, and the new ones,
  /// are looked at again (the others' nodes and their touching ranks are as they were).
  void share(const Insertion& ins);

  /// Facet global ids (Topology::facet_gid) of `facets`, and back: the
  /// interior facets held here among `gids` (others skipped). Facet lists
  /// travel between ranks by global id.
  std::vector<GlobalId> gids(std::span<const Index> facets) const;
  std::vector<Index> facets(std::span<const GlobalId> gids) const;
  /// The cohesive elements' side nodes, kCohesiveSlots per element (-1 for
  /// unused slots): the node groups of Decomposition::rebuild_nodes.
  std::span<const Index> side_nodes() const { return cohesive_.side_nodes; }
  /// Appends to `out` the cohesive elements with node n among their side
  /// nodes (Decomposition::update_nodes' groups_of): those on the facets
  /// through n of the elements around n.
  void cohesive_around(Index n, std::vector<Index>& out) const;

  /// Adds the forces dE/dx at positions x of the cohesive elements this rank
  /// computes to f_int (the nodes it touches get every term); returns the
  /// energies of those it owns.
  CohesiveEnergy add_forces(std::span<const Vec3> x, std::span<Vec3> f_int);

  /// Facets whose traction (from the elements' Cauchy stresses, 6 Voigt
  /// components per element) reaches the strength, sorted by facet gid; on
  /// MPI ranks those whose smaller element is owned (critical_facets: `local`
  /// and `owned` elements, empty on one rank).
  std::vector<Index> check(std::span<const Vec3> x, std::span<const double> stress6,
                           std::span<const Index> local = {}, std::span<const Index> owned = {});
  /// The facets of `gids` (critical facets by global id, ascending and
  /// distinct: at least every one held here) that are held here become
  /// cohesive elements, in the order of their ids; nodes split. `whole`:
  /// each gid's position among the whole model's critical facets and their
  /// count (key_positions), which number the cohesive elements as one rank
  /// would. Returns what changed here (new nodes to fill in by the caller).
  Insertion insert(std::span<const GlobalId> gids, const KeyPositions& whole);
  const Topology& topology() const { return topology_; }
  /// Both faces (element, local face) of every cohesive facet not yet freed, ascending.
  std::vector<std::pair<Index, int>> bonded_faces() const;
  /// The node pairs (side 0, side 1) that a cohesive facet not yet freed joins.
  std::vector<std::array<Index, 2>> bonded_twins() const;
  /// The facet of each cohesive element.
  std::span<const Index> cohesive_facets() const { return cohesive_.facet; }

  /// The bound lambda_c of cohesive_eigenvalue_bound for the lumped masses
  /// `mass` (kg, per node), 1/s^2, over the cohesive elements computed here
  /// (the largest over the ranks is the whole model's), recomputed when
  /// cohesive elements or nodes were added or facets freed since the last
  /// call. The stable step of the volume and cohesive elements together is
  /// 2 / sqrt((2 / element_dt)^2 + lambda_c) (no safety factor).
  double eigenvalue_bound(std::span<const double> mass);

  /// The facets among those owned here whose every point has come apart
  /// (debonded_facets), to free on the ranks holding them
  /// (Decomposition::share_with_neighbours).
  std::vector<Index> debonded() const;
  /// Frees the facets of `gids` held here (debonded() of this rank and of the
  /// ranks around, by global id: at least every one held here); `freed`: how
  /// many the whole model frees.
  void release(std::span<const GlobalId> gids, Index freed);
  /// The cohesive elements of `mine`, a state saved here (save()) since the
  /// last insertion or earlier, that this rank owns and writes to a
  /// checkpoint (those whose facet's first element it owns), as indices into
  /// mine's cohesive arrays, ascending by whole index (runtime/fracture_parts.cpp).
  std::vector<Index> owned_cohesive(const FractureState& mine) const;

  Fragments fragments(std::span<const Vec3> x, std::span<const Vec3> v, std::span<const double> mass) const {
    return find_fragments(model_.mesh, topology_, x, v, mass);
  }
  /// The fragments' element ids (of the owned elements and their facet
  /// neighbours) and the whole model's count (no statistics: no positions
  /// needed; FragmentLabels, collective). Recomputed only after facets were
  /// freed or the state restored: nothing else changes them.
  const Fragments& fragment_labels() const;
  /// The whole model's cohesive elements (a part computes some of them).
  Index cohesive_count() const { return whole_cohesive_; }
  /// The crack surface (crack_area) of the cohesive elements owned here, with
  /// the fragments `frags` of the current state (to sum over the ranks).
  CrackArea crack_area(const Fragments& frags) const {
    return shatter::crack_area(model_.mesh, topology_, cohesive_, laws(), frags.elem_fragment, mine());
  }
  /// Per element damage in [0, 1] (element_damage), for output.
  std::vector<double> damage() const { return element_damage(model_.mesh, topology_, cohesive_, laws()); }

  /// Copies the fracture state into `state`, reusing its storage; the mesh
  /// and per-node model arrays only when the mesh changed since `state` was
  /// last filled (its mesh_revision), so saving every step is cheap.
  void save(FractureState& state) const;
  /// Puts `state` (saved from a run of the same model) back into the model's
  /// mesh and per-node arrays, the facet states and the cohesive elements.
  /// On parts `state` is the whole model's (a checkpoint's): the part takes
  /// its elements' nodes, renumbered, and the cohesive elements of its facets
  /// (Model::Part's node indices follow). The caller resizes its own nodal
  /// arrays to the mesh. Throws Error when the arrays do not fit the model
  /// (sizes, node or facet ids out of range).
  void restore(const FractureState& state);
  double check_seconds() const { return check_seconds_; }
  double check_cpu_seconds() const { return check_cpu_seconds_; }  ///< this rank's thread CPU time
  /// The whole model's cohesive elements whose two elements two ranks own
  /// (cracks across subdomains; collective).
  long across_ranks() const;
  /// The cohesive elements this rank owns (computes and frees).
  long owned_count() const {
    return dec_.distributed() ? static_cast<long>(std::count(owned_.begin(), owned_.end(), std::uint8_t{1}))
                              : static_cast<long>(cohesive_.size());
  }

 private:
  Model& model_;
  const Decomposition& dec_;
  Topology topology_;
  std::vector<Index> by_gid_;  ///< interior facets, ascending by facet_gid
  /// Their facet_gid, ascending: facets() searches the whole model's lists
  /// here, without reading the topology at every step of the search.
  std::vector<GlobalId> sorted_gids_;
  CohesiveElements cohesive_;
  /// Per facet, its cohesive element (-1: none), for cohesive_around.
  std::vector<Index> facet_cohesive_;
  /// Fills facet_cohesive_ for the cohesive elements [first, size).
  void index_cohesive(Index first);
  /// Lists cohesive element c in computed_ (and owned_) when it has a node touched here.
  void share_one(Index c);
  std::vector<Index> cohesive_whole_;  ///< [c]: index among the whole model's cohesive elements
  Index whole_cohesive_ = 0;           ///< the whole model's cohesive elements
  /// The part's own state from its read of a checkpoint (`read`: FractureState::node_rows;
  /// restore on parts): local node ids, the facets and cohesive elements held here.
  FractureState part_of(const FractureState& read);
  std::vector<std::optional<CohesiveLaw>> laws_;
  std::vector<double> facet_strength_;  ///< [f] Pa, with strength scatter only
  double weakest_facet_ = 0;            ///< min of facet_strength_, Pa
  FractureLaws laws() const { return {laws_, facet_strength_, weakest_facet_}; }
  /// share()'s lists (unused on one rank: every element, all owned).
  std::vector<Index> computed_;
  std::vector<std::uint8_t> owned_;
  CohesiveShare mine() const { return {computed_, owned_, !dec_.distributed()}; }
  double check_seconds_ = 0, check_cpu_seconds_ = 0;
  long facet_revision_ = 0;  ///< bumped when facets are freed or the state is restored
  /// A stamp unique in the process, new at construction and whenever a facet
  /// changes state (insert, release, restore): save() lists the broken facets
  /// again only when the state it fills holds another stamp's list (a scan of
  /// every facet, 3 % of a fracture run when it ran before every step).
  std::uint64_t facet_stamp_ = 0;
  void stamp_facets();
  std::unique_ptr<FragmentLabels> labeler_;  ///< from the first share_with
  mutable Fragments labels_;
  mutable long labels_revision_ = -1;  ///< facet_revision_ of labels_
  double eigenvalue_bound_ = 0;  ///< cached cohesive bound, 1/s^2
  Index released_ = 0;           ///< cohesive elements freed by release() so far
  /// (cohesive count, node count, released_) the bound was computed for: what
  /// it depends on, so that it always equals a fresh one (a restored run, which
  /// computes it afresh, takes the same steps)
  std::array<Index, 3> bound_key_ = {-1, -1, -1};
};

}  // namespace shatter
