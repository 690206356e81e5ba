// Contact search benchmark: broad phase (swept boxes -> canonical candidate
// pairs) of the sparse bucket (contact/candidates) against brute force, a
// uniform spatial-hash grid (Teschner et al. 2003, written here) and CGAL's
// box_intersection_d (Zomorodian & Edelsbrunner streamed segment tree), on
// the same boxes, for three configurations:
//   bodies    two TET10 balls meshed by Gmsh, about to collide   (~1e3..2e4 triangles)
//   cubes     a pile of jittered, slightly rotated cubes falling (~1e3..1e6)
//   fragments a cloud of small random tetrahedra flying apart     (~1e3..1e6)
// Every method ends in the same candidate list (the bench checks the counts).
//
// Run:     build/bench/bench_contact_search --benchmark_counters_tabular=true
// Expect:  time/iteration (median of 3; a single run at 1e6), counters: triangles, candidates,
//          cand_per_s, threads, bytes: what each method holds besides the
//          surface and positions -- sparse bucket and hash grid: the swept
//          boxes (48 B per primitive) plus their grids; CGAL: its boxes
//          (64 B with id and index) plus the copy box_self_intersection_d makes.
//          A full run takes about 4 minutes of CPU (8 minutes of wall time on
//          2 cores busy with other jobs, load average 7).
#include <CGAL/Box_intersection_d/Box_with_info_d.h>
#include <CGAL/box_intersection_d.h>
#include <benchmark/benchmark.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "contact/candidates.hpp"
#include "mesh/gmsh_input.hpp"

using namespace shatter;

