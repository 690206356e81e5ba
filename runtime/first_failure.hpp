#pragma once
// One outcome for a step that each rank did on its own (a file written by
// parts, a checkpoint read by parts): a failure of any rank becomes every
// rank's, with one message, so that no rank goes on into a collective the
// others have left (docs/errors.md, "On several ranks").
#include <mpi.h>

#include <string>

namespace shatter {

/// `mine`: this rank's error message, empty when it succeeded. Returns, on
/// every rank of `comm`, the message of the smallest rank that failed, or ""
/// when none did (collective: one reduction, and a broadcast on failure).
/// Without MPI initialised, `mine`.
std::string first_failure(const std::string& mine, MPI_Comm comm);

}  // namespace shatter
