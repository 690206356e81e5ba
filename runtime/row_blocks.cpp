#include "runtime/row_blocks.hpp"

#include <algorithm>
#include <cstring>

#include "kernels/error.hpp"

namespace shatter {

RowBlock row_block(Index total, int rank, int ranks) {
  const auto edge = [&](int r) { return static_cast<Index>(static_cast<long long>(total) * r / ranks); };
  return {edge(rank), edge(rank + 1) - edge(rank)};
}

std::vector<std::byte> to_row_blocks(std::span<const Index> rows, std::span<const std::byte> values, int row_bytes,
                                     Index total, MPI_Comm comm) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  SHATTER_REQUIRE(values.size() == rows.size() * row_bytes,
                  "to_row_blocks: " << values.size() << " bytes for " << rows.size() << " rows of " << row_bytes);
  if (ranks == 1) return {values.begin(), values.end()};
  // The rows are ascending and the blocks contiguous: the rows for rank d
  // are one run of `rows`.
  std::vector<int> send_rows(ranks, 0), recv_rows(ranks, 0);
  for (int d = 0, k = 0; d < ranks; ++d) {
    const RowBlock b = row_block(total, d, ranks);
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
  const RowBlock mine = row_block(total, rank, ranks);
  SHATTER_REQUIRE(received == mine.count, "to_row_blocks: rank " << rank << " received " << received
                                                                  << " rows for its block of " << mine.count);
  static_assert(sizeof(Index) == sizeof(int));
  std::vector<Index> ids(received);
  MPI_Alltoallv(rows.data(), send_rows.data(), send_at.data(), MPI_INT, ids.data(), recv_rows.data(),
                recv_at.data(), MPI_INT, comm);
  // The values travel as rows (counts in rows, not bytes: no int overflow below 2^31 rows).
  MPI_Datatype row = MPI_DATATYPE_NULL;
  MPI_Type_contiguous(row_bytes, MPI_BYTE, &row);
  MPI_Type_commit(&row);
  std::vector<std::byte> in(static_cast<size_t>(received) * row_bytes), out(in.size());
  MPI_Alltoallv(values.data(), send_rows.data(), send_at.data(), row, in.data(), recv_rows.data(), recv_at.data(),
                row, comm);
  MPI_Type_free(&row);
  for (int i = 0; i < received; ++i) {
    const Index r = ids[i] - mine.first;
    SHATTER_REQUIRE(r >= 0 && r < mine.count, "to_row_blocks: row " << ids[i] << " is not in rank " << rank
                                                                     << "'s block");
    std::memcpy(out.data() + static_cast<size_t>(r) * row_bytes, in.data() + static_cast<size_t>(i) * row_bytes,
                row_bytes);
  }
  return out;
}

std::vector<double> to_row_blocks(std::span<const Index> rows, std::span<const double> values, int width,
                                  Index total, MPI_Comm comm) {
  const std::vector<std::byte> block =
      to_row_blocks(rows, std::as_bytes(values), static_cast<int>(width * sizeof(double)), total, comm);
  std::vector<double> out(block.size() / sizeof(double));
  std::memcpy(out.data(), block.data(), block.size());
  return out;
}

}  // namespace shatter
