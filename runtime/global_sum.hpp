#pragma once
// Global sums of ExactSum accumulators over MPI ranks (kernels/exact_sum.hpp):
// integer sums of the digits, so the result does not depend on the number of
// ranks or on which rank added which term. Constant size: ~570 bytes per
// accumulator, whatever the model.
#include <mpi.h>

#include <span>

#include "kernels/exact_sum.hpp"

namespace shatter {

/// Every rank's accumulators summed, on every rank (collective over `comm`).
void allreduce(std::span<ExactSum> accumulators, MPI_Comm comm);
/// The same, the result on `root` only (the others' are left as they were).
void reduce_to_root(std::span<ExactSum> accumulators, MPI_Comm comm, int root = 0);

}  // namespace shatter
