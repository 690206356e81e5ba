#include "runtime/element_forces.hpp"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_for_each.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "kernels/tet10.hpp"
#include "kernels/error.hpp"
#include "kernels/exact_sum.hpp"
#include "kernels/tet4.hpp"

namespace shatter {
namespace {
// Elements per lane group (TET4 and TET10): 8 doubles fill an AVX-512
// vector, two AVX2 or four SSE ones; 8 lanes measured faster than 4 at every
// width (more independent work per instruction, docs/performance.md "Whole step").
constexpr int kLanes = 8;
static_assert(ElementForces::kGranule % kLanes == 0);

// a is a worse volume ratio than b: NaN beats everything, then the smaller.
bool worse(double a, double b) { return std::isnan(a) ? !std::isnan(b) : a < b; }

// The N TET4 elements es[0..N) at positions x into the lanes, forces and
// det F computed.
template <int N>
void tet4_lanes(const Model& model, std::span<const Vec3> x, const Index* es, const NeoHookean& m, Tet4Lanes<N>& L) {
  for (int l = 0; l < N; ++l) {
    const Index* c = model.mesh.conn.data() + 4 * static_cast<size_t>(es[l]);
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) L.x[3 * a + i][l] = x[c[a]][i];
    const double* D = model.tet4_Dm_inv[es[l]].data();
    for (int q = 0; q < 9; ++q) L.Dm_inv[q][l] = D[q];
    L.V0[l] = model.element_volume[es[l]];
  }
  tet4_neo_hookean_lanes(L, m);
}

// The N TET10 elements es[0..N) at positions x into the lanes, forces, det F
// and the squared stable step computed.
template <int N>
void tet10_lanes(const Model& model, std::span<const Vec3> x, const Index* es, const NeoHookean& m,
                 Tet10Lanes<N>& L, double (&dt2)[N]) {
  for (int l = 0; l < N; ++l) {
    const Index* c = model.mesh.conn.data() + 10 * static_cast<size_t>(es[l]);
    for (int a = 0; a < 10; ++a)
      for (int i = 0; i < 3; ++i) L.x[3 * a + i][l] = x[c[a]][i];
    tet10_reference_into_lanes(model.tet10_ref[es[l]], L, l);
  }
  tet10_neo_hookean_lanes(L, m);
  tet10_stable_dt_squared_lanes(L, m, dt2);
}
}  // namespace

ElementStep element_stable_step(const Model& model, std::span<const Vec3> x, Index e) {
  ElementStep r;
  if (model.mesh.order == 1) {
    Tet4Lanes<1> L;
    tet4_lanes<1>(model, x, &e, model.materials[model.mesh.elem_material[e]], L);
    double dt2[1];
    tet4_stable_dt_squared_lanes(L, model.materials[model.mesh.elem_material[e]], dt2);
    r.dt = std::sqrt(dt2[0]);
    r.J = L.J[0];
  } else {
    Tet10Lanes<1> L;
    double dt2[1];
    tet10_lanes<1>(model, x, &e, model.materials[model.mesh.elem_material[e]], L, dt2);
    r.dt = std::sqrt(dt2[0]);
    r.J = L.J[0];
  }
  return r;
}

ElementForces::ElementForces(const Model& model) : model_(model) { rebuild(); }

std::vector<int> block_colors(const Mesh& mesh) {
  const Index ne = mesh.num_elements();
  const int k = mesh.nodes_per_element();
  const Index nblocks = (ne + ElementForces::kBlock - 1) / ElementForces::kBlock;
  std::vector<Index> offsets(nblocks + 1, 0), nodes;
  nodes.reserve(static_cast<size_t>(ne) * k);
  for (Index b = 0; b < nblocks; ++b) {
    const size_t first = nodes.size();
    for (Index e = b * ElementForces::kBlock; e < std::min(ne, (b + 1) * ElementForces::kBlock); ++e)
      for (int a = 0; a < k; ++a) nodes.push_back(mesh.element(e)[a]);
    std::sort(nodes.begin() + first, nodes.end());
    nodes.erase(std::unique(nodes.begin() + first, nodes.end()), nodes.end());
    offsets[b + 1] = static_cast<Index>(nodes.size());
  }
  return greedy_coloring(offsets, nodes, mesh.num_nodes()).color;
}

