#pragma once
// How the time loop is shared between MPI ranks (DESIGN.md "Parallel model",
// docs/parallel.md "The decomposed time loop").
//
// A rank holds either its part of the model (owned elements and ghost
// layer, Model::Part; two ghost layers with fracture) or the whole model
// (scenes with both fracture and contact); either way the work is divided
// as follows, on the part's local
// ids, the granules and blocks being those of the whole model. The elements are cut into granules of ElementForces::kGranule
// consecutive elements (consecutive in the locality order, so a granule is a
// compact piece of a body) and METIS k-way partitions the granule graph (two
// granules adjacent when they share nodes, weighted by the number of shared
// nodes; vertex weight = elements). A rank
//   - OWNS the elements of its granules and TOUCHES their nodes;
//   - computes its owned elements and a ghost layer: every element with a
//     node it touches (so a touched node has its whole element star here and
//     gets, from ElementForces' fixed block/color order, the serial bits);
//   - integrates its touched nodes; every rank touching a node integrates it
//     with the same bits, so no force is summed over ranks;
//   - receives each step the positions of its ghost-only nodes (held through
//     the ghost layer, not touched) from their owner, the smallest rank
//     touching them (Halo, nonblocking).
// Global sums (energies, momenta, work, body rows) are summed per granule by
// the granule's owner, in a fixed order - a node counts in its HOME granule,
// the granule of the first element of its star - and the granules' partial
// sums are added exactly (ExactSum, kernels/exact_sum.hpp) and reduced over
// the ranks by one reduction of constant size (sum()). The result is the
// same double on every rank and for any decomposition and thread count.
// With one rank (or MPI not initialised) nothing is communicated. Shell
// nodes (runtime/shell_model.hpp; the whole model on every rank) are in no
// element: they have granules of their own, of kShellGranule shell nodes
// consecutive along a Morton curve, after the elements' granules,
// partitioned by METIS over the shell patches; the owner of its granule alone touches a shell node, and
// the shell patches are node groups (rebuild_nodes): a rank computes every
// patch with a node it touches and receives the patch's other nodes (the
// 2-ring ghost layer).
#include <mpi.h>

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <vector>

#include "kernels/exact_sum.hpp"
#include "kernels/types.hpp"
#include "mesh/partition.hpp"
#include "runtime/element_forces.hpp"
#include "runtime/model.hpp"
#include "runtime/parallel.hpp"
#include "runtime/shell_model.hpp"

namespace shatter {

class Halo;

/// Load balance and message volume of a decomposition (summary.json).
struct DecompositionStats {
  long owned_min = 0, owned_max = 0;  ///< owned elements per rank
  long local_max = 0;                 ///< owned + ghost elements per rank
  long ghost_bytes_max = 0;           ///< bytes one rank sends per ghost update
  long ghost_messages_max = 0;        ///< messages one rank sends per ghost update
};

class Decomposition {
 public:
  /// Partitions `model`'s elements over the ranks of `comm` (every rank
  /// computes the same partition; no communication; a part of the model
  /// brings the start-up rank's). Throws InputError when the mesh has fewer
  /// granules than ranks.
  Decomposition(const Model& model, MPI_Comm comm);
  ~Decomposition();
  Decomposition(const Decomposition&) = delete;
  Decomposition& operator=(const Decomposition&) = delete;

  /// Recompute the node lists after node splitting or cohesive insertion
  /// (granule ownership stays). `groups`: node groups of `group_width` ids
  /// each (negative ids skipped), the cohesive elements' side nodes: a rank
  /// also holds, and receives from their owners, the nodes of every group
  /// with a node it touches (it computes those groups' forces;
  /// docs/parallel.md "Cohesive elements on ranks").
  void rebuild_nodes(std::span<const Index> groups = {}, int group_width = 1);
  /// The groups holding a node (indices into rebuild_nodes' groups, in any order,
  /// repeats allowed), appended to the vector.
  using GroupsOfNode = std::function<void(Index node, std::vector<Index>& out)>;
  /// rebuild_nodes after an insertion, with the same lists and halo plan, but
  /// recomputed only around what changed (docs/parallel.md "Cohesive elements
  /// on ranks"): `changed`, ascending, holds every node whose element star
  /// changed (the split nodes and their new copies, which follow the nodes of
  /// the last rebuild); groups [0, old_groups) were there at the last rebuild
  /// and changed only in their nodes of `changed`; groups_of lists the groups
  /// around a node. The work is that of the changed nodes' stars and groups
  /// and of their neighbours, and of copying the lists, not of the part's
  /// elements. (With shell nodes, rebuild_nodes.)
  void update_nodes(std::span<const Index> changed, std::span<const Index> groups, int group_width,
                    Index old_groups, const GroupsOfNode& groups_of);

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool distributed() const { return size_ > 1; }
  MPI_Comm comm() const { return comm_; }

