#pragma once
// Recursive coordinate bisection of the contact surface over the MPI ranks
// (Zoltan, LB_METHOD RCB; docs/parallel.md "Contact across ranks"): which
// rank searches and detects the pairs of each surface primitive. Each rank
// hands Zoltan the primitives it holds now; the results of the contact stage
// do not depend on the partition: it decides the load balance, never the bits.
#include <mpi.h>

#include <array>
#include <span>
#include <vector>

#include "kernels/types.hpp"

struct Zoltan_Struct;

namespace shatter {

/// The numbering of `parts` parts onto as many ranks that keeps the most objects at home:
/// overlap lists (part, home rank, objects) entries, summed over the ranks; entries are
/// taken by decreasing count (ties by part, then rank) while both are free, and the parts
/// left go to the ranks left in ascending order. Returns the rank of each part. The same
/// on every rank given the same entries, in any order.
std::vector<int> align_parts(int parts, std::vector<std::array<long, 3>> overlap);

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
  /// homes: per object, the rank whose volume part holds most of its nodes. RCB's parts are
  /// numbered so that as many objects as possible land on their home (align_parts): the part
  /// numbers are Zoltan's choice, and a part handed to the wrong rank would make that rank
  /// fetch the states of nearly every node it detects for.
  std::vector<int> partition(std::span<const Index> names, std::span<const Vec3> points,
                             std::span<const float> weights, std::span<const int> homes);

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