void ElementForces::rebuild() {
  const Index ne = model_.mesh.num_elements();
  // The whole model's blocks and granules that hold elements here (all of
  // them on the whole model), ascending.
  blocks_.clear();
  granules_.clear();
  for (Index e = 0; e < ne; ++e) {
    const Index w = model_.whole_element(e);
    if (blocks_.empty() || blocks_.back() != w / kBlock) blocks_.push_back(w / kBlock);
    if (granules_.empty() || granules_.back() != w / kGranule) granules_.push_back(w / kGranule);
  }
  const Index nblocks = static_cast<Index>(blocks_.size());
  coloring_ = coloring_from(model_.is_part() ? model_.part.block_color : block_colors(model_.mesh));
  SHATTER_REQUIRE(static_cast<Index>(coloring_.color.size()) == nblocks,
                  "ElementForces: " << coloring_.color.size() << " block colors for " << nblocks << " blocks");
  granule_energy_.assign(granules_.size(), 0.0);
  block_dt_.assign(nblocks, HUGE_VAL);
  block_min_J_.assign(nblocks, HUGE_VAL);
  block_worst_.assign(nblocks, -1);
  // Every element, block by block, until restrict_to().
  std::vector<Index> all(ne);
  for (Index e = 0; e < ne; ++e) all[e] = e;
  set_subset(all);
  zero_nodes_.clear();
  split_phases(std::vector<char>(nblocks, 0));
}

Index ElementForces::block_of(Index e) const {
  return static_cast<Index>(std::lower_bound(blocks_.begin(), blocks_.end(), model_.whole_element(e) / kBlock) -
                            blocks_.begin());
}

double ElementForces::granule_energy(Index granule) const {
  const auto it = std::lower_bound(granules_.begin(), granules_.end(), granule);
  return it != granules_.end() && *it == granule ? granule_energy_[it - granules_.begin()] : 0.0;
}

void ElementForces::set_subset(std::span<const Index> elements) {
  const Index nblocks = static_cast<Index>(blocks_.size());
  // Rigid bodies' elements are never computed: their forces are 0 (runtime/rigid_bodies.hpp).
  const std::vector<BodySpec>& bodies = model_.scene.bodies;
  auto rigid = [&](Index e) {
    const int b = model_.mesh.elem_body[e];
    return b >= 0 && static_cast<size_t>(b) < bodies.size() && bodies[b].any_rigid();
  };
  subset_.clear();
  for (const Index e : elements)
    if (!rigid(e)) subset_.push_back(e);
  subset_offsets_.assign(nblocks + 1, 0);
  for (Index e : subset_) ++subset_offsets_[block_of(e) + 1];
  for (Index b = 0; b < nblocks; ++b) subset_offsets_[b + 1] += subset_offsets_[b];
}

void ElementForces::split_phases(const std::vector<char>& late) {
  for (int p = 0; p < 2; ++p) phase_items_[p].clear();
  for (int c = 0; c < coloring_.num_colors(); ++c)
    for (const Index b : coloring_.items_of(c)) phase_items_[late[b] ? 1 : 0].push_back(b);
  // Each phase's graph: walking its blocks in color order, a block follows the last block
  // that touched each of its nodes (blocks of one color share no node).
  const Mesh& mesh = model_.mesh;
  const int k = mesh.nodes_per_element();
  for (int p = 0; p < 2; ++p) {
    std::vector<Index> last(mesh.num_nodes(), -1);
    const std::vector<Index>& items = phase_items_[p];
    const Index n = static_cast<Index>(items.size());
    std::vector<std::vector<Index>> after(n);
    std::vector<Index> seen(n, -1);
    BlockGraph& g = graphs_[p];
    g = {};
    g.waits.assign(n, 0);
    for (Index i = 0; i < n; ++i) {
      const Index b = items[i];
      for (Index j = subset_offsets_[b]; j < subset_offsets_[b + 1]; ++j)
        for (int a = 0; a < k; ++a) {
          Index& before = last[mesh.element(subset_[j])[a]];
          if (before >= 0 && before != i && seen[before] != i) seen[before] = i, after[before].push_back(i), ++g.waits[i];
          before = i;
        }
    }
    g.successor_offsets.assign(1, 0);
    for (Index i = 0; i < n; ++i) {
      if (g.waits[i] == 0) g.first.push_back(i);
      g.successors.insert(g.successors.end(), after[i].begin(), after[i].end());
      g.successor_offsets.push_back(static_cast<Index>(g.successors.size()));
    }
  }
}