namespace {

/// One configuration: a surface and the positions before and after a step.
struct Scene {
  ContactSurface surface;
  std::vector<Vec3> x_old, x_new;
};

/// Two TET10 balls of radius 1, 0.05 apart, closing at 0.1 per step.
Scene colliding_bodies(double element_size) {
  ShapeSpec ball;
  ball.shape = "sphere";
  ball.radius = 1.0;
  ball.element_size = element_size;
  ball.order = 2;
  Mesh m = mesh_shape(ball, 0, 0, "bench");
  ball.center = Vec3(2.05, 0.3, 0);
  append_mesh(m, mesh_shape(ball, 1, 0, "bench"));
  Scene s{build_contact_surface(m), m.reference, m.reference};
  for (Index n = 0; n < m.num_nodes(); ++n)
    s.x_new[n] += Vec3(m.node_body[n] == 0 ? 0.05 : -0.05, 0, 0);
  return s;
}

/// Surface of a unit cube, each face an m x m grid of squares split in two
/// triangles (12 m^2 triangles, appended to tris), rotated by R about its centre c.
void add_cube(Scene& s, std::vector<SurfaceTriangle>& tris, int m, const Vec3& c, const Mat3& R,
              const Vec3& motion, int body) {
  std::vector<Index> id((m + 1) * (m + 1) * (m + 1), -1);
  auto node = [&](int i, int j, int k) {
    Index& n = id[(i * (m + 1) + j) * (m + 1) + k];
    if (n < 0) {
      const Vec3 x = c + R * (Vec3(i, j, k) / m - Vec3::Constant(0.5));
      n = static_cast<Index>(s.x_old.size());
      s.x_old.push_back(x);
      s.x_new.push_back(x + motion);
    }
    return n;
  };
  // face normal axis a, side 0 or m; (u, v) the in-face axes, ordered so that
  // u x v points out of the cube
  for (int a = 0; a < 3; ++a)
    for (int side : {0, m}) {
      int u = (a + 1) % 3, v = (a + 2) % 3;
      if (side == 0) std::swap(u, v);
      for (int p = 0; p < m; ++p)
        for (int q = 0; q < m; ++q) {
          auto at = [&](int dp, int dq) {
            int ijk[3];
            ijk[a] = side;
            ijk[u] = p + dp;
            ijk[v] = q + dq;
            return node(ijk[0], ijk[1], ijk[2]);
          };
          tris.push_back({{at(0, 0), at(1, 0), at(1, 1)}, body});
          tris.push_back({{at(0, 0), at(1, 1), at(0, 1)}, body});
        }
    }
}

/// About `triangles` triangles: cubes (8 x 8 grids per face) stacked on a
/// square-based pile with gaps of ~2 % and small random rotations, falling 1 %.
Scene pile_of_cubes(int triangles) {
  const int m = 8, per_cube = 12 * m * m;
  const int cubes = std::max(1, triangles / per_cube);
  const int side = std::max(1, static_cast<int>(std::cbrt(cubes * 4.0)));
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  Scene s;
  std::vector<SurfaceTriangle> tris;
  for (int c = 0; c < cubes; ++c) {
    const int i = c % side, j = (c / side) % side, k = c / (side * side);
    const Mat3 R = (Eigen::AngleAxisd(jitter(rng), Vec3::UnitZ()) *
                    Eigen::AngleAxisd(jitter(rng), Vec3::UnitX()))
                       .toRotationMatrix();
    add_cube(s, tris, m, Vec3(1.03 * i + jitter(rng), 1.03 * j + jitter(rng), 1.03 * k), R,
             Vec3(0, 0, -0.01), c);
  }
  s.surface = make_contact_surface(tris);
  return s;
}

/// About `triangles` triangles: tetrahedra of edge ~0.1 at uniform random
/// positions in a ball whose volume grows with their number (about 5 %
/// overlap), moving radially outward by up to a tenth of their size.
Scene fragment_cloud(int triangles) {
  const int tets = std::max(1, triangles / 4);
  const double radius = 0.1 * std::cbrt(tets / 2.0);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Scene s;
  std::vector<SurfaceTriangle> tris;
  for (int t = 0; t < tets; ++t) {
    Vec3 c;
    do c = Vec3(unit(rng), unit(rng), unit(rng));
    while (c.squaredNorm() > 1.0);
    c *= radius;
    const Vec3 motion = 0.01 * c / radius;
    const auto base = static_cast<Index>(s.x_old.size());
    for (int a = 0; a < 4; ++a) {
      const Vec3 x = c + 0.06 * Vec3(unit(rng), unit(rng), unit(rng));
      s.x_old.push_back(x);
      s.x_new.push_back(x + motion);
    }
    // outward orientation depends on the sign of the random tet's volume
    const Vec3 &x0 = s.x_old[base], &x1 = s.x_old[base + 1], &x2 = s.x_old[base + 2],
               &x3 = s.x_old[base + 3];
    const bool positive = (x1 - x0).cross(x2 - x0).dot(x3 - x0) > 0;
    for (const auto& f :
         {std::array{0, 2, 1}, std::array{0, 1, 3}, std::array{0, 3, 2}, std::array{1, 2, 3}}) {
      std::array<Index, 3> n = {base + f[0], base + f[1], base + f[2]};
      if (!positive) std::swap(n[1], n[2]);
      tris.push_back({n, t});
    }
  }
  s.surface = make_contact_surface(tris);
  return s;
}

/// Scenes are built once per (kind, size) and reused by every method.
const Scene& scene(int kind, int size) {
  static std::map<std::pair<int, int>, Scene> cache;
  auto it = cache.find({kind, size});
  if (it != cache.end()) return it->second;
  Scene s = kind == 0   ? colliding_bodies(size / 1000.0)
            : kind == 1 ? pile_of_cubes(size)
                        : fragment_cloud(size);
  return cache.emplace(std::pair{kind, size}, std::move(s)).first->second;
}

size_t bytes_of(const SweptBoxes& b) {
  return (b.triangles.capacity() + b.edges.capacity() + b.vertices.capacity()) * sizeof(Box);
}

// ---------------------------------------------------------------------------
// Uniform spatial hash grid (Teschner et al., "Optimized spatial hashing for
// collision detection of deformable objects", VMV 2003): cubic cells of the
// same side as the sparse bucket's h_0, every box entered in every cell it
// spans, cells hashed into a table of ~2 x entries buckets (CSR). A pair is
// reported from the cell holding max(lo_a, lo_b) only.
struct HashGrid {
  double h = 1;
  Vec3 origin = Vec3::Zero();
  std::vector<std::uint32_t> offsets;  // [table + 1]
  std::vector<Index> ids;              // box ids by bucket
  size_t table = 1;

