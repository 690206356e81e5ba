// bench_step — one whole explicit step (predictor, element forces, corrector,
// ledger) on a ~300k-tet TET4 block and a ~40k-element TET10 block, threads 1
// and 2 (issue 2's performance goal: >= 25 M element-steps/s/core for TET4,
// >= 1.8x on 2 threads).
// Run:     build/bench/bench_step --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Expect:  items_per_second = element-steps per second (all threads); the
//          per-core rate is items_per_second / threads. Meshing the block with
//          Gmsh takes ~30 s before the first result.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

#include "runtime/model.hpp"
#include "runtime/scene.hpp"
#include "runtime/simulation.hpp"

using namespace shatter;

namespace {

// One model per order, built once: a unit-ish steel block with a velocity
// gradient so the elements deform.
Model& block(int order) {
  static std::map<int, std::unique_ptr<Model>> models;
  auto& m = models[order];
  if (!m) {
    const auto path = std::filesystem::temp_directory_path() / ("bench_step_" + std::to_string(order) + ".yaml");
    std::ofstream(path) << "name: bench_step\n"
                           "time: {end: 1.0}\n"
                           "materials:\n"
                           "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
                           "bodies:\n"
                           "  - material: steel\n"
                           "    mesh: {shape: box, size: [0.1, 0.1, 0.1], element_size: "
                        << (order == 1 ? "0.0027" : "0.0075") << ", order: " << order
                        << "}\n"
                           "    velocity_gradient: [[100, 20, 0], [0, -50, 10], [5, 0, 30]]\n";
    m = std::make_unique<Model>(build_model(load_scene(path.string())));
  }
  return *m;
}

void BM_Step(benchmark::State& state) {
  const int order = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  Model& model = block(order);
  RunOptions opt;
  opt.threads = threads;
  Simulation sim(model, opt);
  for (auto _ : state) sim.step();
  const double ne = model.mesh.num_elements();
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * ne));
  state.counters["elements"] = ne;
  state.counters["threads"] = threads;
  // seconds of the element loop per step (the rest: predictor, corrector, ledger)
  state.counters["element_loop_s_per_step"] = sim.element_loop_seconds() / (state.iterations() + 1);
}

}  // namespace

BENCHMARK(BM_Step)->ArgsProduct({{1, 2}, {1, 2}})->ArgNames({"order", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK_MAIN();