void ElementForces::restrict_to(std::span<const Index> elements, std::span<const Index> nodes,
                                std::span<const Index> late_nodes) {
  const Index nblocks = static_cast<Index>(block_dt_.size());
  SHATTER_REQUIRE(!nodes.empty() || elements.empty(), "ElementForces::restrict_to: elements without nodes");
  set_subset(elements);
  zero_nodes_.assign(nodes.begin(), nodes.end());

  // Late blocks: those reading a late node, then closed under the color order.
  const Mesh& mesh = model_.mesh;
  const int k = mesh.nodes_per_element();
  auto for_nodes = [&](Index b, auto f) {
    for (Index i = subset_offsets_[b]; i < subset_offsets_[b + 1]; ++i)
      for (int a = 0; a < k; ++a)
        if (f(mesh.element(subset_[i])[a])) return true;
    return false;
  };
  std::vector<char> late_node(mesh.num_nodes(), 0), late(nblocks, 0);
  for (Index n : late_nodes) late_node[n] = 1;
  for (Index b = 0; b < nblocks; ++b) late[b] = for_nodes(b, [&](Index n) { return late_node[n] != 0; });
  std::vector<int> min_late_color(mesh.num_nodes());
  for (bool changed = true; changed;) {
    std::fill(min_late_color.begin(), min_late_color.end(), coloring_.num_colors());
    for (Index b = 0; b < nblocks; ++b)
      if (late[b])
        for_nodes(b, [&](Index n) {
          min_late_color[n] = std::min(min_late_color[n], coloring_.color[b]);
          return false;
        });
    changed = false;
    for (Index b = 0; b < nblocks; ++b)
      if (!late[b] && for_nodes(b, [&](Index n) { return min_late_color[n] < coloring_.color[b]; }))
        late[b] = changed = true;
  }
  split_phases(late);
}

