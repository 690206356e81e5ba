#include "runtime/failure.hpp"

#include <chrono>
#include <cstdio>
#include <thread>

namespace shatter {

FailureChannel::FailureChannel(MPI_Comm comm) {
  MPI_Comm_dup(comm, &comm_);
}

FailureChannel::~FailureChannel() {
  // After an agreement that not every rank joined, the request is still
  // pending and the process is about to be aborted: leave the communicator.
  if (!agreed_ || agreed_->all_ranks) MPI_Comm_free(&comm_);
}

FailureAgreement FailureChannel::agree(int status, double patience) {
  if (agreed_) return *agreed_;
  int size = 1;
  MPI_Comm_size(comm_, &size);
  FailureAgreement a{true, status};
  if (size > 1) {
    mine_ = status;
    MPI_Request request;
    MPI_Iallreduce(&mine_, &largest_, 1, MPI_INT, MPI_MAX, comm_, &request);
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(patience);
    int done = 0;
    for (;;) {
      MPI_Test(&request, &done, MPI_STATUS_IGNORE);
      if (done || std::chrono::steady_clock::now() > deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    a.all_ranks = done != 0;
    if (done) a.status = largest_;
  }
  agreed_ = a;
  return a;
}

int report_failure(FailureChannel& failures, int status, const std::string& message) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const FailureAgreement a = failures.agree(status);
  if (!a.all_ranks) {
    std::fprintf(stderr,
                 "error: %s\n(rank %d of %d failed alone while the others waited in a collective: "
                 "every rank is ended with MPI_Abort; no checkpoint of this failure, an earlier "
                 "one stays)\n",
                 message.c_str(), rank, ranks);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, status);
  }
  if (rank == 0) std::fprintf(stderr, "error: %s\n", message.c_str());
  return a.status;
}

}  // namespace shatter
