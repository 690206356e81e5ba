// bench_kernels — element force kernels in the loop the runtime uses, against
// the memory bandwidth of the machine.
//
// What it shows:
//   * STREAM triad a[i] = b[i] + s c[i] on 3 x 128 MiB arrays (GB/s, STREAM
//     convention: 24 bytes per index), 1 and 2 threads: the bandwidth reference.
//   * TET4 Neo-Hookean internal force + energy on a ~300k-tet box (Gmsh), one
//     explicit step = gather positions, kernel, scatter into the nodal force
//     array (zeroed every step). Variants:
//       Tet4Serial/<kernel>/<order>            plain element loop
//       Tet4Colored/<B>/<threads>/<order>      consecutive blocks of B elements,
//                                              blocks colored (greedy_coloring),
//                                              each color's blocks in tbb::parallel_for
//     kernel 0 = the seed kernel (Eigen expressions, kept here as the
//     baseline), 1 = kernels/tet4.hpp; order 0 = Gmsh order, 1 = after
//     reorder_for_locality (mesh/reorder.hpp).
//   * TET10 Neo-Hookean (4-point rule) on a ~70k-element box, same loops.
//   * ln J of 4 096 values in [0.5, 2) in shuffled order, in L1 (LaneLog/<kernel>):
//     kernel 0 = glibc's std::log value by value, 1 = lane_log (kernels/lane_log.hpp,
//     what the lane kernels call), 2 = Eigen's packet log of 8 values (lane_log's
//     path with AVX; at the baseline width its SSE form, which lane_log does not use).
// Counters: items_per_second = element-steps/s (all threads);
//   Melem_per_core = million element-steps/s per thread;
//   bw_frac = (bytes per element-step x rate) / STREAM triad rate at the same
//   thread count, with bytes = connectivity + reference constants + gathered
//   positions + scattered forces (read and write), i.e. no reuse of nodal data
//   through the caches: an upper bound on traffic, so a lower bound on time.
//
// How to run:  build-dir/bench/bench_kernels --benchmark_repetitions=5
//                --benchmark_report_aggregates_only=true
//   (bench/run_all.sh does this and writes bench/results/). The STREAM
//   benchmarks run first; bw_frac of a kernel uses the median STREAM rate
//   measured in the same process (0 if the STREAM benchmarks were filtered out).
// What to expect: see docs/performance.md, "Element kernels".
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <ctime>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "kernels/lane_log.hpp"
#include "kernels/tet10.hpp"
#include "kernels/tet4.hpp"
#include "mesh/gmsh_input.hpp"
#include "mesh/reorder.hpp"
#include "mesh/coloring.hpp"

using namespace shatter;

namespace {

/// CPU seconds of the whole process (all threads). The machine this was
/// written on is shared with compilers (load 3x the core count), so wall
/// time mostly measures the scheduler; process CPU time / threads is the
/// time the work would take with the cores to itself (TBB's idle spinning is
/// included, which makes it conservative).
double process_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// ---------------------------------------------------------------- STREAM ---

constexpr size_t kStreamN = size_t{1} << 24;  // 128 MiB per array, 4 x L3
std::map<int, std::vector<double>> g_stream_rates;  // threads -> GB/s per repetition

double stream_rate(int threads) {
  auto it = g_stream_rates.find(threads);
  if (it == g_stream_rates.end() || it->second.empty()) return 0.0;
  std::vector<double> v = it->second;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

void BM_StreamTriad(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  std::unique_ptr<double[]> a(new double[kStreamN]), b(new double[kStreamN]), c(new double[kStreamN]);
  const tbb::blocked_range<size_t> all(0, kStreamN, 1 << 16);
  tbb::static_partitioner part;
  tbb::parallel_for(all, [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) a[i] = 0.0, b[i] = 1.0, c[i] = 2.0;
  }, part);
  const double s = 3.0;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    tbb::parallel_for(all, [&](const tbb::blocked_range<size_t>& r) {
      double* __restrict pa = a.get();
      const double* __restrict pb = b.get();
      const double* __restrict pc = c.get();
      for (size_t i = r.begin(); i < r.end(); ++i) pa[i] = pb[i] + s * pc[i];
    }, part);
    benchmark::DoNotOptimize(a.get());
    benchmark::ClobberMemory();
  }
  const double cpu = (process_cpu_seconds() - cpu0) / threads;
  const double bytes = 24.0 * kStreamN * state.iterations();
  state.SetBytesProcessed(static_cast<int64_t>(bytes));
  state.counters["GBps_wall"] = benchmark::Counter(bytes * 1e-9, benchmark::Counter::kIsRate);
  state.counters["GBps"] = bytes * 1e-9 / cpu;
  // This repetition's rate, for the kernels' bandwidth fraction.
  g_stream_rates[threads].push_back(bytes * 1e-9 / cpu);
  state.counters["threads"] = threads;
}

