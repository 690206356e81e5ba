#pragma once
// Sparse all-to-all of per-rank lists: one MPI_Alltoall of the counts, one
// MPI_Alltoallv of the items (Decomposition::alltoall, checkpoints' facet
// rows sorted by ranges).
#include <mpi.h>

#include <vector>

namespace shatter {

/// to[r] goes to rank r of `comm` (to.size() == its size); returns what each
/// rank sent here, by rank. `type`: the MPI type of T. Collective.
template <class T>
std::vector<std::vector<T>> alltoall_lists(const std::vector<std::vector<T>>& to, MPI_Datatype type, MPI_Comm comm) {
  const int ranks = static_cast<int>(to.size());
  std::vector<int> send_counts(ranks), recv_counts(ranks), send_at(ranks, 0), recv_at(ranks, 0);
  for (int r = 0; r < ranks; ++r) send_counts[r] = static_cast<int>(to[r].size());
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r) {
    send_at[r] = send_at[r - 1] + send_counts[r - 1];
    recv_at[r] = recv_at[r - 1] + recv_counts[r - 1];
  }
  std::vector<T> out, in(recv_at[ranks - 1] + recv_counts[ranks - 1]);
  out.reserve(send_at[ranks - 1] + send_counts[ranks - 1]);
  for (const auto& list : to) out.insert(out.end(), list.begin(), list.end());
  MPI_Alltoallv(out.data(), send_counts.data(), send_at.data(), type, in.data(), recv_counts.data(), recv_at.data(),
                type, comm);
  std::vector<std::vector<T>> from(ranks);
  for (int r = 0; r < ranks; ++r) from[r].assign(in.begin() + recv_at[r], in.begin() + recv_at[r] + recv_counts[r]);
  return from;
}

}  // namespace shatter
