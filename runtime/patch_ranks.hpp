#pragma once
// DCR's exchanges between the ranks' contact patches (DcrRanks, contact/dcr.hpp;
// docs/parallel.md "Contact across ranks"). Each found pair is resolved by the
// rank that found it; the ranks meet only where pairs share nodes:
//   - link: each found pair's nodes go to their volume owners, which order each
//     node's pairs by key (order_links) and answer with the ranks of the pairs
//     before and after (one message to and from each neighbour);
//   - post / receive: the state of a node passes from the rank of one pair on it
//     to the next one's, point to point, as the pairs are resolved;
//   - settle: the final state of each node that moved goes to its volume owner,
//     which sends it on to every rank that reads it.
// Nothing goes to every rank; the one collective is the sum of the pairs found.
#include <mpi.h>

#include <cstdint>
#include <span>
#include <vector>

#include "contact/dcr.hpp"

namespace shatter {

class ContactPatch;
class Decomposition;

class PatchRanks final : public DcrRanks {
 public:
  /// The patch must outlive this. Nodes are the patch's (ContactPatch::num_nodes()); between
  /// ranks they are named by their whole ids (ContactPatch::whole). Collective (duplicates the
  /// communicator).
  PatchRanks(const ContactPatch& patch, const Decomposition& dec);
  ~PatchRanks() override;
  PatchRanks(const PatchRanks&) = delete;
  PatchRanks& operator=(const PatchRanks&) = delete;

  int rank() const override { return rank_; }
  std::uint64_t id(Index node) const override;
  long total(long count) override;
  void link(std::vector<DcrLink>& links) override;
  void post(int r, std::span<const DcrNodeState> states) override;
  std::vector<DcrNodeState> receive(bool wait) override;
  std::vector<Index> settle(std::span<const Index> last, std::span<Vec3> x_new, std::span<Vec3> v) override;

  /// Bytes this rank sent so far (links, posts and settles).
  long bytes() const { return bytes_; }
  /// Node states this rank posted so far (to the rank of a node's next pair).
  long posted() const { return posted_; }
  /// Wall and CPU seconds spent in the calls above so far (the messages' waits included).
  double seconds() const { return seconds_; }
  double cpu_seconds() const { return cpu_seconds_; }

 private:
  using Words = std::vector<std::uint64_t>;
  /// One message to and one from each neighbour (out[k] goes to neighbors()[k]).
  std::vector<Words> exchange(const std::vector<Words>& out, int tag);
  /// The index of rank r among the neighbours.
  size_t neighbor(int r) const;
  void append(Words& w, Index node, const Vec3& x_new, const Vec3& v) const;

  const ContactPatch& patch_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0;
  std::vector<Words> sending_;  ///< posts in flight
  std::vector<MPI_Request> requests_;
  long bytes_ = 0, posted_ = 0;
  double seconds_ = 0, cpu_seconds_ = 0;
};

}  // namespace shatter