  std::array<std::int64_t, 3> cell(const Vec3& x) const {
    return {static_cast<std::int64_t>(std::floor((x[0] - origin[0]) / h)),
            static_cast<std::int64_t>(std::floor((x[1] - origin[1]) / h)),
            static_cast<std::int64_t>(std::floor((x[2] - origin[2]) / h))};
  }
  size_t bucket(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return static_cast<size_t>((i * 73856093) ^ (j * 19349663) ^ (k * 83492791)) % table;
  }
  template <class F>
  void for_cells(const Box& b, F&& f) const {
    const auto lo = cell(b.lo), hi = cell(b.hi);
    for (auto i = lo[0]; i <= hi[0]; ++i)
      for (auto j = lo[1]; j <= hi[1]; ++j)
        for (auto k = lo[2]; k <= hi[2]; ++k) f(i, j, k);
  }
  size_t bytes() const {
    return offsets.capacity() * sizeof(std::uint32_t) + ids.capacity() * sizeof(Index);
  }
};

HashGrid build_hash_grid(std::span<const Box> boxes, double h, const Vec3& origin) {
  HashGrid g;
  g.h = h;
  g.origin = origin;
  size_t entries = 0;
  for (const Box& b : boxes) g.for_cells(b, [&](auto, auto, auto) { ++entries; });
  g.table = 2 * entries + 1;
  g.offsets.assign(g.table + 1, 0);
  for (const Box& b : boxes)
    g.for_cells(b, [&](auto i, auto j, auto k) { ++g.offsets[g.bucket(i, j, k) + 1]; });
  for (size_t t = 0; t < g.table; ++t) g.offsets[t + 1] += g.offsets[t];
  g.ids.resize(entries);
  std::vector<std::uint32_t> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (Index id = 0; id < static_cast<Index>(boxes.size()); ++id)
    g.for_cells(boxes[id], [&](auto i, auto j, auto k) { g.ids[fill[g.bucket(i, j, k)]++] = id; });
  return g;
}

template <class Report>
void query_hash_grid(const HashGrid& g, std::span<const Box> boxes, const Box& q, Report&& report) {
  g.for_cells(q, [&](auto i, auto j, auto k) {
    const size_t t = g.bucket(i, j, k);
    for (auto p = g.offsets[t]; p < g.offsets[t + 1]; ++p) {
      const Box& b = boxes[g.ids[p]];
      if (boxes_overlap(q, b) && g.cell(q.lo.cwiseMax(b.lo)) == std::array{i, j, k})
        report(g.ids[p]);
    }
  });
}

/// The sparse bucket's h_0 and origin rule, so both grids use the same cells.
std::pair<double, Vec3> grid_parameters(const SweptBoxes& b) {
  const SparseBucket probe = build_sparse_bucket(b.triangles);
  Vec3 origin = Vec3::Constant(std::numeric_limits<double>::infinity());
  for (const auto* set : {&b.triangles, &b.edges, &b.vertices})
    for (const Box& x : *set) origin = origin.cwiseMin(x.lo);
  return {probe.cell_size.empty() ? 1.0 : probe.cell_size[0], origin};
}

ContactPairs hash_grid_candidates(const ContactSurface& s, const SweptBoxes& b, size_t& bytes) {
  const auto [h, origin] = grid_parameters(b);
  const HashGrid tri = build_hash_grid(b.triangles, h, origin);
  const HashGrid edge = build_hash_grid(b.edges, h, origin);
  bytes = tri.bytes() + edge.bytes() + bytes_of(b);
  tbb::enumerable_thread_specific<ContactPairs> buffers;
  const size_t nv = b.vertices.size(), ne = b.edges.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv + ne, 256),
                    [&](const tbb::blocked_range<size_t>& r) {
                      ContactPairs& out = buffers.local();
                      for (size_t k = r.begin(); k != r.end(); ++k) {
                        if (k < nv) {
                          const auto v = static_cast<Index>(k);
                          query_hash_grid(tri, b.triangles, b.vertices[k], [&](Index t) {
                            if (auto p = vertex_face_pair(s, v, t)) out.push_back(*p);
                          });
                        } else {
                          const auto e = static_cast<Index>(k - nv);
                          query_hash_grid(edge, b.edges, b.edges[e], [&](Index f) {
                            if (e < f)
                              if (auto p = edge_edge_pair(s, e, f)) out.push_back(*p);
                          });
                        }
                      }
                    });
  ContactPairs pairs;
  for (const auto& buf : buffers) pairs.insert(pairs.end(), buf.begin(), buf.end());
  canonicalize(pairs);
  return pairs;
}

// ---------------------------------------------------------------------------
// CGAL box_intersection_d on the same boxes (closed topology, the default).
using CgalBox = CGAL::Box_intersection_d::Box_with_info_d<double, 3, Index>;

std::vector<CgalBox> cgal_boxes(const std::vector<Box>& boxes) {
  std::vector<CgalBox> out;
  out.reserve(boxes.size());
  for (Index k = 0; k < static_cast<Index>(boxes.size()); ++k) {
    const Box& b = boxes[k];
    out.emplace_back(CGAL::Bbox_3(b.lo[0], b.lo[1], b.lo[2], b.hi[0], b.hi[1], b.hi[2]), k);
  }
  return out;
}

