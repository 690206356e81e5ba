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

  /// The objects this rank owns after a new partition, ascending (collective). Each rank
  /// passes the objects it holds now (ids in [0, total), each id on exactly one rank) with
  /// their points and two weights each (>= 0, object-major), balanced together (Zoltan's
  /// multi-criteria RCB); it keeps those Zoltan does not export and gains those Zoltan
  /// imports (its migration lists: no list of every object's part goes to every rank).
  std::vector<Index> partition(std::span<const Index> ids, std::span<const Vec3> points,
                               std::span<const float> weights, Index total);

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  Zoltan_Struct* zz_ = nullptr;
  // The slice handed to Zoltan's callbacks during partition().
  std::span<const Index> ids_;
  std::span<const Vec3> points_;
  std::span<const float> weights_;
};

}  // namespace shatter
