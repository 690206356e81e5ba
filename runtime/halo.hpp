#pragma once
// Ghost update of nodal arrays between the ranks of a volume decomposition
// (DESIGN.md "Parallel model", docs/parallel.md): every rank sends the values
// of nodes it owns to the ranks holding copies of them, which overwrite their
// copies. Nonblocking (MPI_Isend/MPI_Irecv) with a begin/end split, so
// interior work can run while the messages travel.
#include <mpi.h>

#include <cstddef>
#include <span>
#include <vector>

#include "kernels/types.hpp"
#include "mesh/partition.hpp"

namespace shatter {

/// Refreshes copies of nodal arrays from their owners. Nodal arrays are laid
/// out node-major: values[n*components + c] is component c of local node n,
/// and hold exactly num_nodes * components doubles.
///
/// Ghost update (update_ghosts): the nodes in the receive lists get, bit for
/// bit, the values their owners had in the send lists; every other entry is
/// left as it is. Decomposition (runtime/decomposition.hpp) refreshes the
/// positions of its ghost-only nodes with it.
///
/// One exchange at a time per Halo: a begin_update must be followed by its
/// end_update before the next begin_update (else Error). Between begin and
/// end the caller may not change the entries that are sent nor read the
/// entries that will be written. MPI is called only from the calling thread
/// (MPI_THREAD_FUNNELED suffices).
/// The tags of the Halos that share a decomposition's communicator.
enum HaloTag : int { kGhostTag = 7401, kFragmentTag = 7402, kPatchTag = 7403 };

class Halo {
 public:
  /// `send` lists, per other rank, the nodes of the `num_nodes` whose values
  /// go there, `receive` the nodes filled from each rank; the list rank r
  /// sends to q must name the same nodes, in the same order, as the list q
  /// receives from r. The lists are copied. Not collective: `comm` is used
  /// as it is (a duplicate per Halo cost an MPI_Comm_dup, a collective, at
  /// every new plan), and `tag` (HaloTag) keeps the messages of one kind of
  /// exchange apart from the others' on it; the ranks run the updates of one
  /// tag in the same order.
  Halo(Index num_nodes, const NodeExchange& send, const NodeExchange& receive, MPI_Comm comm, int tag);
  /// A plan between two numberings (update()): `send` indexes arrays of `send_nodes`
  /// nodes, `receive` arrays of `receive_nodes`.
  Halo(Index send_nodes, Index receive_nodes, const NodeExchange& send, const NodeExchange& receive, MPI_Comm comm,
       int tag);
  ~Halo();
  Halo(const Halo&) = delete;
  Halo& operator=(const Halo&) = delete;

  /// Post the sends of the listed values and the receives.
  void begin_update(std::span<const double> values, int components);
  void begin_update(std::span<const Vec3> values);
  /// Wait, then overwrite the received nodes with their owners' values.
  void end_update(std::span<double> values, int components);
  void end_update(std::span<Vec3> values);
  /// begin_update + end_update.
  void update_ghosts(std::span<double> values, int components);
  void update_ghosts(std::span<Vec3> values);
  /// update_ghosts of several arrays in one message per rank.
  void update_ghosts(std::span<const std::span<Vec3>> arrays);
  /// The same from one set of arrays into another (the constructor's two numberings):
  /// the send lists' entries of `from[k]` go into the receive lists' entries of `to[k]`.
  void update(std::span<const std::span<const Vec3>> from, std::span<const std::span<Vec3>> to);
  /// One value per listed entry, the lists naming entries of arrays stacked end to end: entry
  /// e of a send list is from[k][e - (the sizes of from[0..k-1])], and likewise for a receive
  /// list and `to`. The sizes of `from` sum to the constructor's send nodes, those of `to` to
  /// its receive nodes. So one message per rank carries some arrays' values for some nodes
  /// and other arrays' for others.
  void update_stacked(std::span<const std::span<const Vec3>> from, std::span<const std::span<Vec3>> to);

  /// Bytes this rank sends per update of `components` doubles per node.
  std::size_t update_bytes(int components) const { return send_.nodes.size() * components * sizeof(double); }
  /// Messages this rank sends per update.
  int update_messages() const { return send_.num_ranks(); }

 private:
  void check(std::span<const double> values, int components, bool expect_pending) const;
  /// Whether arrays of `size` doubles hold `nodes` nodes of `components` (else Error).
  static void check_size(size_t size, Index nodes, int components);
  void wait();
  /// Post the receives and the sends of send_buffer_, `components` doubles per node.
  void post(int components);

  MPI_Comm comm_ = MPI_COMM_NULL;
  int tag_ = 0;
  Index num_nodes_ = 0, num_receive_nodes_ = 0;
  NodeExchange send_, recv_;
  std::vector<double> send_buffer_, recv_buffer_;
  std::vector<MPI_Request> requests_;
  bool pending_ = false;
};

}  // namespace shatter