// ------------------------------------------------------------ the problem ---

const NeoHookean kSteel = NeoHookean::from_young_poisson(200e9, 0.3, 7800);

/// A meshed unit box with reference constants, perturbed positions and a
/// force array; built once per (order, reordering).
struct Problem {
  Mesh mesh;
  std::vector<Tet4Reference> tet4;
  std::vector<Tet10Reference> tet10;
  std::vector<Vec3> x;  ///< current positions, m
  std::vector<Vec3> f;  ///< nodal internal forces, N
  std::map<int, Coloring> block_colors;  ///< block size -> coloring of the blocks
  std::vector<double> block_energy;
  double dt_min = HUGE_VAL;  ///< for the variant that also computes the stable step

  const Coloring& coloring(int B) {
    auto it = block_colors.find(B);
    if (it != block_colors.end()) return it->second;
    const int k = mesh.nodes_per_element();
    const Index ne = mesh.num_elements(), nb = (ne + B - 1) / B;
    std::vector<Index> offs(nb + 1);
    for (Index b = 0; b <= nb; ++b) offs[b] = std::min<Index>(b * B, ne) * k;
    return block_colors.emplace(B, greedy_coloring(offs, mesh.conn, mesh.num_nodes())).first->second;
  }
};

Problem make_problem(int order, bool reorder) {
  Problem p;
  ShapeSpec s;
  s.shape = "box";
  s.size = Vec3(1.0, 1.0, 1.0);
  // ~4.5 tets per h^3 with Gmsh's Delaunay: h = 0.0251 -> ~300k TET4,
  // h = 0.043 -> ~60k TET10.
  s.element_size = order == 1 ? 0.0251 : 0.043;
  s.order = order;
  p.mesh = mesh_shape(s, 0, 0, "bench_kernels");
  if (reorder) reorder_for_locality(p.mesh);
  const Index ne = p.mesh.num_elements(), nn = p.mesh.num_nodes();
  if (order == 1) {
    p.tet4.resize(ne);
    for (Index e = 0; e < ne; ++e) {
      const Index* c = p.mesh.element(e);
      p.tet4[e] = tet4_reference(p.mesh.reference[c[0]], p.mesh.reference[c[1]], p.mesh.reference[c[2]],
                                 p.mesh.reference[c[3]]);
    }
  } else {
    p.tet10.resize(ne);
    for (Index e = 0; e < ne; ++e) {
      Tet10Nodes X;
      for (int a = 0; a < 10; ++a) X.col(a) = p.mesh.reference[p.mesh.element(e)[a]];
      p.tet10[e] = tet10_reference(X);
    }
  }
  // Perturbed reference: a uniform stretch plus 1% random noise of h.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  p.x.resize(nn);
  for (Index v = 0; v < nn; ++v)
    p.x[v] = 1.001 * p.mesh.reference[v] + 0.01 * s.element_size * Vec3(u(rng), u(rng), u(rng));
  p.f.assign(nn, Vec3::Zero());
  std::fprintf(stderr, "# TET%d box: %d elements, %d nodes, %s order\n", order == 1 ? 4 : 10, ne, nn,
               reorder ? "Morton" : "Gmsh");
  return p;
}

