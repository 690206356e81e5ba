#include "runtime/first_failure.hpp"

#include "runtime/comm_place.hpp"

namespace shatter {

std::string first_failure(const std::string& mine, MPI_Comm comm) {
  const CommPlace place = comm_place(comm);
  if (place.size == 1) return mine;
  const int rank = place.rank, ranks = place.size;
  int failed = mine.empty() ? ranks : rank;
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MIN, comm);
  if (failed == ranks) return "";
  int length = rank == failed ? static_cast<int>(mine.size()) : 0;
  MPI_Bcast(&length, 1, MPI_INT, failed, comm);
  std::string message = rank == failed ? mine : std::string(static_cast<size_t>(length), '\0');
  MPI_Bcast(message.data(), length, MPI_CHAR, failed, comm);
  return message;
}

}  // namespace shatter
