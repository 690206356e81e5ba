#pragma once
// All-gather of per-rank lists of any length: one MPI_Allgather of the counts,
// one MPI_Allgatherv of the items (Decomposition::allgather, the contact
// partition's part overlaps).
#include <mpi.h>

#include <span>
#include <vector>

namespace shatter {

/// Every rank's `mine`, concatenated in rank order, on every rank of `comm`. `type`: the MPI
/// type of T. Collective.
template <class T>
std::vector<T> allgather_list(std::span<const T> mine, MPI_Datatype type, MPI_Comm comm) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  std::vector<int> counts(ranks), displs(ranks, 0);
  const int n = static_cast<int>(mine.size());
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<T> all(displs[ranks - 1] + counts[ranks - 1]);
  MPI_Allgatherv(mine.data(), n, type, all.data(), counts.data(), displs.data(), type, comm);
  return all;
}

}  // namespace shatter
