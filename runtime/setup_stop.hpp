#pragma once
// SIGINT and SIGTERM before the time loop (docs/errors.md, "Stopped"):
// during MPI start-up, scene checks and meshing there is no state worth a
// checkpoint and nothing written but the empty output folder, so a stop
// ends the process at once with one message and exit status
// kSetupStopStatus. The time loop then installs install_stop_handlers()
// (checkpoint.hpp), which finishes the step under way and checkpoints it.
namespace shatter {

/// The exit status of a run stopped during set-up (the status of a run
/// stopped by a signal in the time loop, too).
inline constexpr int kSetupStopStatus = 1;

/// Installs the set-up handlers: print "error: stopped by signal N during
/// set-up (before step 0): nothing to continue from; run it again" (only on
/// rank 0, or on every process while the rank is not known), remove the disk
/// reserve (disk_reserve.hpp), and _exit(kSetupStopStatus). Call before
/// MPI_Init and again after it (MPI may install its own).
void install_setup_stop_handlers();

/// Tells the handlers this process's rank: only rank 0 prints.
void set_setup_stop_rank(int rank);

/// After the process's failure was reported: SIGINT and SIGTERM are ignored
/// while it finishes (mpirun sends SIGTERM to the ranks still finishing once
/// one rank has exited non-zero; the set-up handler then printed a second,
/// wrong message).
void ignore_stop_signals();

}  // namespace shatter
