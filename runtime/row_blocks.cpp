#include "runtime/row_blocks.hpp"

#include <algorithm>

#include "kernels/error.hpp"

namespace shatter {

RowBlock row_block(Index total, int rank, int ranks) {
  const auto edge = [&](int r) { return static_cast<Index>(static_cast<long long>(total) * r / ranks); };
  return {edge(rank), edge(rank + 1) - edge(rank)};
}

namespace {

/// The rows to the ranks whose blocks hold them, block(d) being rank d's.
template <class Block>
std::vector<double> to_blocks(std::span<const Index> rows, std::span<const double> values, int width,
                              MPI_Comm comm, Block block) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  SHATTER_REQUIRE(values.size() == rows.size() * width,
                  "to_row_blocks: " << values.size() << " values for " << rows.size() << " rows of " << width);
  // The rows are ascending and the blocks contiguous: the rows for rank d
  // are one run of `rows`.
  std::vector<int> send_rows(ranks, 0), recv_rows(ranks, 0);
  for (int d = 0, k = 0; d < ranks; ++d) {
    const RowBlock b = block(d);
    const int begin = k;
    while (k < static_cast<int>(rows.size()) && rows[k] < b.first + b.count) ++k;
    send_rows[d] = k - begin;
  }
  MPI_Alltoall(send_rows.data(), 1, MPI_INT, recv_rows.data(), 1, MPI_INT, comm);
  std::vector<int> send_at(ranks, 0), recv_at(ranks, 0);
  for (int d = 1; d < ranks; ++d) {
    send_at[d] = send_at[d - 1] + send_rows[d - 1];
    recv_at[d] = recv_at[d - 1] + recv_rows[d - 1];
  }
  const int received = recv_at[ranks - 1] + recv_rows[ranks - 1];
  const RowBlock mine = block(rank);
  SHATTER_REQUIRE(received == mine.count, "to_row_blocks: rank " << rank << " received " << received
                                                                  << " rows for its block of " << mine.count);
  static_assert(sizeof(Index) == sizeof(int));
  std::vector<Index> ids(received);
  MPI_Alltoallv(rows.data(), send_rows.data(), send_at.data(), MPI_INT, ids.data(), recv_rows.data(),
                recv_at.data(), MPI_INT, comm);
  for (int d = 0; d < ranks; ++d) {
    send_rows[d] *= width, send_at[d] *= width;
    recv_rows[d] *= width, recv_at[d] *= width;
  }
  std::vector<double> in(static_cast<size_t>(received) * width), out(in.size());
  MPI_Alltoallv(values.data(), send_rows.data(), send_at.data(), MPI_DOUBLE, in.data(), recv_rows.data(),
                recv_at.data(), MPI_DOUBLE, comm);
  for (int i = 0; i < received; ++i) {
    const Index r = ids[i] - mine.first;
    SHATTER_REQUIRE(r >= 0 && r < mine.count, "to_row_blocks: row " << ids[i] << " is not in rank " << rank
                                                                     << "'s block");
    std::copy_n(in.begin() + static_cast<size_t>(i) * width, width, out.begin() + static_cast<size_t>(r) * width);
  }
  return out;
}

}  // namespace

std::vector<double> to_row_blocks(std::span<const Index> rows, std::span<const double> values, int width,
                                  Index total, MPI_Comm comm) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  if (ranks == 1) return {values.begin(), values.end()};
  return to_blocks(rows, values, width, comm, [&](int d) { return row_block(total, d, ranks); });
}

std::vector<double> to_root(std::span<const Index> rows, std::span<const double> values, int width, Index total,
                            MPI_Comm comm) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  if (ranks == 1) return {values.begin(), values.end()};
  return to_blocks(rows, values, width, comm, [&](int d) { return d == 0 ? RowBlock{0, total} : RowBlock{total, 0}; });
}

}  // namespace shatter
