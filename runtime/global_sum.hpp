#pragma once
// Global reductions over MPI ranks, one message each, through user-defined
// operations:
// - sums of ExactSum accumulators (kernels/exact_sum.hpp): integer sums of the
//   digits, so the result does not depend on the number of ranks or on which
//   rank added which term; ~570 bytes per accumulator, whatever the model. The
//   specials (infinities, NaN) and any maxima travel with the digits.
// - minima with a least (key, index) pair (the stable step and the worst element).
#include <mpi.h>

#include <cstddef>
#include <span>
#include <utility>

#include "kernels/exact_sum.hpp"

namespace shatter {

/// Every rank's accumulators summed, and every rank's `most` replaced by the
/// element-wise maxima over the ranks, on every rank (collective over `comm`).
void allreduce(std::span<ExactSum> accumulators, MPI_Comm comm, std::span<long> most = {});
/// Bytes of one allreduce's message: `accumulators` sums and `maxima` maxima.
std::size_t allreduce_bytes(std::size_t accumulators, std::size_t maxima = 0);
/// The sums only, the result on `root` only (the others' are left as they were).
void reduce_to_root(std::span<ExactSum> accumulators, MPI_Comm comm, int root = 0);
/// Every rank's `values` replaced by their element-wise minima over the ranks (a NaN
/// on any rank wins on every rank), and `least` by the least (key, index) pair (the
/// smaller key, then the smaller index: MPI's MINLOC order; |index| < 2^53).
void allreduce_min(std::span<double> values, std::pair<double, long>& least, MPI_Comm comm);

}  // namespace shatter