Problem& problem(int order, bool reorder) {
  static std::map<std::pair<int, bool>, std::unique_ptr<Problem>> cache;
  auto& slot = cache[{order, reorder}];
  if (!slot) slot = std::make_unique<Problem>(make_problem(order, reorder));
  return *slot;
}

// ---------------------------------------------------- the seed TET4 kernel ---

/// The TET4 kernel as first committed (Eigen expressions, a second
/// determinant): the baseline of the speed-up.
Tet4Force tet4_internal_force_seed(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                                   const Mat3& Dm_inv, double V0, const NeoHookean& mat) {
  Mat3 Ds;
  Ds << x1 - x0, x2 - x0, x3 - x0;
  const Mat3 F = Ds * Dm_inv;
  Mat3 P;
  double W;
  mat.stress_energy(F, P, W);
  Tet4Force out;
  const Mat3 H = V0 * P * Dm_inv.transpose();
  out.f.template rightCols<3>() = H;
  out.f.col(0) = -H.rowwise().sum();
  out.energy = V0 * W;
  out.J = F.determinant();
  return out;
}

// --------------------------------------------------------- element ranges ---

constexpr int kLanes = 4;  ///< elements per tet4_neo_hookean_lanes call

/// Gather, kernel, scatter for elements [e0, e1); returns the strain energy.
/// Kernel 0: seed kernel, 1: tet4_internal_force, N >= 2: tet4_neo_hookean_lanes
/// on N elements at a time (the rest one by one; bitwise the same forces).
template <int Kernel, bool kWithDt = false>
double tet4_range(Problem& p, Index e0, Index e1) {
  const Index* __restrict conn = p.mesh.conn.data();
  const Tet4Reference* __restrict ref = p.tet4.data();
  const Vec3* __restrict x = p.x.data();
  Vec3* __restrict f = p.f.data();
  double energy = 0.0;
  Index e = e0;
  if constexpr (Kernel >= 2) {
    constexpr int N = Kernel == 6 ? kLanes : Kernel;
    Tet4Lanes<N> L;
    for (; e + N <= e1; e += N) {
      const Index* c = conn + 4 * static_cast<size_t>(e);
      for (int l = 0; l < N; ++l) {
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) L.x[3 * a + i][l] = x[c[4 * l + a]][i];
        for (int q = 0; q < 9; ++q) L.Dm_inv[q][l] = ref[e + l].Dm_inv.data()[q];
        L.V0[l] = ref[e + l].volume;
      }
      tet4_neo_hookean_lanes(L, kSteel);
      if constexpr (Kernel == 6) {
        double dt2[N];
        tet4_stable_dt_squared_lanes(L, kSteel, dt2);
        for (int l = 0; l < N; ++l) p.dt_min = std::min(p.dt_min, dt2[l]);  // sqrt once, per step
      } else if constexpr (kWithDt) {
        for (int l = 0; l < N; ++l) {
          const Index* cl = c + 4 * l;
          const double h = tet4_stable_length(x[cl[0]], x[cl[1]], x[cl[2]], x[cl[3]]);
          p.dt_min = std::min(p.dt_min, h / kSteel.wave_speed(L.J[l] > 0 ? L.J[l] : 1.0));
        }
      }
      for (int l = 0; l < N; ++l) {
        for (int a = 0; a < 4; ++a) {
          double* fa = f[c[4 * l + a]].data();
          for (int i = 0; i < 3; ++i) fa[i] += L.f[3 * a + i][l];
        }
        energy += L.energy[l];
      }
    }
  }
  for (; e < e1; ++e) {
    const Index* c = conn + 4 * static_cast<size_t>(e);
    const Tet4Force out =
        Kernel == 0 ? tet4_internal_force_seed(x[c[0]], x[c[1]], x[c[2]], x[c[3]], ref[e].Dm_inv, ref[e].volume, kSteel)
                    : tet4_internal_force(x[c[0]], x[c[1]], x[c[2]], x[c[3]], ref[e].Dm_inv, ref[e].volume, kSteel);
    for (int a = 0; a < 4; ++a) f[c[a]] += out.f.col(a);
    energy += out.energy;
  }
  return energy;
}