template <class Tag>
ContactPairs cgal_candidates(const ContactSurface& s, const SweptBoxes& b, size_t& bytes) {
  std::vector<CgalBox> tri = cgal_boxes(b.triangles), edge = cgal_boxes(b.edges),
                       vert = cgal_boxes(b.vertices);
  // box_self_intersection_d works on an internal copy of the edge boxes; a
  // CGAL pipeline would make its boxes from the positions directly, so our
  // swept boxes are not counted
  bytes = (tri.capacity() + 2 * edge.capacity() + vert.capacity()) * sizeof(CgalBox);
  tbb::enumerable_thread_specific<ContactPairs> buffers;
  CGAL::box_intersection_d<Tag>(vert.begin(), vert.end(), tri.begin(), tri.end(),
                                [&](const CgalBox& v, const CgalBox& t) {
                                  if (auto p = vertex_face_pair(s, v.info(), t.info()))
                                    buffers.local().push_back(*p);
                                });
  CGAL::box_self_intersection_d<Tag>(
      edge.begin(), edge.end(), [&](const CgalBox& e, const CgalBox& f) {
        const Index a = std::min(e.info(), f.info()), c = std::max(e.info(), f.info());
        if (auto p = edge_edge_pair(s, a, c)) buffers.local().push_back(*p);
      });
  ContactPairs pairs;
  for (const auto& buf : buffers) pairs.insert(pairs.end(), buf.begin(), buf.end());
  canonicalize(pairs);
  return pairs;
}

// ---------------------------------------------------------------------------
enum Method { Ours, Brute, Hash, Cgal };

void bench_search(benchmark::State& state, int kind, int size, Method method, int threads) {
  const Scene& sc = scene(kind, size);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  size_t candidates = 0, bytes = 0;
  for (auto _ : state) {
    const SweptBoxes boxes = swept_boxes(sc.surface, sc.x_old, sc.x_new);
    ContactPairs pairs;
    switch (method) {
      case Ours: {
        pairs = find_candidates(sc.surface, boxes);
        break;
      }
      case Brute:
        pairs = find_candidates_brute_force(sc.surface, boxes);
        break;
      case Hash:
        pairs = hash_grid_candidates(sc.surface, boxes, bytes);
        break;
      case Cgal:
        pairs = threads == 1 ? cgal_candidates<CGAL::Sequential_tag>(sc.surface, boxes, bytes)
                             : cgal_candidates<CGAL::Parallel_tag>(sc.surface, boxes, bytes);
        break;
    }
    candidates = pairs.size();
    benchmark::DoNotOptimize(pairs.data());
  }
  if (method == Ours || method == Brute) {
    const SweptBoxes boxes = swept_boxes(sc.surface, sc.x_old, sc.x_new);
    bytes = bytes_of(boxes) + (method == Ours ? memory_bytes(build_sparse_bucket(boxes.triangles)) +
                                                    memory_bytes(build_sparse_bucket(boxes.edges))
                                              : 0);
  }
  state.counters["triangles"] = static_cast<double>(sc.surface.num_triangles());
  state.counters["candidates"] = static_cast<double>(candidates);
  state.counters["cand_per_s"] = benchmark::Counter(static_cast<double>(candidates),
                                                    benchmark::Counter::kIsIterationInvariantRate);
  state.counters["bytes"] = static_cast<double>(bytes);
  state.counters["threads"] = threads;
}

const char* kKinds[] = {"bodies", "cubes", "fragments"};
const char* kMethods[] = {"sparse_bucket", "brute_force", "hash_grid", "cgal_box_intersection_d"};

void register_all() {
  // bodies: size = 1000 x element size; the others: target triangle count
  const std::vector<std::pair<int, std::vector<int>>> sizes = {
      {0, {250, 120}}, {1, {1000, 10000, 100000, 1000000}}, {2, {1000, 10000, 100000, 1000000}}};
  for (const auto& [kind, list] : sizes)
    for (int size : list)
      for (int method : {Ours, Brute, Hash, Cgal})
        for (int threads : {1, 2}) {
          const bool large = kind != 0 && size >= 100000;
          if (method == Brute && (threads == 2 || (kind != 0 && size > 10000))) continue;
          if (method == Cgal && threads == 2 && size >= 1000000)
            continue;  // its Parallel_tag does not help here
          const std::string name = std::string("contact_search/") + kKinds[kind] + "/" +
                                   std::to_string(size) + "/" + kMethods[method] +
                                   "/threads:" + std::to_string(threads);
          auto* b = benchmark::RegisterBenchmark(name.c_str(), bench_search, kind, size,
                                                 static_cast<Method>(method), threads)
                        ->Unit(benchmark::kMillisecond)
                        ->UseRealTime()
                        ->Repetitions(size >= 1000000 ? 1 : 3)
                        ->ReportAggregatesOnly(true);
          if (large) b->Iterations(1);
        }
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
