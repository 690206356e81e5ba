// The explicit solver against invariants and analytic solutions:
// lumped mass, affine patch test, free rigid motion, a dilatational wave, and
// bitwise determinism across thread counts.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "expect_close.hpp"
#include "run_checks.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;
using shatter::test::scene_from_text;

namespace {

std::string body_scene(const std::string& name, const std::string& shape, int order, const std::string& extra_body,
                       const std::string& extra = "") {
  return shatter::test::steel_body_scene(name, shape + ", order: " + std::to_string(order), extra_body, extra);
}

}  // namespace

TEST(Model, LumpedMassSumsToRhoV) {
  for (int order : {1, 2}) {
    Model m = build_model(scene_from_text(
        "mass", body_scene("mass", "shape: cylinder, radius: 0.01, length: 0.05, element_size: 0.006", order, "")));
    double total = 0, volume = 0;
    for (double mi : m.mass) {
      EXPECT_GT(mi, 0.0);
      total += mi;
    }
    for (double v : m.element_volume) volume += v;
    EXPECT_CLOSE(total, 7850 * volume, 1e-13, 0) << "order " << order;
    EXPECT_CLOSE(m.body_mass[0], total, 1e-13, 0);
  }
}

// summary.json mesh_time: the start-up's meshing, timed inside the model's build.
TEST(Model, MeshTimeIsPartOfTheBuild) {
  const Scene scene = scene_from_text(
      "mesh_time", body_scene("mesh_time", "shape: cylinder, radius: 0.01, length: 0.05, element_size: 0.004", 1, ""));
  const auto t0 = std::chrono::steady_clock::now();
  const Model m = build_model(scene);
  const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GT(m.mesh_seconds, 0.0);
  EXPECT_LT(m.mesh_seconds, build);
}

// Affine patch test: every boundary node driven with v = L X (constant), the
// interior nodes, free, follow x = (I + t L) X to round-off, because a uniform
// stress gives zero net force on every interior node.
TEST(Simulation, AffinePatchTestIsReproducedToRoundOff) {
  for (int order : {1, 2}) {
    Model m = build_model(scene_from_text(
        "patch", body_scene("patch", "shape: box, size: [0.02, 0.02, 0.02], element_size: " + std::string(order == 1 ? "0.003" : "0.006"), order, "")));
    Mat3 L;
    L << 30, 10, -5, 0, -20, 8, 4, 6, 15;  // 1/s
    const Vec3 v0(1.0, -2.0, 0.5);
    std::vector<char> interior(m.mesh.num_nodes(), 1);
    m.scene.boundary_conditions.emplace_back();  // a constant velocity, per node below
    for (Index i = 0; i < m.mesh.num_nodes(); ++i) {
      const Vec3& X = m.mesh.reference[i];
      if ((X.cwiseAbs().array() > 0.01 - 1e-9).any()) interior[i] = 0;
      m.initial_velocity[i] = v0 + L * X;
      if (!interior[i]) {
        m.bc_mask[i] = 7;
        m.bc_velocity[i] = v0 + L * X;
        m.bc_condition[i] = {0, 0, 0};
      }
    }
    Simulation sim(m, {});
    for (int s = 0; s < 200; ++s) sim.step();
    const double t = sim.time();
    double err = 0, scale = 0;
    int n_interior = 0;
    for (Index i = 0; i < m.mesh.num_nodes(); ++i) {
      if (!interior[i]) continue;
      ++n_interior;
      const Vec3& X = m.mesh.reference[i];
      const Vec3 exact = X + t * (v0 + L * X);
      err = std::max(err, (sim.positions()[i] - exact).norm());
      scale = std::max(scale, (exact - X).norm());
    }
    ASSERT_GT(n_interior, 50);
    EXPECT_LT(err, 1e-9 * scale) << "order " << order << ": max error " << err << " over displacement " << scale;
  }
}