  Index num_granules() const { return static_cast<Index>(granule_rank_.size()); }
  int granule_rank(Index g) const { return granule_rank_[g]; }
  bool owns_granule(Index g) const { return granule_rank_[g] == rank_; }
  std::span<const Index> owned_granules() const { return owned_granules_; }
  /// Owned elements and the ghost layer, ascending.
  std::span<const Index> local_elements() const { return local_elements_; }
  /// Nodes of local_elements() and of the groups with a touched node (rebuild_nodes), ascending.
  std::span<const Index> held_nodes() const { return held_nodes_; }
  /// Nodes of owned elements (integrated here), ascending.
  std::span<const Index> touched_nodes() const { return touched_nodes_; }
  /// The home nodes of the k-th owned granule (owned_granules()[k]), ascending:
  /// the nodes whose home granule (the granule of the first element of their
  /// star) it is. A node's terms in global sums are added by its home
  /// granule's owner, which touches it.
  std::span<const Index> home_nodes(size_t k) const {
    return {home_nodes_.data() + home_offsets_[k], static_cast<size_t>(home_offsets_[k + 1] - home_offsets_[k])};
  }
  /// The home nodes of all owned granules, ascending.
  std::span<const Index> owned_nodes() const { return owned_nodes_; }
  /// Whether this rank adds node n's terms to global sums (it owns n's home granule).
  bool owns_node(Index n) const { return home_granule_[n] >= 0 && owns_granule(home_granule_[n]); }
  /// Elements of the owned granules, ascending.
  std::span<const Index> owned_element_ids() const { return owned_element_ids_; }
  /// Whether element e is owned here.
  bool owns_element(Index e) const { return owns_granule(model_.whole_element(e) / ElementForces::kGranule); }
  /// The rank owning element e (held here).
  int element_rank(Index e) const { return granule_rank_[model_.whole_element(e) / ElementForces::kGranule]; }
  /// The ranks touching the node, ascending (empty on one rank).
  std::span<const int> node_ranks(Index node) const {
    if (size_ == 1) return {};
    return {node_ranks_.data() + node_rank_offsets_[node],
            static_cast<size_t>(node_rank_offsets_[node + 1] - node_rank_offsets_[node])};
  }
  /// Whether rank r touches the node (on several ranks).
  bool touches(Index node, int r) const {
    return std::binary_search(node_ranks_.begin() + node_rank_offsets_[node],
                              node_ranks_.begin() + node_rank_offsets_[node + 1], r);
  }
  /// The smallest rank touching the node.
  int node_owner(Index node) const { return size_ == 1 ? 0 : node_ranks_[node_rank_offsets_[node]]; }
  Index owned_elements() const { return owned_elements_; }

  /// Apply body(i) to every touched node, in parallel (all nodes on 1 rank).
  template <class Body>
  void for_touched(Index num_nodes, Body body) const;

  /// Positions of the ghost-only nodes from their owners, nonblocking: begin
  /// posts the owned values (x must not change until end), end waits and
  /// writes the ghost-only nodes (not to be read before). No-ops on one rank.
  void begin_ghost_update(std::span<const Vec3> x) const;
  void end_ghost_update(std::span<Vec3> x) const;
  /// Nodes held here but touched only by other ranks (filled by the update), ascending.
  std::span<const Index> ghost_only_nodes() const { return ghost_only_nodes_; }
  /// Bytes this rank sends per ghost update.
  std::size_t ghost_bytes() const;
  /// Over all ranks (collective).
  DecompositionStats stats() const;

