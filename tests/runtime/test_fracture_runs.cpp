// Whole runs with cohesive fracture: a ring expanding under a radial velocity
// field cracks and fragments. Splitting nodes keeps mass and momentum, the
// energy ledger (kinetic + strain + cohesive stored + dissipated) stays
// constant, and the run is bitwise identical for any thread count.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

#include "expect_close.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;

namespace {

const std::string kRing =
    "name: ring\n"
    "time: {end: 1.0}\n" +
    shatter::test::ring_aluminium() +
    "bodies:\n"
    "  - name: ring\n"
    "    material: alu\n"
    "    mesh: {shape: tube, inner_radius: 4.5e-3, outer_radius: 5.5e-3, length: 1.0e-3, element_size: 5.0e-4}\n"
    "    velocity_gradient: [[2.0e4, 0, 0], [0, 2.0e4, 0], [0, 0, 0]]\n";

struct RunResult {
  std::vector<Vec3> x;
  Ledger ledger, ledger0;
  double mass0 = 0, mass = 0, momentum_scale = 0;
  long fragments = 0;
  Index nodes0 = 0, nodes = 0;
};

RunResult run_ring(int threads, int steps) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  Model m = build_model(shatter::test::scene_from_text("ring", kRing));
  RunResult r;
  for (double mi : m.mass) r.mass0 += mi;
  r.nodes0 = m.mesh.num_nodes();
  Simulation sim(m, {});
  r.ledger0 = sim.ledger();
  for (Index i = 0; i < m.mesh.num_nodes(); ++i) r.momentum_scale += m.mass[i] * sim.velocities()[i].norm();
  for (int s = 0; s < steps; ++s) {
    sim.step();
    // The cached labels (renewed only when facets are freed) are a fresh labelling.
    if (s % 100 == 99) {
      EXPECT_EQ(sim.fracture()->fragment_labels().elem_fragment,
                label_fragments(m.mesh, sim.fracture()->topology()).elem_fragment)
          << "step " << s + 1;
    }
  }
  r.x.assign(sim.positions().begin(), sim.positions().end());
  r.ledger = sim.ledger();
  for (double mi : m.mass) r.mass += mi;
  r.nodes = m.mesh.num_nodes();
  r.fragments = sim.fracture()->fragments(sim.positions(), sim.velocities(), m.mass).count();
  return r;
}

}  // namespace

TEST(FractureRun, RingFragmentsConservingMassMomentumAndEnergy) {
  const RunResult r = run_ring(2, 800);
  EXPECT_GT(r.ledger.cohesive_elements, 100);
  EXPECT_GT(r.nodes, r.nodes0) << "no node was split";
  EXPECT_GT(r.fragments, 1);
  EXPECT_GT(r.ledger.cohesive_dissipated, 0.0);
  EXPECT_CLOSE(r.mass, r.mass0, 1e-13, 0);
  EXPECT_LT((r.ledger.momentum - r.ledger0.momentum).norm(), 1e-12 * r.momentum_scale);
  // Angular momentum is not exact: the equal and opposite cohesive tractions
  // act across the opening delta with torque delta x T, zero for the
  // Ortiz-Pandolfi law in tension with beta = 1 but not for the compression
  // penalty with shear (delta_n (k_p - t beta^2/delta) delta_s x n). Measured
  // here: 1e-6 of L-scale = sum m |v| r.
  EXPECT_LT((r.ledger.angular_momentum - r.ledger0.angular_momentum).norm(), 1e-5 * r.momentum_scale * 5.5e-3);
  // kinetic + strain + cohesive stored + dissipated stays within 1 % (issue 5)
  EXPECT_LT(std::abs(r.ledger.total() - r.ledger0.total()), 0.01 * r.ledger0.total())
      << "total " << r.ledger.total() << " from " << r.ledger0.total();
}

TEST(FractureRun, BitwiseIdenticalForThreads124) {
  const RunResult a = run_ring(1, 300), b = run_ring(2, 300), c = run_ring(4, 300);
  ASSERT_GT(a.nodes, a.nodes0) << "the ring must have split nodes for this test to mean something";
  for (const RunResult* o : {&b, &c}) {
    ASSERT_EQ(o->x.size(), a.x.size());
    EXPECT_EQ(0, std::memcmp(o->x.data(), a.x.data(), a.x.size() * sizeof(Vec3)));
    EXPECT_EQ(o->ledger.total(), a.ledger.total());
    EXPECT_EQ(o->ledger.cohesive_elements, a.ledger.cohesive_elements);
    EXPECT_EQ(o->fragments, a.fragments);
  }
}