// A free body translating and spinning: linear and angular momentum are
// conserved to round-off and the energy drifts by < 1e-4 of the kinetic
// energy over 10^4 steps.
TEST(Simulation, FreeSpinningBodyConservesMomentaAndEnergy) {
  Model m = build_model(scene_from_text(
      "spin", body_scene("spin", "shape: box, size: [0.03, 0.02, 0.01], element_size: 0.006", 1,
                         "    initial_velocity: [3, -1, 2]\n    angular_velocity: [200, 500, -300]\n")));
  Simulation sim(m, {});
  const Ledger l0 = sim.ledger();
  const double p_scale = l0.momentum.norm();
  double L_scale = 0;
  for (Index i = 0; i < m.mesh.num_nodes(); ++i)
    L_scale += m.mass[i] * sim.positions()[i].norm() * sim.velocities()[i].norm();
  for (int s = 0; s < 10000; ++s) sim.step();
  ASSERT_GT(sim.time(), 9999 * 0.5 * sim.dt());
  const Ledger& l = sim.ledger();
  EXPECT_LT((l.momentum - l0.momentum).norm(), 1e-12 * p_scale);
  EXPECT_LT((l.angular_momentum - l0.angular_momentum).norm(), 1e-11 * L_scale);
  EXPECT_LT(std::abs(l.total() - l0.total()), 1e-4 * l0.kinetic)
      << "drift " << (l.total() - l0.total()) / l0.kinetic << " of the kinetic energy";
}

// One-dimensional strain wave: a bar with its lateral faces held (no lateral
// motion) and one end driven at v0 carries a front at the dilatational speed
// c = sqrt((lambda + 2 mu) / rho) with stress rho c v0 behind it.
TEST(Simulation, DilatationalWaveSpeedAndStress) {
  const double v0 = 5.0, len = 0.1;
  const std::string lateral =
      "boundary_conditions:\n"
      "  - {body: b, region: {box: [[-1, -1, -1], [1.0e-9, 1, 1]]}, velocity: [5.0, 0, 0]}\n"
      "  - {body: b, region: {box: [[-1, -1, -1], [1, -0.002999, 1]]}, velocity: [null, 0, null]}\n"
      "  - {body: b, region: {box: [[-1, 0.002999, -1], [1, 1, 1]]}, velocity: [null, 0, null]}\n"
      "  - {body: b, region: {box: [[-1, -1, -1], [1, 1, -0.002999]]}, velocity: [null, null, 0]}\n"
      "  - {body: b, region: {box: [[-1, -1, 0.002999], [1, 1, 1]]}, velocity: [null, null, 0]}\n";
  Model m = build_model(scene_from_text(
      "wave", body_scene("wave", "shape: box, size: [0.1, 0.006, 0.006], center: [0.05, 0, 0], element_size: 0.0015",
                         1, "", lateral)));
  const NeoHookean& mat = m.materials[0];
  const double c = mat.wave_speed();
  Simulation sim(m, {});
  while (sim.time() < 0.7 * len / c) sim.step();
  const double t = sim.time();
  // Front: where the velocity has risen to half of v0, located by linear
  // interpolation of the nodal velocities binned along x.
  const int bins = 200;
  std::vector<double> sum(bins, 0), cnt(bins, 0);
  for (Index i = 0; i < m.mesh.num_nodes(); ++i) {
    const int b = std::min(bins - 1, static_cast<int>(m.mesh.reference[i].x() / len * bins));
    sum[b] += sim.velocities()[i].x();
    cnt[b] += 1;
  }
  double front = -1;
  for (int b = bins - 1; b > 0; --b) {
    if (cnt[b] == 0 || cnt[b - 1] == 0) continue;
    const double hi = sum[b - 1] / cnt[b - 1], lo = sum[b] / cnt[b];
    if (hi >= 0.5 * v0 && lo < 0.5 * v0) {
      front = (b - 1 + 0.5 + (hi - 0.5 * v0) / (hi - lo)) * len / bins;
      break;
    }
  }
  EXPECT_CLOSE(front / t, c, 0.02, 0) << "front at " << front << " m after " << t << " s";
  // Stress behind the front: mean sigma_xx over elements with centroid in
  // [0.2, 0.8] x front.
  double sxx = 0;
  int n = 0;
  for (Index e = 0; e < m.mesh.num_elements(); ++e) {
    double cx = 0;
    for (int a = 0; a < 4; ++a) cx += 0.25 * m.mesh.reference[m.mesh.element(e)[a]].x();
    if (cx > 0.2 * front && cx < 0.8 * front) {
      double s6[6];
      element_cauchy_stress6(m, sim.positions(), e, s6);
      sxx += s6[0];
      ++n;
    }
  }
  EXPECT_CLOSE(-sxx / n, mat.density * c * v0, 0.03, 0);
}

