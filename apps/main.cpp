// shatter — command line (SCENE.md "Command line"):
//   shatter run SCENE.yaml [--out DIR] [--threads T] [--set key.path=value ...]
//             [--deterministic] [--restart CHECKPOINT.h5] [--quiet] [--max-elements N]
//   shatter check SCENE.yaml [--set ...] [--max-elements N]
//   shatter partition SCENE.yaml --ranks R [--out DIR] [--set ...] [--max-elements N]
//             (the parts for R ranks, one file each, for `run --parts DIR`)
//   shatter plot OUTDIR        (PNGs of a run's history into OUTDIR/plots/)
// Exit status: 0 success, 2 bad input, 1 failure during the run.
#include <mpi.h>
#include <tbb/global_control.h>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <thread>

#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/failure.hpp"
#include "runtime/disk_reserve.hpp"
#include "runtime/model.hpp"
#include "runtime/output_folder.hpp"
#include "runtime/part_files.hpp"
#include "runtime/report.hpp"
#include "runtime/restart_check.hpp"
#include "runtime/scene.hpp"
#include "runtime/setup_stop.hpp"
#include "runtime/simulation.hpp"

using namespace shatter;

namespace {

/// The model summary of `shatter check`, printed by rank 0; on several ranks
/// each holds its part, and the counts are summed over the owned nodes and
/// elements (collective).
void print_check(const Model& model, const Simulation& sim) {
  const Scene& s = model.scene;
  const Mesh& mesh = model.mesh;
  const Decomposition& d = sim.decomposition();
  const size_t nb = s.bodies.size();
  std::vector<long> count(2 * nb, 0);  // per body: nodes, elements
  for (Index i : d.owned_nodes()) ++count[2 * mesh.node_body[i]];
  for (Index e : d.owned_element_ids()) ++count[2 * mesh.elem_body[e] + 1];
  // A shell body's elements: its control triangles, which every rank holds (rank 0 counts them).
  long shell_triangles = 0;
  for (const ShellBody& sb : model.shells) {
    if (d.rank() == 0) count[2 * sb.body + 1] += sb.mesh.num_triangles();
    shell_triangles += sb.mesh.num_triangles();
  }
  count = d.sum(count);
  MeshScaledJacobian worst;
  if (mesh.order == 2) {
    worst = min_scaled_jacobian(mesh);
    double least[2] = {worst.value, static_cast<double>(worst.element)};
    d.broadcast(least, d.rank_of_min(least[0]));
    worst = {least[0], static_cast<GlobalId>(least[1])};
  }
  const double dt = s.fixed_dt ? *s.fixed_dt : sim.stable_dt();
  // The model's arrays plus the solver's five nodal vectors and work arrays, the largest rank's.
  const long memory = d.max(static_cast<long>(model_bytes(model) + double(mesh.num_nodes()) * (5 * sizeof(Vec3) + sizeof(double))));
  if (d.rank() != 0) return;
  std::printf("scene %s (%s)\n", s.name.c_str(), s.file.c_str());
  std::printf("%-12s %-12s %10s %10s %14s %14s\n", "body", "material", "nodes", "elements", "mass [kg]", "volume [m^3]");
  for (size_t b = 0; b < nb; ++b)
    std::printf("%-12s %-12s %10ld %10ld %14.6e %14.6e\n", s.bodies[b].name.c_str(),
                s.materials[s.bodies[b].material].name.c_str(), count[2 * b], count[2 * b + 1], model.body_mass[b],
                model.body_volume[b]);
  double mass = 0;
  for (double m : model.body_mass) mass += m;
  std::printf("total: %d nodes, %d elements (TET%d)", model.whole_nodes(), model.whole_elements(), mesh.nodes_per_element());
  if (shell_triangles > 0) std::printf(", %ld shell triangles", shell_triangles);
  std::printf(", mass %.6e kg\n", mass);
  if (mesh.order == 2)
    std::printf("TET10 minimum scaled Jacobian %.4f (element %lld; det J / (6 x volume) at the quadrature points, 1 "
                "for straight-sided elements, valid above 0)\n",
                worst.value, static_cast<long long>(worst.element));
  std::printf("stable dt %.4e s (safety %.2f)%s; dt used %.4e s\n", sim.stable_dt() / s.safety, s.safety,
              s.fixed_dt && *s.fixed_dt > sim.stable_dt() ? "  WARNING: time.dt is above it" : "", dt);
  const double steps = std::ceil(s.end_time / dt);
  std::printf("end time %.4e s: about %.0f steps\n", s.end_time, steps);
  std::printf("contact: %s; fracture: %s; gravity: [%g, %g, %g]; boundary conditions: %zu\n",
              s.contact ? "on" : "off", s.fracture_enabled() ? "on" : "off", s.gravity.x(), s.gravity.y(),
              s.gravity.z(), s.boundary_conditions.size());
  std::printf("memory: about %.1f MB%s\n", memory / 1e6, d.distributed() ? " on the largest rank" : "");
}

/// `shatter partition`: the whole model, built here, cut into `ranks` part files
/// in `out_dir` (default parts/<name>); prints what it wrote. On one process.
int write_parts(const Scene& scene, int ranks, const std::string& out_dir, double max_elements, int processes) {
  if (processes > 1)
    throw InputError("shatter partition runs on one process (it was started on " + std::to_string(processes) +
                     "); expected `shatter partition SCENE --ranks R` without mpirun");
  const std::filesystem::path dir = out_dir.empty() ? std::filesystem::path("parts") / scene.name : std::filesystem::path(out_dir);
  const Model whole = build_model(scene, MPI_COMM_SELF, max_elements);
  const std::vector<std::uintmax_t> sizes = write_part_files(whole, ranks, dir);
  std::uintmax_t total = 0;
  for (const std::uintmax_t b : sizes) total += b;
  std::printf("wrote the parts of scene %s (%d nodes, %d elements; meshed in %.1f s) for %d ranks to %s: %.1f MB, "
              "the largest part %.1f MB\nrun them with: mpirun -np %d shatter run %s --parts %s\n",
              scene.name.c_str(), whole.whole_nodes(), whole.whole_elements(), whole.mesh_seconds, ranks,
              dir.c_str(), total / 1e6, *std::max_element(sizes.begin(), sizes.end()) / 1e6, ranks,
              scene.file.c_str(), dir.c_str());
  return 0;
}

/// Run scripts/plot.py of the source tree (SHATTER_SOURCE_DIR) with the Python
/// that has matplotlib (SHATTER_PYTHON) on a run's output folder; returns the
/// script's exit status (2: no such folder or no history.csv).
int plot_outputs(const std::string& out_dir) {
  const std::string script = std::string(SHATTER_SOURCE_DIR) + "/scripts/plot.py";
  if (!std::filesystem::is_regular_file(script)) {
    std::fprintf(stderr, "error: %s: the plot script is missing\n", script.c_str());
    return 1;
  }
  std::string python = SHATTER_PYTHON;
  std::vector<char*> args{python.data(), const_cast<char*>(script.c_str()), const_cast<char*>(out_dir.c_str()),
                          nullptr};
  pid_t pid = 0;
  if (posix_spawnp(&pid, python.c_str(), nullptr, nullptr, args.data(), environ) != 0) {
    std::fprintf(stderr, "error: cannot start %s\n", python.c_str());
    return 1;
  }
  int wstatus = 0;
  if (waitpid(pid, &wstatus, 0) != pid || !WIFEXITED(wstatus)) return 1;
  return WEXITSTATUS(wstatus);
}

int cli(int argc, char** argv, FailureChannel& failures) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);

  CLI::App app{"shatter: explicit dynamics of solids that collide, crack and fragment"};
  app.require_subcommand(1);
  std::string scene_path, out_dir, restart, parts_dir;
  int part_ranks = 0;
  std::vector<std::string> overrides;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  bool deterministic = false, quiet = false;
  double max_elements = kDefaultMaxElements;

  auto* run = app.add_subcommand("run", "run a scene");
  run->add_option("scene", scene_path, "scene file (YAML)")->required();
  run->add_option("--out", out_dir, "output folder (default out/<name>)");
  run->add_option("--threads", threads, "oneTBB threads per rank")->check(CLI::Range(1, 4096));
  run->add_option("--set", overrides, "override a scene key: key.path=value (repeatable)");
  run->add_flag("--deterministic", deterministic, "bitwise identical results for any ranks and threads");
  run->add_option("--restart", restart, "continue from a checkpoint");
  run->add_flag("--quiet", quiet, "no progress line and no closing 'done' line; warnings and errors still print");
  run->add_option("--max-elements", max_elements, "refuse scenes whose shapes Gmsh would mesh into more elements "
                                                  "(estimated before meshing; default 5e7)")
      ->check(CLI::Range(1.0, 1e15));
  run->add_option("--parts", parts_dir, "read each rank's part from this folder of `shatter partition`'s files "
                                        "instead of meshing (no rank holds the whole model)");
  auto* check = app.add_subcommand("check", "check a scene and print the model summary; run nothing");
  check->add_option("scene", scene_path, "scene file (YAML)")->required();
  check->add_option("--set", overrides, "override a scene key: key.path=value (repeatable)");
  check->add_option("--max-elements", max_elements, "as for run")->check(CLI::Range(1.0, 1e15));
  auto* partition = app.add_subcommand("partition", "mesh a scene once and write its parts for R ranks, one file "
                                                    "per rank, for `shatter run --parts DIR` (one process)");
  partition->add_option("scene", scene_path, "scene file (YAML)")->required();
  partition->add_option("--ranks", part_ranks, "the ranks the run will use")->required()->check(CLI::Range(2, 1 << 20));
  partition->add_option("--out", out_dir, "folder of the part files (default parts/<name>)");
  partition->add_option("--set", overrides, "override a scene key: key.path=value (repeatable)");
  partition->add_option("--max-elements", max_elements, "as for run")->check(CLI::Range(1.0, 1e15));
  auto* plot = app.add_subcommand("plot", "plot a run's history.csv into OUTDIR/plots/ (PNG)");
  plot->add_option("outdir", out_dir, "output folder of a run")->required();

  // Outside the try block: a failure is reported (and, on one rank alone,
  // ends the process) before the simulation's collective destructors run.
  std::optional<Model> model;
  std::unique_ptr<Simulation> sim;
  try {
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      // --help and --version exit 0 through CLI11; a bad command line is bad input.
      const int rc = e.get_exit_code() == 0 ? app.exit(e) : 2;
      if (rc != 0 && rank == 0)
        std::fprintf(stderr, "error: %s (shatter --help shows the usage)\n", e.what());
      return rc == 0 ? 0 : 2;
    }
    if (*plot) return rank == 0 ? plot_outputs(out_dir) : 0;
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    const Scene scene = load_scene(scene_path, overrides);
    RunOptions opt;
    opt.threads = threads;
    opt.ranks = ranks;
    opt.quiet = quiet;
    opt.deterministic = deterministic;
    opt.failures = &failures;
    if (*run) opt.out_dir = out_dir.empty() ? std::filesystem::path("out") / scene.name : std::filesystem::path(out_dir);
    // A restart continues the outputs beside its checkpoint unless --out says otherwise.
    if (!restart.empty() && out_dir.empty()) opt.out_dir = std::filesystem::absolute(restart).parent_path();
    // Before the meshing: a folder that cannot take the outputs is bad input.
    if (*run) prepare_output_folder(opt.out_dir, MPI_COMM_WORLD);
    if (*partition) return write_parts(scene, part_ranks, out_dir, max_elements, ranks);
    model = build_model(scene, ranks > 1 ? MPI_COMM_WORLD : MPI_COMM_SELF, max_elements, parts_dir);
    sim = std::make_unique<Simulation>(*model, opt);
    if (!restart.empty()) {
      CheckpointRun written;
      SimulationState state = read_checkpoint(restart, *model, &written);
      // Before run() cuts the rows after the checkpoint: a refused restart touches nothing.
      on_root_for_all(MPI_COMM_WORLD, [&] { check_restart(restart, state, written, scene, opt.out_dir); });
      sim->restore_state(state);
    }
    if (*check) {
      print_check(*model, *sim);
    } else {
      install_stop_handlers();
      const long steps = sim->run();
      if (!quiet && rank == 0)
        std::fprintf(stderr, "done: %ld steps, energy error %.2e; outputs in %s\n", steps,
                     sim->energy_error(), opt.out_dir.c_str());
    }
  } catch (const InputError& e) {
    return report_failure(failures, 2, e.what());
  } catch (const std::exception& e) {
    return report_failure(failures, 1, e.what());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  install_setup_stop_handlers();
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  set_setup_stop_rank(rank);
  install_setup_stop_handlers();
  int status = 0;
  {
    FailureChannel failures(MPI_COMM_WORLD);
    status = cli(argc, argv, failures);
  }
  if (status != 0) ignore_stop_signals();
  release_disk_space();
  MPI_Finalize();
  return status;
}
