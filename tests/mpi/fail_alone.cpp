// A run in which one rank alone fails inside the time loop (tests/mpi/failures.sh):
//   fail_alone SCENE OUTDIR RANK STEP
// runs SCENE on the ranks of MPI_COMM_WORLD as `shatter run` does, and rank
// RANK throws before step STEP (RunOptions::before_step) while the others go
// on into the step's collectives. The failure takes the CLI's path
// (report_failure): one message, every rank ended, exit 1.
#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include "kernels/error.hpp"
#include "runtime/failure.hpp"
#include "runtime/model.hpp"
#include "runtime/scene.hpp"
#include "runtime/simulation.hpp"

int main(int argc, char** argv) {
  using namespace shatter;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int status = 0;
  {
    FailureChannel failures(MPI_COMM_WORLD);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    // Declared outside the try block, as in the CLI: a failure is reported
    // before the simulation's collective destructors run.
    std::optional<Model> model;
    std::optional<Simulation> sim;
    try {
      if (argc != 5) throw InputError("usage: fail_alone SCENE OUTDIR RANK STEP");
      const int fail_rank = std::atoi(argv[3]);
      const long fail_step = std::atol(argv[4]);
      model = build_model(load_scene(argv[1], {}), MPI_COMM_WORLD);
      RunOptions opt;
      opt.out_dir = argv[2];
      opt.ranks = ranks;
      opt.quiet = true;
      opt.failures = &failures;
      opt.before_step = [&](long step) {
        if (step == fail_step && rank == fail_rank)
          throw Error("step " + std::to_string(step) + ": failure injected on rank " + std::to_string(rank) +
                      " by the test");
      };
      sim.emplace(*model, opt);
      sim->run();
    } catch (const InputError& e) {
      status = report_failure(failures, 2, e.what());
    } catch (const std::exception& e) {
      status = report_failure(failures, 1, e.what());
    }
  }
  MPI_Finalize();
  return status;
}