ElementLoopResult ElementForces::compute(std::span<const Vec3> x, std::span<Vec3> f_int, std::span<double> stress6,
                                         const std::function<void()>& between) const {
  const Mesh& mesh = model_.mesh;
  const Index* conn = mesh.conn.data();
  const int* mat = mesh.elem_material.data();
  const NeoHookean* mats = model_.materials.data();

  const bool restricted = !zero_nodes_.empty();
  const size_t nzero = restricted ? zero_nodes_.size() : f_int.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nzero, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) f_int[restricted ? zero_nodes_[i] : i].setZero();
  });

  // kLanes consecutive elements of one material go through the lane kernel
  // together (vectorised across elements); the rest one at a time through
  // the same code with one lane, so the forces are the same bits.
  auto tet4_group = [&]<int N>(const Index* es, const NeoHookean& m, double& energy, double& dt2, double& minJ,
                               Index& worst) {
    Tet4Lanes<N> L;
    tet4_lanes<N>(model_, x, es, m, L);
    double lane_dt2[N];
    tet4_stable_dt_squared_lanes(L, m, lane_dt2);
    for (int l = 0; l < N; ++l) {
      const Index* c = conn + 4 * static_cast<size_t>(es[l]);
      for (int a = 0; a < 4; ++a) f_int[c[a]] += Vec3(L.f[3 * a][l], L.f[3 * a + 1][l], L.f[3 * a + 2][l]);
      energy += L.energy[l];
      dt2 = std::min(dt2, lane_dt2[l]);
      if (worse(L.J[l], minJ)) {
        minJ = L.J[l];
        worst = es[l];
      }
    }
  };

  auto tet10_group = [&]<int N>(const Index* es, const NeoHookean& m, double& energy, double& dt2, double& minJ,
                                Index& worst) {
    Tet10Lanes<N> L;
    double lane_dt2[N];
    tet10_lanes<N>(model_, x, es, m, L, lane_dt2);
    for (int l = 0; l < N; ++l) {
      const Index* c = conn + 10 * static_cast<size_t>(es[l]);
      for (int a = 0; a < 10; ++a) f_int[c[a]] += Vec3(L.f[3 * a][l], L.f[3 * a + 1][l], L.f[3 * a + 2][l]);
      energy += L.energy[l];
      dt2 = std::min(dt2, lane_dt2[l]);
      if (worse(L.J[l], minJ)) {
        minJ = L.J[l];
        worst = es[l];
      }
    }
  };

  auto run_block = [&](Index b) {
    const Index* first = subset_.data() + subset_offsets_[b];
    const Index* last = subset_.data() + subset_offsets_[b + 1];
    double dt2 = HUGE_VAL, minJ = HUGE_VAL;
    Index worst = -1;
    // One granule at a time: its energy is summed on its own.
    for (const Index* g0 = first; g0 < last;) {
      const Index granule = model_.whole_element(*g0) / kGranule;
      const Index* g1 = g0;
      while (g1 < last && model_.whole_element(*g1) / kGranule == granule) ++g1;
      double energy = 0;
      for (const Index* e = g0; e < g1;) {
        const int m = mat[*e];
        const bool group =
            g1 - e >= kLanes && std::all_of(e + 1, e + kLanes, [&](Index o) { return mat[o] == m; });
        if (mesh.order == 1 && group)
          tet4_group.template operator()<kLanes>(e, mats[m], energy, dt2, minJ, worst);
        else if (mesh.order == 1)
          tet4_group.template operator()<1>(e, mats[m], energy, dt2, minJ, worst);
        else if (group)
          tet10_group.template operator()<kLanes>(e, mats[m], energy, dt2, minJ, worst);
        else
          tet10_group.template operator()<1>(e, mats[m], energy, dt2, minJ, worst);
        e += group ? kLanes : 1;
      }
      granule_energy_[std::lower_bound(granules_.begin(), granules_.end(), granule) - granules_.begin()] = energy;
      g0 = g1;
    }
    const double dt = std::sqrt(dt2);  // sqrt is monotone: sqrt(min dt^2) = min dt
    if (!stress6.empty())
      for (const Index* e = first; e < last; ++e)
        element_cauchy_stress6(model_, x, *e, stress6.data() + 6 * static_cast<size_t>(*e));
    block_dt_[b] = dt;
    block_min_J_[b] = minJ;
    block_worst_[b] = worst;
  };

  const bool one_thread =
      std::min<std::size_t>(tbb::this_task_arena::max_concurrency(),
                            tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)) == 1;
  for (int p = 0; p < 2; ++p) {
    if (p == 1 && between) between();
    const std::vector<Index>& items = phase_items_[p];
    if (one_thread) {
      for (const Index b : items) run_block(b);  // color order
      continue;
    }
    // A block runs when its predecessors have (their counts reset each step).
    const BlockGraph& g = graphs_[p];
    std::vector<std::atomic<int>> waiting(items.size());
    for (size_t i = 0; i < items.size(); ++i) waiting[i].store(g.waits[i], std::memory_order_relaxed);
    tbb::parallel_for_each(g.first.begin(), g.first.end(), [&](Index i, tbb::feeder<Index>& feeder) {
      run_block(items[i]);
      for (Index s = g.successor_offsets[i]; s < g.successor_offsets[i + 1]; ++s)
        if (waiting[g.successors[s]].fetch_sub(1, std::memory_order_acq_rel) == 1) feeder.add(g.successors[s]);
    });
  }

  ElementLoopResult res;
  ExactSum energy;
  for (double e : granule_energy_) energy += e;
  res.strain_energy = energy.value();
  for (size_t b = 0; b < block_dt_.size(); ++b) {
    res.stable_dt = std::min(res.stable_dt, block_dt_[b]);
    if (worse(block_min_J_[b], res.min_jacobian)) {
      res.min_jacobian = block_min_J_[b];
      res.worst_element = block_worst_[b];
    }
  }
  return res;
}

void element_cauchy_stress6(const Model& model, std::span<const Vec3> x, Index e, double* o) {
  const Mesh& mesh = model.mesh;
  const NeoHookean& m = model.materials[mesh.elem_material[e]];
  const Index* c = mesh.element(e);
  Mat3 s = Mat3::Zero();
  if (mesh.order == 1) {
    s = m.cauchy_stress(tet4_deformation_gradient(x[c[0]], x[c[1]], x[c[2]], x[c[3]], model.tet4_Dm_inv[e]));
  } else {
    Tet10Nodes xe;
    for (int a = 0; a < 10; ++a) xe.col(a) = x[c[a]];
    for (int q = 0; q < 4; ++q) s += 0.25 * m.cauchy_stress(xe * tet10_gradients(model.tet10_ref[e], q));
  }
  o[0] = s(0, 0), o[1] = s(1, 1), o[2] = s(2, 2), o[3] = s(1, 2), o[4] = s(0, 2), o[5] = s(0, 1);
}


}  // namespace shatter
