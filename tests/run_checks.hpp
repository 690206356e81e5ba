#pragma once
// Checks on a running Simulation shared by the whole-run tests: body motion,
// the independent penetration check (point in tetrahedron on the volume
// meshes, brute force, no DCR code involved) and the ledger's history.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstring>
#include <span>
#include <vector>

#include "runtime/contact_stage.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"

namespace shatter::test {

/// Same input, any thread count: the model of `scene` run `steps` steps with
/// 1, 2 and 4 threads gives the same positions and ledger total, bit for bit.
inline void expect_same_bits_for_threads(const Scene& scene, int steps) {
  std::vector<std::vector<Vec3>> results;
  std::vector<double> energies;
  for (int threads : {1, 2, 4}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Model m = build_model(scene);
    Simulation sim(m, {});
    for (int s = 0; s < steps; ++s) sim.step();
    results.emplace_back(sim.positions().begin(), sim.positions().end());
    energies.push_back(sim.ledger().total());
  }
  for (size_t k = 1; k < results.size(); ++k) {
    EXPECT_EQ(energies[k], energies[0]);
    ASSERT_EQ(results[k].size(), results[0].size());
    EXPECT_EQ(0, std::memcmp(results[k].data(), results[0].data(), results[0].size() * sizeof(Vec3)));
  }
}

/// Mass-weighted mean over the nodes of body b of a nodal array (positions, velocities).
inline Vec3 body_mean(const Simulation& sim, int b, std::span<const Vec3> field) {
  const Model& m = sim.model();
  Vec3 sum = Vec3::Zero();
  double mass = 0;
  for (Index i = 0; i < m.mesh.num_nodes(); ++i)
    if (m.mesh.node_body[i] == b) {
      sum += m.mass[i] * field[i];
      mass += m.mass[i];
    }
  return sum / mass;
}

/// Centre-of-mass velocity of body b, m/s.
inline Vec3 body_velocity(const Simulation& sim, int b) {
  return body_mean(sim, b, sim.velocities());
}

/// Centre of mass of body b, m.
inline Vec3 body_centre(const Simulation& sim, int b) {
  return body_mean(sim, b, sim.positions());
}

/// sum m |x| |v| over the nodes, kg m^2/s: the scale of the angular momentum about the
/// origin against which its changes are measured.
inline double angular_momentum_scale(const Simulation& sim) {
  const Model& m = sim.model();
  double scale = 0;
  for (Index i = 0; i < m.mesh.num_nodes(); ++i)
    scale += m.mass[i] * sim.positions()[i].norm() * sim.velocities()[i].norm();
  return scale;
}

/// The number of surface vertices of each body that lie inside a tetrahedron of another
/// body by more than `depth` times that tetrahedron's smallest altitude (all four
/// barycentric coordinates above `depth`). Brute force over the volume meshes (corner
/// nodes) with a bounding-box filter. The simulation must have a contact block.
inline int count_penetrations(const Simulation& sim, double depth = 1e-6) {
  const Model& m = sim.model();
  const Mesh& mesh = m.mesh;
  const auto x = sim.positions();
  const auto& vertices = sim.contact()->surface().vertices;
  int found = 0;
  for (Index e = 0; e < mesh.num_elements(); ++e) {
    const Index* t = mesh.element(e);
    const Vec3 &a = x[t[0]], &b = x[t[1]], &c = x[t[2]], &d = x[t[3]];
    const Vec3 lo = a.cwiseMin(b).cwiseMin(c).cwiseMin(d),
               hi = a.cwiseMax(b).cwiseMax(c).cwiseMax(d);
    Mat3 J;
    J.col(0) = b - a;
    J.col(1) = c - a;
    J.col(2) = d - a;
    const Mat3 J_inv = J.inverse();
    for (const Index v : vertices) {
      if (mesh.node_body[v] == mesh.elem_body[e]) continue;
      const Vec3& p = x[v];
      if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
      const Vec3 l = J_inv * (p - a);
      const double l0 = 1.0 - l.sum();
      if (std::min({l0, l.x(), l.y(), l.z()}) > depth) ++found;
    }
  }
  return found;
}

/// Succeeds when no value is below the one before it (a ledger column over the steps of a
/// run, e.g. contact_dissipated, SCENE.md); else names the first entry that is, and by how much.
inline ::testing::AssertionResult never_decreases(std::span<const double> values) {
  for (size_t k = 1; k < values.size(); ++k)
    if (values[k] < values[k - 1])
      return ::testing::AssertionFailure() << "entry " << k << " is " << values[k] << ", "
                                           << values[k - 1] - values[k] << " below the one before";
  return ::testing::AssertionSuccess();
}

}  // namespace shatter::test
