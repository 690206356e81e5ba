#pragma once
// Halo exchange of nodal arrays between the ranks of a volume decomposition
// (DESIGN.md "Parallel model", docs/parallel.md): summation of partial nodal
// sums over the ranks that share a node, and copy of owned values to the
// ghost copies of other ranks. Nonblocking (MPI_Isend/MPI_Irecv) with a
// begin/end split, so interior work can run while the messages travel.
#include <mpi.h>

#include <cstddef>
#include <span>
#include <vector>

#include "kernels/types.hpp"
#include "mesh/partition.hpp"

namespace shatter {

/// Which copies a ghost update refreshes.
enum class GhostCopies {
  all,         ///< every node held here and owned by another rank
  ghost_only,  ///< only nodes that no owned element uses (LocalMesh::node_touched == 0)
};

/// Exchanges nodal arrays of one LocalMesh. Nodal arrays are laid out
/// node-major: values[n*components + c] is component c of local node n, and
/// hold exactly mesh.num_nodes() * components doubles.
///
/// Summation (sum_nodal): each rank fills `values` with partial sums over the
/// elements it OWNS. For every shared node, each rank touching it sends its
/// partial to all other ranks touching it; every one of them then adds the
/// partials in ascending rank order, its own at its rank position, starting
/// from +0.0: value = ((0 + p_r0) + p_r1) + ... for r0 < r1 < ... So the
/// result does not depend on message timing, and all ranks touching a node
/// hold bitwise the same value. Nodes touched only here are left as they are;
/// nodes held here but touched only elsewhere (ghost-only) keep their input:
/// update_ghosts fills them.
///
/// Ghost update (update_ghosts): every node held here and owned by another
/// rank (LocalMesh::node_owner) receives the owner's value, bit for bit; with
/// GhostCopies::ghost_only only the nodes that no owned element uses do, which
/// is all the owner-computes scheme needs (docs/parallel.md): a touched node
/// has its whole element star here and integrates itself.
///
/// One exchange at a time per Halo: a begin_* must be followed by its end_*
/// before the next begin_*. Between begin and end the caller may not change
/// the entries that are sent (shared nodes for a sum, owned nodes for an
/// update) nor read the entries that will be written. MPI is called only from
/// the calling thread (MPI_THREAD_FUNNELED suffices).
class Halo {
 public:
  /// Collective over `comm` (duplicated, so messages never mix with the
  /// caller's). `local` must be the LocalMesh of this rank of `comm`; its node
  /// lists are copied.
  Halo(const LocalMesh& local, MPI_Comm comm);
  /// A Halo that only refreshes copies: `send` lists, per other rank, the
  /// nodes of the `num_nodes` whose values go there, `receive` the nodes
  /// filled from each rank (lists matching pairwise as in LocalMesh).
  /// update_ghosts refreshes exactly those (for either GhostCopies); there is
  /// nothing to sum. Collective over `comm`.
  Halo(Index num_nodes, const NodeExchange& send, const NodeExchange& receive, MPI_Comm comm);
  ~Halo();
  Halo(const Halo&) = delete;
  Halo& operator=(const Halo&) = delete;

  /// Post the sends of this rank's partials of shared nodes and the receives.
  void begin_sum(std::span<const double> values, int components);
  /// Wait, then combine the partials of every shared node in rank order.
  void end_sum(std::span<double> values, int components);
  /// begin_sum + end_sum.
  void sum_nodal(std::span<double> values, int components);
  void sum_nodal(std::span<Vec3> values);

  /// Post the sends of owned values to the ranks holding those `copies`, and the receives.
  void begin_update(std::span<const double> values, int components,
                    GhostCopies copies = GhostCopies::all);
  void begin_update(std::span<const Vec3> values, GhostCopies copies = GhostCopies::all);
  /// Wait, then overwrite the copies chosen in begin_update with their owners' values.
  void end_update(std::span<double> values, int components);
  void end_update(std::span<Vec3> values);
  /// begin_update + end_update.
  void update_ghosts(std::span<double> values, int components,
                     GhostCopies copies = GhostCopies::all);
  void update_ghosts(std::span<Vec3> values, GhostCopies copies = GhostCopies::all);

  /// Bytes this rank sends in one sum / one update of `components` doubles per node.
  std::size_t sum_bytes(int components) const {
    return shared_.nodes.size() * components * sizeof(double);
  }
  std::size_t update_bytes(int components, GhostCopies copies = GhostCopies::all) const {
    return sends(copies).nodes.size() * components * sizeof(double);
  }
  /// Messages this rank sends per sum / per update.
  int sum_messages() const { return shared_.num_ranks(); }
  int update_messages(GhostCopies copies = GhostCopies::all) const {
    return sends(copies).num_ranks();
  }

 private:
  enum class Pending { none, sum, update };
  void check(std::span<const double> values, int components, Pending expected) const;
  void post(const NodeExchange& out, const NodeExchange& in, std::span<const double> values,
            int components, int tag);
  void wait();
  const NodeExchange& sends(GhostCopies copies) const {
    return copies == GhostCopies::all ? send_ : only_send_;
  }
  const NodeExchange& receives(GhostCopies copies) const {
    return copies == GhostCopies::all ? recv_ : only_recv_;
  }

  MPI_Comm comm_ = MPI_COMM_NULL;
  Index num_nodes_ = 0;
  NodeExchange shared_, send_, recv_, only_send_, only_recv_;
  // Combination plan of the sum: shared node combine_node_[j] adds, in rank
  // order, the sources combine_source_[combine_offsets_[j] .. [j+1]): an
  // index into shared_.nodes (a neighbour's partial, at the same position in
  // the receive buffer) or -1 (this rank's own partial).
  std::vector<Index> combine_node_, combine_offsets_, combine_source_;
  std::vector<double> send_buffer_, recv_buffer_;
  std::vector<MPI_Request> requests_;
  Pending pending_ = Pending::none;
  GhostCopies pending_copies_ = GhostCopies::all;
};

}  // namespace shatter
