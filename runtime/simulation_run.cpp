// Simulation::run: the time loop with its outputs, progress, checkpoints
// (periodic, on SIGINT/SIGTERM, of the last good state when a step fails)
// and the failure protocol across ranks (runtime/failure.hpp).
#include <array>
#include <chrono>
#include <optional>

#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/contact_stage.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/failure.hpp"
#include "runtime/field_output.hpp"
#include "runtime/report.hpp"
#include "runtime/simulation.hpp"
#include "runtime/timed.hpp"

namespace shatter {

long Simulation::run() {
  const Scene& scene = model_.scene;
  const auto wall0 = std::chrono::steady_clock::now();
  const bool root = dec_->rank() == 0;
  long field_every = scene.output_every;
  if (field_every < 0) {
    // Default: about 20 frames over the run.
    const double est_steps = scene.end_time / (scene.fixed_dt ? *scene.fixed_dt : scene.safety * stable_dt0_);
    field_every = std::max(1L, static_cast<long>(std::ceil(est_steps / 20)));
  }
  if (!opt_.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt_.out_dir, ec);
    if (ec) throw Error("cannot create the output folder " + opt_.out_dir.string() + ": " + ec.message());
    // A restart keeps the rows up to its step and appends the rest.
    if (restored_ && root)
      for (const char* csv : {"history.csv", "bodies.csv"}) truncate_rows_after(opt_.out_dir / csv, step_);
    if (root) {
    history_ = std::make_unique<CsvWriter>(opt_.out_dir / "history.csv", history_columns(), restored_);
    bodies_ = std::make_unique<CsvWriter>(
        opt_.out_dir / "bodies.csv",
        std::vector<std::string>{"step", "time", "body", "mass", "cx", "cy", "cz", "vx", "vy", "vz"}, restored_);
    }
    // A restart's frames go to OUTDIR/restart_<step>/; fields.h5 keeps the earlier ones.
    const std::filesystem::path field_dir =
        restored_ ? opt_.out_dir / ("restart_" + std::to_string(step_)) : opt_.out_dir;
    if (field_every > 0)
      fields_ = std::make_unique<FieldWriter>(field_dir, dec_->distributed() ? dec_->comm() : MPI_COMM_WORLD);
  }
  Progress progress(scene.end_time, opt_.quiet || !root);
  if (!restored_) write_outputs(field_every > 0);
  // Checkpoints (checkpoint.hpp): periodic, on SIGINT/SIGTERM, and of the
  // last good state when a step fails. On
  // several ranks, every rank writes its own rows (save_checkpoint).
  const std::filesystem::path checkpoint = opt_.out_dir / "checkpoint.h5";
  const bool checkpoints = !opt_.out_dir.empty();
  SimulationState good;  // the state before the current step
  auto last_checkpoint = std::chrono::steady_clock::now();
  const double tiny = 1e-12 * scene.end_time;
  while (time_ < scene.end_time - tiny) {
    if (checkpoints) save_state(good);
    try {
      step();
    } catch (const std::exception& e) {
      if (!checkpoints) throw;
      progress.finish();
      // On several ranks the state is saved only when every rank failed in
      // this step; a failure of this rank alone leaves the others in a
      // collective, and the CLI aborts them all.
      if (dec_->distributed() && opt_.failures && !opt_.failures->agree(1).all_ranks) throw;
      try {
        save_checkpoint(checkpoint, good, e.what());
      } catch (const Error& w) {
        throw Error(std::string(e.what()) + "\n" + w.what());
      }
      const std::string saved =
          std::string(e.what()) + "\nthe last good state (step " + std::to_string(good.step) + ") is in " +
          checkpoint.string();
      // A smaller step cures an inverted element, not a cause in the scene's physics.
      if (dynamic_cast<const PhysicsError*>(&e))
        throw Error(saved + ": a restart would continue the same physics (it refuses changed physics keys), so "
                            "correct the scene (the likely cause above) and run it again");
      throw Error(saved + ": continue from it with --restart " + checkpoint.string() +
                  " and a smaller --set time.safety=...");
    }
    const bool last = time_ >= scene.end_time - tiny;
    const bool field_row = field_every > 0 && (step_ % field_every == 0 || last);
    if (step_ % scene.history_every == 0 || last || field_row) write_outputs(field_row);
    progress.update(step_, time_, dt_, energy_error(), last);
    const int stop = last ? 0 : stop_;
    const auto now = std::chrono::steady_clock::now();
    const std::optional<CheckpointSpec>& every = scene.checkpoint;
    // Rank 0's clock decides for every rank.
    const bool due = every && ((every->every_steps > 0 && step_ % every->every_steps == 0) ||
                               dec_->max(root && every->every_seconds > 0 &&
                                         now - last_checkpoint >= std::chrono::duration<double>(every->every_seconds)));
    if (checkpoints && (due || stop) && !last) {
      save_state(good);
      timed(checkpoint_seconds_, [&] { save_checkpoint(checkpoint, good); });
      last_checkpoint = now;
    }
    if (stop) {
      progress.finish();
      const std::string where = checkpoints ? "; continue with --restart " + checkpoint.string()
                                            : "; no checkpoint written (no output folder)";
      throw Error("stopped by signal " + std::to_string(stop) + " after step " + std::to_string(step_) + where);
    }
  }
  progress.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  fields_.reset();
  if (!opt_.out_dir.empty()) {
    FractureSummary fracture;
    if (fracture_) {
      double cpu[2] = {fracture_->check_cpu_seconds(), insert_cpu_seconds_};
      dec_->max(cpu);
      const long owned = fracture_->owned_count();
      fracture = {write_fragments(), fracture_->across_ranks(), cpu[0], cpu[1], -dec_->max(-owned), dec_->max(owned)};
    }
    const DecompositionStats stats = dec_->stats();
    const ContactBalance pairs = contact_ ? contact_->balance() : ContactBalance{};
    const std::pair<std::vector<long>, long> memory{dec_->gather(peak_memory_bytes()), dec_->max(loop_bytes())};
    // Shell elements per rank: owned (smallest, largest) and computed (owned + ghost, largest).
    std::array<long, 3> shell{};
    if (shells_) {
      const long owned = shells_->owned_elements();
      shell = {-dec_->max(-owned), dec_->max(owned), dec_->max(static_cast<long>(shells_->elements()))};
    }
    if (root) write_summary(wall, stats, pairs, fracture, memory, shell);
  }
  return step_;
}

}  // namespace shatter