double tet10_range(Problem& p, Index e0, Index e1) {
  double energy = 0.0;
  for (Index e = e0; e < e1; ++e) {
    const Index* c = p.mesh.element(e);
    Tet10Nodes xe;
    for (int a = 0; a < 10; ++a) xe.col(a) = p.x[c[a]];
    const Tet10Force out = tet10_internal_force(xe, p.tet10[e], kSteel);
    for (int a = 0; a < 10; ++a) p.f[c[a]] += out.f.col(a);
    energy += out.energy;
  }
  return energy;
}

template <class Range>
double serial_step(Problem& p, Range range) {
  std::fill(p.f.begin(), p.f.end(), Vec3::Zero());
  return range(p, 0, p.mesh.num_elements());
}

/// The colored-block step: colors in order, the blocks of one color in
/// parallel; the energy is summed per block, then over blocks in block order,
/// so it is bitwise the same for any thread count.
template <class Range>
double colored_step(Problem& p, const Coloring& col, int B, Range range) {
  const Index ne = p.mesh.num_elements();
  tbb::parallel_for(tbb::blocked_range<Index>(0, p.mesh.num_nodes(), 4096),
                    [&](const tbb::blocked_range<Index>& r) {
                      std::fill(p.f.begin() + r.begin(), p.f.begin() + r.end(), Vec3::Zero());
                    });
  for (int c = 0; c < col.num_colors(); ++c) {
    const auto items = col.items_of(c);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, items.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        const Index b = items[i];
        p.block_energy[b] = range(p, b * B, std::min<Index>(ne, (b + 1) * B));
      }
    });
  }
  double energy = 0.0;
  for (double e : p.block_energy) energy += e;
  return energy;
}

/// Bytes per element-step with no reuse of nodal data: connectivity,
/// reference constants, gathered positions, scattered forces (read + write).
double bytes_per_element(int order) {
  return order == 1 ? 4 * 4 + sizeof(Tet4Reference) + 4 * 24 + 2 * 4 * 24
                    : 10 * 4 + sizeof(Tet10Reference) + 10 * 24 + 2 * 10 * 24;
}

/// Counters from the process CPU time `cpu` spent in the timed loop:
/// Melem_per_core = element-steps per CPU second; bw_frac = the traffic rate
/// at time cpu / threads over the STREAM rate measured the same way.
void set_counters(benchmark::State& state, const Problem& p, int order, int threads, double cpu) {
  const double steps = double(p.mesh.num_elements()) * state.iterations();
  state.SetItemsProcessed(static_cast<int64_t>(steps));
  state.counters["Melem_per_core"] = steps * 1e-6 / cpu;
  state.counters["Melem_per_core_wall"] = benchmark::Counter(steps * 1e-6 / threads, benchmark::Counter::kIsRate);
  const double stream = stream_rate(threads);
  state.counters["bw_frac"] = stream > 0 ? steps * bytes_per_element(order) * 1e-9 / (cpu / threads) / stream : 0.0;
  state.counters["threads"] = threads;
  state.counters["elements"] = p.mesh.num_elements();
}

// ------------------------------------------------------------- benchmarks ---

void BM_Tet4Serial(benchmark::State& state) {
  const int kernel = static_cast<int>(state.range(0));
  Problem& p = problem(1, state.range(1) != 0);
  double energy = 0;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    switch (kernel) {
      case 0: energy = serial_step(p, tet4_range<0>); break;
      case 1: energy = serial_step(p, tet4_range<1>); break;
      case 2: energy = serial_step(p, tet4_range<2>); break;
      case 4: energy = serial_step(p, tet4_range<4>); break;
      default: energy = serial_step(p, tet4_range<8>); break;
    }
    benchmark::DoNotOptimize(energy);
    benchmark::DoNotOptimize(p.f.data());
  }
  set_counters(state, p, 1, 1, process_cpu_seconds() - cpu0);
}