  /// In place: every rank's accumulators become their sum over the ranks
  /// (exact; ~570 bytes per accumulator, whatever the model), and every rank's
  /// `most` their element-wise maxima, in the same message.
  void sum(std::span<ExactSum> values, std::span<long> most = {}) const;
  /// Bytes one sum() of `count` accumulators and `maxima` maxima sends per rank.
  static std::size_t sum_bytes(std::size_t count, std::size_t maxima = 0);
  /// In place: `root`'s values on every rank.
  void broadcast(std::span<double> values, int root) const;
  /// `root`'s text on every rank.
  std::string broadcast(std::string text, int root) const;
  /// Every rank's `mine`, concatenated in rank order, on every rank.
  std::vector<Index> allgather(std::span<const Index> mine) const;
  std::vector<GlobalId> allgather(std::span<const GlobalId> mine) const;
  std::vector<double> allgather(std::span<const double> mine) const;
  /// This rank's `mine` followed by the lists of the ranks around it (any
  /// order): each rank sends its list to the ranks whose parts hold an
  /// element it owns, which are the ranks owning an element of its part (the
  /// ghost layers are rings of elements sharing nodes, so the relation is
  /// symmetric). A list about facets of owned elements (critical, freed) thus
  /// reaches every rank holding one of them, and no other; with the whole
  /// model on every rank, every rank. Collective (alltoall).
  std::vector<GlobalId> share_with_neighbours(std::span<const GlobalId> mine) const;
  /// Sparse all-to-all: to[r] goes to rank r (to.size() == size()); returns what each rank sent here
  /// (MPI_Alltoall of the counts, MPI_Alltoallv of the ids; collective).
  std::vector<std::vector<Index>> alltoall(const std::vector<std::vector<Index>>& to) const;
  std::vector<std::vector<GlobalId>> alltoall(const std::vector<std::vector<GlobalId>>& to) const;
  /// Global minimum (exact in any order).
  double min(double value) const;
  /// In place: the element-wise global minima.
  void min(std::span<double> values) const;
  /// The same, and in the same message the least (key, index) pair over the
  /// ranks: the smallest key, then the smallest index (MPI's MINLOC order).
  void min(std::span<double> values, std::pair<double, long>& least) const;
  /// In place: the element-wise global maxima.
  void max(std::span<double> values) const;
  /// The smallest rank holding the global minimum of `value`.
  int rank_of_min(double value) const;
  /// Element-wise sums over the ranks, on every rank.
  std::vector<long> sum(std::vector<long> values) const;
  /// Global maximum of an int.
  int max(int value) const;
  /// Global maximum of a long.
  long max(long value) const;
  /// Every rank's value in rank order, on rank 0 (empty elsewhere).
  std::vector<long> gather(long value) const;

 private:
  template <class T>
  std::vector<std::vector<T>> alltoall_of(const std::vector<std::vector<T>>& to, MPI_Datatype type) const;

  const Model& model_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
  std::vector<int> granule_rank_;
  std::vector<int> neighbours_;  ///< the other ranks owning an element held here, ascending
  /// The first granule of the shell nodes (kShellGranule shell nodes each,
  /// past the elements' granules; a shell node's home granule).
  Index first_shell_granule_ = 0;
  Index first_shell_node_ = 0, shell_nodes_ = 0;
  /// Per shell node (from first_shell_node_): its position along the Morton
  /// curve of the shells' reference positions; granule g holds positions
  /// [g kShellGranule, (g+1) kShellGranule), so a granule is a compact piece of a shell.
  std::vector<Index> shell_position_;
  ShellPatchNodes shell_patches_;  ///< the nodes of every shell patch (groups of rebuild_nodes)
  bool is_shell_node(Index n) const { return n >= first_shell_node_ && n < first_shell_node_ + shell_nodes_; }
  std::vector<Index> owned_granules_;
  Index owned_elements_ = 0;
  std::vector<Index> node_rank_offsets_;
  std::vector<int> node_ranks_;  ///< CSR: ranks touching each node, ascending (empty on one rank)
  std::vector<Index> local_elements_, held_nodes_, touched_nodes_, ghost_only_nodes_;
  std::vector<Index> owned_nodes_, owned_element_ids_;
  std::vector<Index> home_granule_;               ///< per node
  std::vector<Index> home_offsets_, home_nodes_;  ///< CSR over the owned granules' index k
  /// Per rank, the nodes sent to it / received from it per ghost update, ascending (the halo plan).
  std::map<int, std::vector<Index>> send_, recv_;
  /// Node n's home granule: the granule of the first element of its star (a
  /// shell node's own granule; -1 for a node in no element).
  Index home_granule_of(Index n) const;
  std::unique_ptr<Halo> halo_;
};

/// Throws InputError when `model` has fewer granules than `ranks`, saying how
/// many ranks it can take.
void check_ranks(const Model& model, int ranks);

/// The ranks touching each node of `mesh` when granule g of the whole model
/// (ElementForces::kGranule elements) belongs to granule_rank[g]; on a part,
/// `whole_element` gives each element's index in the whole model (empty: `mesh`
/// is the whole model). A node's ranks are whole when its star is.
NodeRanks granule_touching_ranks(const Mesh& mesh, std::span<const int> granule_rank,
                                 std::span<const Index> whole_element = {});

template <class Body>
void Decomposition::for_touched(Index num_nodes, Body body) const {
  if (!distributed()) return parallel_for_each(num_nodes, body);
  parallel_for_each(static_cast<Index>(touched_nodes_.size()), [&](Index k) { body(touched_nodes_[k]); });
}

}  // namespace shatter
