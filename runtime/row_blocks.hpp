#pragma once
// Rows of a global array moved from their owners to contiguous blocks, one
// per rank, for collective output in global order (fields.h5 and
// checkpoint.h5: each rank writes one contiguous hyperslab, and the file is
// the same for any decomposition). A hand-made two-phase write: one
// MPI_Alltoallv of the rows, O(rows a rank holds) per rank.
#include <mpi.h>

#include <cstddef>
#include <span>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

/// Rank `rank`'s block of a global array of `total` rows among `ranks`:
/// rows [first, first + count), first = floor(total rank / ranks).
struct RowBlock {
  Index first = 0, count = 0;
};
RowBlock row_block(Index total, int rank, int ranks);

/// This rank's rows `rows` (global row ids, ascending; every row of [0,
/// total) held by exactly one rank of `comm`) with `row_bytes` bytes each in
/// `values` [rows.size() x row_bytes], sent to the ranks whose blocks hold
/// them (collective). Returns this rank's block, [block.count x row_bytes],
/// in row order.
std::vector<std::byte> to_row_blocks(std::span<const Index> rows, std::span<const std::byte> values, int row_bytes,
                                     Index total, MPI_Comm comm);

/// As above, for rows of `width` doubles.
std::vector<double> to_row_blocks(std::span<const Index> rows, std::span<const double> values, int width,
                                  Index total, MPI_Comm comm);

}  // namespace shatter