// Same input, any thread count: the same bits.
TEST(Simulation, BitwiseIdenticalForThreads124) {
  shatter::test::expect_same_bits_for_threads(
      scene_from_text("det", body_scene("det", "shape: cylinder, radius: 0.01, length: 0.04, element_size: 0.003", 1,
                                        "    initial_velocity: [3, -1, 2]\n"
                                        "    velocity_gradient: [[300, 50, 0], [0, -200, 80], [10, 0, 100]]\n"
                                        "    angular_velocity: [200, 500, -300]\n")),
      100);
}

// The step controller (StepControl, docs/physics.md "Step control"): never above
// the safe step; constant while the safe step vibrates within the headroom; down
// to the headroom below a safe step that fell under it; up by at most kGrowth,
// once per kWindow steps, only after the safe step stayed clear of it.
TEST(StepControl, HoldsTheStepAndChangesItRarely) {
  using C = StepControl;
  C c;
  EXPECT_EQ(c.next(1.0), 1.0);  // the first step is the safe step
  // A safe step vibrating by 4 % above the step does not move it.
  for (int k = 0; k < 10 * C::kWindow; ++k) ASSERT_EQ(c.next(1.02 + 0.02 * std::sin(0.7 * k)), 1.0);
  // Below it: down to the headroom, then held while the vibration stays above.
  EXPECT_EQ(c.next(0.9), C::kHeadroom * 0.9);
  const double held = c.dt;
  for (int k = 0; k < 10 * C::kWindow; ++k)
    ASSERT_EQ(c.next(k % 7 == 0 ? 0.9 : 0.9 + 0.04 * std::abs(std::sin(0.7 * k))), held);
  // A safe step well above: kGrowth once per window, capped at the headroom.
  int changes = 0;
  double dt = held;
  for (int k = 1; k <= 20 * C::kWindow; ++k) {
    const double next = c.next(2.0);
    if (next != dt) {
      ++changes;
      EXPECT_EQ(k % C::kWindow, 0) << "step " << k;
      EXPECT_LE(next, C::kGrowth * dt * (1 + 1e-15));
    }
    dt = next;
  }
  EXPECT_EQ(dt, C::kHeadroom * 2.0);
  EXPECT_EQ(changes, 9);  // 0.855 x 1.1^8 = 1.83 < 1.9 = 0.95 x 2
  // Whatever the safe step does, the step taken is never above it and grows at
  // most once per window: a vibration of up to 30 % (slowly modulated, on a
  // drift) makes 34 rises and 52 drops in 1e5 steps.
  C d;
  int rises = 0, drops = 0;
  dt = 0;
  for (int k = 0; k < 100000; ++k) {
    const double safe = (1.0 - 2e-6 * k) * (1.0 + 0.3 * std::sin(0.9 * k) * std::sin(1e-3 * k));
    const double next = d.next(safe);
    ASSERT_LE(next, safe) << "step " << k;
    rises += k > 0 && next > dt;
    drops += next < dt;
    dt = next;
  }
  EXPECT_LE(rises, 100000 / C::kWindow);
  EXPECT_LT(drops, 100);
}
