// bench_fracture — cost of the facet check (FractureStage::check: critical_facets
// with the runtime's laws) against the bulk element update (ElementForces::compute,
// which also writes the stresses the check reads) on the same TET4 box (~90k
// elements), threads 1 and 2. Issues 5 and 19: the hot field at most 30 % of
// the element update (bench/facet_check_ratio.sh: interleaved runs, medians,
// the ratio of the times and of the time per facet to the time per element).
// Stress fields of the check:
//   cold: uniaxial 0.5 sigma_c everywhere (no element can reach the strength:
//         the Frobenius bound rejects every element in one sweep);
//   mixed: smooth field plus noise, ~10 % of the elements above the bound
//         (like a fragmenting body after the first cracks);
//   hot:  uniaxial 1.05 sigma_c everywhere (every facet evaluated in full; the
//         expanding ring just before the first insertions).
// Run:     build/bench/bench_fracture --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Expect:  check/update ratios (median real time) in docs/performance.md; meshing takes ~10 s first.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>

#include "runtime/decomposition.hpp"
#include "runtime/element_forces.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/model.hpp"
#include "runtime/scene.hpp"

using namespace shatter;

namespace {

constexpr double kStrength = 300.0e6;

struct Setup {
  std::unique_ptr<Model> model;
  std::unique_ptr<Decomposition> dec;       // one rank: MPI is not initialised
  std::unique_ptr<FractureStage> fracture;  // the runtime's topology, laws and check
  std::vector<Vec3> x;
};

Setup& setup() {
  static Setup s;
  if (!s.model) {
    const auto path = std::filesystem::temp_directory_path() / "bench_fracture.yaml";
    std::ofstream(path) << "name: bench_fracture\n"
                           "time: {end: 1.0}\n"
                           "materials:\n"
                           "  alu: {model: neo_hookean, density: 2750, youngs_modulus: 275.0e9, poisson_ratio: 0.3,\n"
                           "        fracture: {strength: 300.0e6, energy: 1000.0, beta: 1.0}}\n"
                           "bodies:\n"
                           "  - material: alu\n"
                           "    mesh: {shape: box, size: [0.1, 0.1, 0.1], element_size: 0.004}\n";
    s.model = std::make_unique<Model>(build_model(load_scene(path.string())));
    // The check reads sigma_c and beta only. Gc = 1000 J/m^2 (not the ring's
    // 100) so that the elastic rise sigma_c / k_p, with k_p = E / h_min as the
    // runtime sets it, ends before delta_c on this coarse (4 mm) mesh.
    s.dec = std::make_unique<Decomposition>(*s.model, MPI_COMM_SELF);
    s.fracture = std::make_unique<FractureStage>(*s.model, *s.dec);
    s.x = s.model->mesh.reference;
    for (Vec3& p : s.x) p = Vec3(1.001 * p.x(), 0.9997 * p.y(), 0.9997 * p.z());
  }
  return s;
}

std::vector<double> stress_field(const Mesh& mesh, int kind) {
  std::vector<double> s(6 * static_cast<size_t>(mesh.num_elements()), 0.0);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.15 * kStrength);
  for (Index e = 0; e < mesh.num_elements(); ++e) {
    double* v = s.data() + 6 * e;
    if (kind == 0) {
      v[0] = 0.5 * kStrength;
    } else if (kind == 2) {
      v[0] = 1.05 * kStrength;
    } else {
      const Vec3 X = mesh.reference[mesh.element(e)[0]];
      const double smooth = 0.45 * kStrength * (1 + std::sin(60 * X.x()) * std::cos(40 * X.y()));
      for (int i = 0; i < 6; ++i) v[i] = (i == 0 ? smooth : 0.2 * smooth) + noise(rng);
    }
  }
  return s;
}

void BM_ElementUpdate(benchmark::State& state) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, state.range(0));
  Setup& s = setup();
  const ElementForces elements(*s.model);
  std::vector<Vec3> f(s.model->mesh.num_nodes());
  std::vector<double> stress(6 * static_cast<size_t>(s.model->mesh.num_elements()));
  for (auto _ : state) benchmark::DoNotOptimize(elements.compute(s.x, f, stress));
  state.SetItemsProcessed(state.iterations() * s.model->mesh.num_elements());
  state.counters["elements"] = s.model->mesh.num_elements();
}

void BM_FacetCheck(benchmark::State& state) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, state.range(0));
  Setup& s = setup();
  const std::vector<double> stress = stress_field(s.model->mesh, static_cast<int>(state.range(1)));
  size_t found = 0;
  for (auto _ : state) {
    const std::vector<Index> f = s.fracture->check(s.x, stress);
    found = f.size();
    benchmark::DoNotOptimize(f.data());
  }
  state.SetItemsProcessed(state.iterations() * s.model->mesh.num_elements());
  state.counters["critical_facets"] = static_cast<double>(found);
  state.counters["facets"] = s.fracture->topology().num_facets();
  state.counters["elements"] = s.model->mesh.num_elements();
}

}  // namespace

BENCHMARK(BM_ElementUpdate)->Arg(1)->Arg(2)->ArgNames({"threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FacetCheck)
    ->ArgsProduct({{1, 2}, {0, 1, 2}})
    ->ArgNames({"threads", "cold_mixed_hot"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_MAIN();
