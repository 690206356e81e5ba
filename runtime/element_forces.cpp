#include "runtime/element_forces.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "kernels/tet10.hpp"
#include "kernels/tet4.hpp"

namespace shatter {
namespace {
// a is a worse volume ratio than b: NaN beats everything, then the smaller.
bool worse(double a, double b) { return std::isnan(a) ? !std::isnan(b) : a < b; }
}  // namespace

ElementForces::ElementForces(const Model& model) : model_(model) { rebuild(); }

void ElementForces::rebuild() {
  const Mesh& mesh = model_.mesh;
  const Index ne = mesh.num_elements();
  const int k = mesh.nodes_per_element();
  const Index nblocks = (ne + kBlock - 1) / kBlock;
  std::vector<Index> offsets(nblocks + 1, 0), nodes;
  nodes.reserve(static_cast<size_t>(ne) * k);
  for (Index b = 0; b < nblocks; ++b) {
    const size_t first = nodes.size();
    for (Index e = b * kBlock; e < std::min(ne, (b + 1) * kBlock); ++e)
      for (int a = 0; a < k; ++a) nodes.push_back(mesh.element(e)[a]);
    std::sort(nodes.begin() + first, nodes.end());
    nodes.erase(std::unique(nodes.begin() + first, nodes.end()), nodes.end());
    offsets[b + 1] = static_cast<Index>(nodes.size());
  }
  coloring_ = greedy_coloring(offsets, nodes, mesh.num_nodes());
  block_energy_.assign(nblocks, 0.0);
  block_dt_.assign(nblocks, HUGE_VAL);
  block_min_J_.assign(nblocks, HUGE_VAL);
  block_worst_.assign(nblocks, -1);
}

ElementLoopResult ElementForces::compute(std::span<const Vec3> x, std::span<Vec3> f_int,
                                         std::span<double> stress6) const {
  const Mesh& mesh = model_.mesh;
  const Index ne = mesh.num_elements();
  const Index* conn = mesh.conn.data();
  const int* mat = mesh.elem_material.data();
  const NeoHookean* mats = model_.materials.data();

  tbb::parallel_for(tbb::blocked_range<size_t>(0, f_int.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) f_int[i].setZero();
  });

  auto run_block = [&](Index b) {
    double energy = 0, dt = HUGE_VAL, minJ = HUGE_VAL;
    Index worst = -1;
    const Index end = std::min(ne, (b + 1) * kBlock);
    for (Index e = b * kBlock; e < end; ++e) {
      const NeoHookean& m = mats[mat[e]];
      double J, h;
      if (mesh.order == 1) {
        const Index* c = conn + 4 * static_cast<size_t>(e);
        const Vec3 &x0 = x[c[0]], &x1 = x[c[1]], &x2 = x[c[2]], &x3 = x[c[3]];
        const Tet4Force out = tet4_internal_force(x0, x1, x2, x3, model_.tet4_Dm_inv[e], model_.element_volume[e], m);
        for (int a = 0; a < 4; ++a) f_int[c[a]] += out.f.col(a);
        energy += out.energy;
        J = out.J;
        h = tet4_stable_length(x0, x1, x2, x3);
      } else {
        const Index* c = conn + 10 * static_cast<size_t>(e);
        Tet10Nodes xe;
        for (int a = 0; a < 10; ++a) xe.col(a) = x[c[a]];
        const Tet10Force out = tet10_internal_force(xe, model_.tet10_ref[e], m);
        for (int a = 0; a < 10; ++a) f_int[c[a]] += out.f.col(a);
        energy += out.energy;
        J = out.J;
        h = tet10_stable_length(x[c[0]], x[c[1]], x[c[2]], x[c[3]]);
      }
      if (!stress6.empty()) element_cauchy_stress6(model_, x, e, stress6.data() + 6 * static_cast<size_t>(e));
      // J <= 0 (or NaN) makes the wave speed NaN; the caller diagnoses it.
      dt = std::min(dt, h / m.wave_speed(J > 0 ? J : 1.0));
      if (worse(J, minJ)) {
        minJ = J;
        worst = e;
      }
    }
    block_energy_[b] = energy;
    block_dt_[b] = dt;
    block_min_J_[b] = minJ;
    block_worst_[b] = worst;
  };

  for (int c = 0; c < coloring_.num_colors(); ++c) {
    const auto items = coloring_.items_of(c);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, items.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) run_block(items[i]);
    });
  }

  ElementLoopResult res;
  for (size_t b = 0; b < block_energy_.size(); ++b) {
    res.strain_energy += block_energy_[b];
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
    for (int q = 0; q < 4; ++q) s += 0.25 * m.cauchy_stress(xe * model.tet10_ref[e].dNdX[q]);
  }
  o[0] = s(0, 0), o[1] = s(1, 1), o[2] = s(2, 2), o[3] = s(1, 2), o[4] = s(0, 2), o[5] = s(0, 1);
}

void element_stresses(const Model& model, std::span<const Vec3> x, std::vector<double>& stress6,
                      std::vector<double>& von_mises_out) {
  const Index ne = model.mesh.num_elements();
  stress6.resize(static_cast<size_t>(ne) * 6);
  von_mises_out.resize(ne);
  tbb::parallel_for(tbb::blocked_range<Index>(0, ne, 1024), [&](const tbb::blocked_range<Index>& r) {
    for (Index e = r.begin(); e < r.end(); ++e) {
      double* o = stress6.data() + 6 * static_cast<size_t>(e);
      element_cauchy_stress6(model, x, e, o);
      Mat3 s;
      s << o[0], o[5], o[4], o[5], o[1], o[3], o[4], o[3], o[2];
      von_mises_out[e] = von_mises(s);
    }
  });
}

}  // namespace shatter
