#pragma once
// How a failed run ends on several ranks (docs/errors.md, "On several
// ranks"). A failure found from data every rank shares (a reduction, the
// scene) is thrown by every rank at the same point; an exception raised on
// one rank only leaves the others waiting in their next collective. The
// ranks that fail therefore agree, on a communicator of their own, whether
// every rank failed:
//   - every rank joined within the patience: the failure is collective; the
//     run ends cleanly (the last good state is checkpointed, rank 0 prints the
//     one message, MPI_Finalize, exit status 1 or 2);
//   - not every rank joined: the failure is this rank's alone; it prints its
//     message and the CLI ends every rank with MPI_Abort (the others cannot
//     be reached: they wait in a collective).
#include <mpi.h>

#include <optional>
#include <string>

namespace shatter {

/// Seconds the failed ranks wait for the others. Ranks that fail together
/// leave the same reduction within microseconds; this bounds how long a
/// failure of one rank alone takes to end the run.
inline constexpr double kFailurePatience = 5.0;

struct FailureAgreement {
  bool all_ranks = true;  ///< every rank failed: a collective failure
  int status = 0;         ///< the largest exit status among the ranks that joined
};

/// A duplicate of a communicator that carries failure agreements only, so that
/// they match no other collective. Made by every rank at once (collective),
/// freed before MPI_Finalize.
class FailureChannel {
 public:
  explicit FailureChannel(MPI_Comm comm);
  ~FailureChannel();
  FailureChannel(const FailureChannel&) = delete;
  FailureChannel& operator=(const FailureChannel&) = delete;

  /// Called by a rank that failed with exit `status` (1 or 2): waits up to
  /// `patience` seconds for every rank to call it too. A run fails once: the
  /// first agreement is kept and returned by every later call.
  FailureAgreement agree(int status, double patience = kFailurePatience);

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
  int mine_ = 0, largest_ = 0;  ///< the reduction's buffers: they outlive a request left pending
  std::optional<FailureAgreement> agreed_;
};

/// The one message of a failure and the exit status `status` (1 or 2) of a
/// run on the ranks of MPI_COMM_WORLD: when every rank failed, rank 0 prints
/// "error: <message>" and the status is returned on every rank; a rank that
/// failed alone prints its message with a note and ends every rank with
/// MPI_Abort.
int report_failure(FailureChannel& failures, int status, const std::string& message);

}  // namespace shatter