/// The kernel with its data in L1: 256 elements over and over, serial.
/// The compute ceiling of the loop body (gather + kernel + scatter).
void BM_Tet4InCache(benchmark::State& state) {
  const int kernel = static_cast<int>(state.range(0));
  Problem& p = problem(1, true);
  constexpr Index kElems = 256;
  for (auto _ : state) {
    const double energy = kernel == 0   ? tet4_range<0>(p, 0, kElems)
                          : kernel == 1 ? tet4_range<1>(p, 0, kElems)
                          : kernel == 5 ? tet4_range<kLanes, true>(p, 0, kElems)
                          : kernel == 6 ? tet4_range<6>(p, 0, kElems)
                                        : tet4_range<kLanes>(p, 0, kElems);
    benchmark::DoNotOptimize(energy);
    benchmark::DoNotOptimize(p.f.data());
  }
  state.SetItemsProcessed(kElems * state.iterations());
  state.counters["Melem_per_core"] = benchmark::Counter(kElems * 1e-6 * state.iterations(), benchmark::Counter::kIsRate);
}

/// ln of 4 096 det F values in [0.5, 2), shuffled (no branch pattern to learn),
/// in L1: ns per value (docs/performance.md "A vectorised log").
void BM_LaneLog(benchmark::State& state) {
  const int kernel = static_cast<int>(state.range(0));
  constexpr int kValues = 4096;
  std::vector<double> x(kValues), y(kValues);
  for (int i = 0; i < kValues; ++i) x[i] = 0.5 + 1.5 * ((i * 2654435761u) % kValues) / kValues;
  using Block = Eigen::Array<double, 8, 1>;
  for (auto _ : state) {
    for (int i = 0; i < kValues; i += 8) {
      const double(&in)[8] = *reinterpret_cast<const double(*)[8]>(x.data() + i);
      double(&out)[8] = *reinterpret_cast<double(*)[8]>(y.data() + i);
      if (kernel == 0) {
        for (int l = 0; l < 8; ++l) out[l] = std::log(in[l]);
      } else if (kernel == 1) {
        lane_log(in, out);
      } else {
        const Block r = Eigen::Map<const Block>(in).log();
        for (int l = 0; l < 8; ++l) out[l] = r[l];
      }
    }
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(int64_t{kValues} * state.iterations());
}

/// Determinism guard, run once: the lane kernel equals the single-element
/// kernel bitwise, and the colored loop gives bitwise the same forces and
/// energy on 1 and 2 threads.
void BM_Tet4Determinism(benchmark::State& state) {
  Problem& p = problem(1, true);
  const double e1 = serial_step(p, tet4_range<1>);
  const std::vector<Vec3> f1 = p.f;
  const double e4 = serial_step(p, tet4_range<kLanes>);
  bool ok = e1 == e4 && p.f == f1;
  const Coloring& col = p.coloring(256);
  p.block_energy.assign(col.items.size(), 0.0);
  std::vector<Vec3> fc[2];
  double ec[2];
  for (int t = 1; t <= 2; ++t) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, t);
    ec[t - 1] = colored_step(p, col, 256, tet4_range<kLanes>);
    fc[t - 1] = p.f;
  }
  ok = ok && ec[0] == ec[1] && fc[0] == fc[1];
  // The squared stable step agrees with h / wave_speed(J) to round-off.
  double dt_rel = 0.0;
  for (Index e = 0; e < p.mesh.num_elements(); e += 7) {
    const Index* c = p.mesh.element(e);
    Tet4Lanes<1> L;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) L.x[3 * a + i][0] = p.x[c[a]][i];
    for (int q = 0; q < 9; ++q) L.Dm_inv[q][0] = p.tet4[e].Dm_inv.data()[q];
    L.V0[0] = p.tet4[e].volume;
    tet4_neo_hookean_lanes(L, kSteel);
    double dt2[1];
    tet4_stable_dt_squared_lanes(L, kSteel, dt2);
    const double dt = tet4_stable_length(p.x[c[0]], p.x[c[1]], p.x[c[2]], p.x[c[3]]) / kSteel.wave_speed(L.J[0]);
    dt_rel = std::max(dt_rel, std::abs(std::sqrt(dt2[0]) - dt) / dt);
  }
  ok = ok && dt_rel < 1e-14;
  state.counters["dt_max_rel_diff"] = dt_rel;
  for (auto _ : state) benchmark::DoNotOptimize(ok);
  state.counters["bitwise_equal"] = ok ? 1 : 0;
  if (!ok) state.SkipWithError("forces differ between kernels or thread counts");
}

