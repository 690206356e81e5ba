#pragma once
// Global sums of ExactSum accumulators over MPI ranks (kernels/exact_sum.hpp):
// integer sums of the digits, so the result does not depend on the number of
// ranks or on which rank added which term. Constant size: ~570 bytes per
// accumulator, whatever the model. One message per reduction: the digits, the
// specials (infinities, NaN) and any maxima travel together, through one
// user-defined operation.
#include <mpi.h>

#include <cstddef>
#include <span>

#include "kernels/exact_sum.hpp"

namespace shatter {

/// Every rank's accumulators summed, and every rank's `most` replaced by the
/// element-wise maxima over the ranks, on every rank (collective over `comm`).
void allreduce(std::span<ExactSum> accumulators, MPI_Comm comm, std::span<long> most = {});
/// Bytes of one allreduce's message: `accumulators` sums and `maxima` maxima.
std::size_t allreduce_bytes(std::size_t accumulators, std::size_t maxima = 0);
/// The sums only, the result on `root` only (the others' are left as they were).
void reduce_to_root(std::span<ExactSum> accumulators, MPI_Comm comm, int root = 0);

}  // namespace shatter
