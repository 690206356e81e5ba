#include "runtime/restart_check.hpp"

#include <cstdio>
#include <fstream>

#include "kernels/error.hpp"
#include "runtime/output_folder.hpp"

namespace shatter {
namespace {

/// The step of the last complete row of a history.csv or bodies.csv (-1: no
/// rows). A last line without its newline (cut short by a kill) does not
/// count; every other row must begin with a step number.
long last_row_step(const std::filesystem::path& csv, const std::string& where) {
  std::ifstream in(csv, std::ios::binary);
  if (!in) throw InputError(where + ": " + csv.string() + " is missing; it is needed to continue the run's rows");
  std::string line;
  if (!std::getline(in, line) || line.rfind("step,", 0) != 0)
    throw InputError(where + ": " + csv.string() + " has no header row starting with 'step,'");
  long last = -1, number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (in.eof()) break;
    const std::string step = line.substr(0, line.find(','));
    if (step.empty() || step.size() > 18 || step.find_first_not_of("0123456789") != std::string::npos)
      throw InputError(where + ": " + csv.string() + ":" + std::to_string(number) +
                       ": expected a step number in the first column, got '" + step.substr(0, 40) + "'");
    last = std::stol(step);
  }
  return last;
}

}  // namespace

void check_restart(const std::filesystem::path& checkpoint, const SimulationState& state,
                   const CheckpointRun& run, const Scene& scene, const std::filesystem::path& out_dir) {
  const std::string where = "--restart " + checkpoint.string();
  if (state.time >= scene.end_time * (1 - 1e-12)) {
    char buf[256];
    std::snprintf(buf, sizeof buf, ": the checkpoint is at t = %.6g s (step %ld), time.end = %.6g s in ",
                  state.time, state.step, scene.end_time);
    throw InputError(where + buf + scene.file + "; expected a time.end after the checkpoint's time");
  }
  const long every = run.history_every > 0 ? run.history_every : scene.history_every;
  const long needed = state.step / every * every;
  for (const char* name : {"history.csv", "bodies.csv"}) {
    const std::filesystem::path csv = out_dir / name;
    const long last = last_row_step(csv, where);
    if (last < needed)
      throw InputError(where + ": " + csv.string() +
                       (last < 0 ? std::string(" has no rows") : " ends at step " + std::to_string(last)) +
                       " but the checkpoint is at step " + std::to_string(state.step) +
                       " (a row every " + std::to_string(every) + " steps); expected its rows up to step " +
                       std::to_string(needed) + " (the run's own " + name + ")");
  }
  // The rows appended must be of the columns above them (an older shatter's history.csv
  // has no contact_work, for one).
  std::string header, expected;
  std::ifstream history(out_dir / "history.csv", std::ios::binary);
  std::getline(history, header);
  for (const std::string& column : history_columns()) expected += (expected.empty() ? "" : ",") + column;
  if (header != expected)
    throw InputError(where + ": " + (out_dir / "history.csv").string() + " has the columns '" +
                     header.substr(0, 400) + "'; expected '" + expected +
                     "' (written by another version of shatter? the rows continued would not match them)");
  const std::filesystem::path fields = out_dir / ("restart_" + std::to_string(state.step));
  for (const char* name : {"fields.h5", "fields.xdmf"}) refuse_non_file_at(fields / name, true);
}

}  // namespace shatter
