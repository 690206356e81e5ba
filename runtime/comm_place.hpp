#pragma once
// Where this process stands in a communicator, for code that also runs in
// the one-rank tests that never initialise MPI.
#include <mpi.h>

namespace shatter {

struct CommPlace {
  int rank = 0;
  int size = 1;
  bool mpi = false;  ///< MPI is initialised (comm may be used)
};

/// This process's rank in `comm` and the ranks of `comm`; rank 0 of 1
/// without MPI initialised.
inline CommPlace comm_place(MPI_Comm comm) {
  CommPlace place;
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) return place;
  place.mpi = true;
  MPI_Comm_rank(comm, &place.rank);
  MPI_Comm_size(comm, &place.size);
  return place;
}

}  // namespace shatter