void BM_Tet4Colored(benchmark::State& state) {
  const int B = static_cast<int>(state.range(0)), threads = static_cast<int>(state.range(1));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  Problem& p = problem(1, state.range(2) != 0);
  const Coloring& col = p.coloring(B);
  p.block_energy.assign(col.items.size(), 0.0);
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    const double energy = colored_step(p, col, B, tet4_range<kLanes>);
    benchmark::DoNotOptimize(energy);
    benchmark::DoNotOptimize(p.f.data());
  }
  set_counters(state, p, 1, threads, process_cpu_seconds() - cpu0);
  state.counters["colors"] = col.num_colors();
}

void BM_Tet10Serial(benchmark::State& state) {
  Problem& p = problem(2, state.range(0) != 0);
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    const double energy = serial_step(p, tet10_range);
    benchmark::DoNotOptimize(energy);
    benchmark::DoNotOptimize(p.f.data());
  }
  set_counters(state, p, 2, 1, process_cpu_seconds() - cpu0);
}

void BM_Tet10Colored(benchmark::State& state) {
  const int B = static_cast<int>(state.range(0)), threads = static_cast<int>(state.range(1));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  Problem& p = problem(2, state.range(2) != 0);
  const Coloring& col = p.coloring(B);
  p.block_energy.assign(col.items.size(), 0.0);
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    const double energy = colored_step(p, col, B, tet10_range);
    benchmark::DoNotOptimize(energy);
    benchmark::DoNotOptimize(p.f.data());
  }
  set_counters(state, p, 2, threads, process_cpu_seconds() - cpu0);
  state.counters["colors"] = col.num_colors();
}

}  // namespace

BENCHMARK(BM_StreamTriad)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Tet4Serial)->ArgNames({"kernel", "morton"})->ArgsProduct({{0, 1, 2, 4, 8}, {1}})->ArgsProduct({{0, 4}, {0}})->Unit(benchmark::kMillisecond);
// kernel 5 = lanes + the per-element stable step as runtime/element_forces.cpp
// computes it (tet4_stable_length, NeoHookean::wave_speed(J): a second log, 2 sqrt);
// kernel 6 = lanes + tet4_stable_dt_squared_lanes (no log, no sqrt per element).
BENCHMARK(BM_Tet4InCache)->ArgName("kernel")->Arg(0)->Arg(1)->Arg(kLanes)->Arg(5)->Arg(6);
BENCHMARK(BM_LaneLog)->ArgName("kernel")->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_Tet4Determinism)->Iterations(1)->Repetitions(1);
BENCHMARK(BM_Tet4Colored)
    ->ArgNames({"B", "threads", "morton"})
    ->ArgsProduct({{64, 256, 1024, 4096}, {1, 2}, {1}})
    ->ArgsProduct({{1024}, {1, 2}, {0}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Tet10Serial)->ArgName("morton")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Tet10Colored)
    ->ArgNames({"B", "threads", "morton"})
    ->ArgsProduct({{128}, {1, 2}, {0, 1}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
