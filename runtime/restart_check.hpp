#pragma once
// What a restart must find before it touches anything (docs/checkpoint.md,
// "Restarting"): a restart continues the run exactly or not at all. Checked
// after the checkpoint is read and before Simulation::run truncates the
// outputs, so a refused restart leaves every file as it was.
#include <filesystem>

#include "runtime/checkpoint.hpp"
#include "runtime/scene.hpp"
#include "runtime/simulation.hpp"

namespace shatter {

/// Throws InputError naming `checkpoint` and what differs when
///  - scene.end_time is not after the checkpoint's time (nothing to run: the
///    restart would only cut the rows after the checkpoint);
///  - `out_dir`/history.csv or bodies.csv is missing, has a row whose step is
///    not a number (named by line), or ends before the last row the run wrote
///    at or before the checkpoint's step (a row every `run.history_every`
///    steps, the scene's when the checkpoint does not record it): the rows in
///    between are lost and the continued file would have a gap; or when
///    history.csv's header is not history_columns() (an older shatter's);
///  - `out_dir`/restart_<step>/fields.h5 or fields.xdmf is a folder or a device.
void check_restart(const std::filesystem::path& checkpoint, const SimulationState& state,
                   const CheckpointRun& run, const Scene& scene, const std::filesystem::path& out_dir);

}  // namespace shatter
