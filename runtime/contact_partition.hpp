#pragma once
// Recursive coordinate bisection of the contact surface over the MPI ranks
// (Zoltan, LB_METHOD RCB; docs/parallel.md "Contact across ranks"): which
// rank searches and detects the pairs of each surface primitive. Each rank
// hands Zoltan the primitives it holds now; the results of the contact stage
// do not depend on the partition: it decides the load balance, never the bits.
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

  /// Words in an object's name.
  static constexpr int kNameWords = 4;
  /// Where each object this rank holds goes in a new partition (collective): per object, its
  /// new rank (this one when it stays). Each rank passes the objects it holds now, named by
  /// kNameWords numbers >= 0 each (distinct over the ranks), with their points and two
  /// weights each (>= 0, object-major), balanced together (Zoltan's multi-criteria RCB).
  /// Only Zoltan's export lists are read: no list of every object's part goes to every rank.
  std::vector<int> partition(std::span<const Index> names, std::span<const Vec3> points,
                             std::span<const float> weights);

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  Zoltan_Struct* zz_ = nullptr;
  // The slice handed to Zoltan's callbacks during partition().
  std::span<const Index> names_;
  std::span<const Vec3> points_;
  std::span<const float> weights_;
};

}  // namespace shatter
