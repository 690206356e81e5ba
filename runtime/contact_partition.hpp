#pragma once
// Recursive coordinate bisection of the contact surface over the MPI ranks
// (Zoltan, LB_METHOD RCB; docs/parallel.md "Contact across ranks"): which
// rank resolves the pairs of each surface primitive. The partition is a
// function of the primitives' points and weights only (every rank passes the
// same ones and gets the same parts), and the results of the contact stage do
// not depend on it: it decides the load balance, never the bits.
#include <mpi.h>

#include <span>
#include <vector>

#include "kernels/types.hpp"

struct Zoltan_Struct;

namespace shatter {

class ContactPartition {
 public:
  /// A partitioner over the ranks of comm (collective; MPI initialised).
  explicit ContactPartition(MPI_Comm comm);
  ~ContactPartition();
  ContactPartition(const ContactPartition&) = delete;
  ContactPartition& operator=(const ContactPartition&) = delete;

  /// The part (rank) of each of the points, weighted by weights (>= 0), the same
  /// array on every rank (collective: every rank passes the same points and weights).
  /// Each rank hands Zoltan the points [k n / R, (k+1) n / R); the parts come back
  /// through one MPI_Allgatherv.
  std::vector<int> partition(std::span<const Vec3> points, std::span<const float> weights);

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  Zoltan_Struct* zz_ = nullptr;
  // The slice handed to Zoltan's callbacks during partition().
  std::span<const Vec3> points_;
  std::span<const float> weights_;
  Index first_ = 0, count_ = 0;
};

}  // namespace shatter
