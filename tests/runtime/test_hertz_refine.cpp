// bodies[i].mesh.refine through the runtime (issue 18): the key reaches the
// shape and the restart's physics keys; Hertz impact of two steel spheres
// with the contact point refined: the contact duration and peak force
// against Hertz's quasi-static solution (Johnson, Contact Mechanics, 1985,
// ch. 4 and 11), on a mesh a uniform version of which misses
// the duration by a quarter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "run_checks.hpp"
#include "runtime/model.hpp"
#include "runtime/scene_keys.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;
using shatter::test::body_velocity;
using shatter::test::num;
using shatter::test::scene_from_text;

namespace {

}  // namespace

TEST(RefineKey, ReachesTheShapeAndThePhysicsKeys) {
  const Scene s = scene_from_text(
      "refine_key", "name: refine_key\ntime: {end: 1.0e-6}\nmaterials:\n"
                    "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
                    "bodies:\n  - name: b\n    material: steel\n"
                    "    mesh: {shape: box, size: [0.01, 0.01, 0.01], element_size: 0.005, refine: "
                    "[{center: [0.005, 0, 0], radius: 0.002, element_size: 0.001}, "
                    "{center: [-0.005, 0, 0], radius: 0.003, element_size: 0.005}]}\n");
  const std::vector<RefineSpec>& r = s.bodies[0].shape.refine;
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].center, Vec3(0.005, 0, 0));
  EXPECT_EQ(r[0].radius, 0.002);
  EXPECT_EQ(r[0].element_size, 0.001);
  EXPECT_EQ(r[1].center, Vec3(-0.005, 0, 0));
  EXPECT_EQ(r[1].radius, 0.003);
  EXPECT_EQ(r[1].element_size, 0.005);  // equal to the body's: allowed
  const std::string keys = physics_keys(s);
  EXPECT_NE(keys.find("bodies[0].mesh.refine[1].radius=0.003\n"), std::string::npos) << keys;
  Scene other = s;
  other.bodies[0].shape.refine[0].element_size = 0.002;
  EXPECT_EQ(first_difference(keys, physics_keys(other)).key, "bodies[0].mesh.refine[0].element_size");
}

// Spheres R = 5 mm at +-25 m/s (approach v = 50 m/s), frictionless, e = 1,
// TET4 of 1.4 mm refined to 0.25 mm within 1 mm of the contact point
// (Hertz contact radius 0.76 mm: 3 elements across it). Hertz with the meshed
// spheres' mass m: t_c = 2.87 (m*^2 / (R* E*^2 v))^(1/5), F_max = 4/3 E*
// sqrt(R*) d^(3/2), d = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5), m* = m / 2,
// R* = R / 2, E* = E / (2 (1 - nu^2)).
// The tolerances are measured, not Hertz's: at 50 m/s the mesh-converged DCR
// answer is 5.1 % short and 6.1 % strong (TET10 refined to 0.4 mm and TET4 to
// 0.1 mm agree to 0.1 %; docs/contact.md "Hertz with local refinement"),
// Hertz's linear theory being off at a peak pressure of E / 9; this mesh adds
// its own error, -3.2 and +3.2 points (measured -8.3 % and +9.3 %). The
// bounds, 10 % and 12 %, leave 1.7 and 2.7 points for a Gmsh that meshes the
// rest of the spheres differently; the uniform 1.4 mm mesh (-25.6 %, +14.8 %,
// bench/hertz_refine.py) fails both.
TEST(HertzRefine, RefinedContactPointGivesTheConvergedDuration) {
  const double R = 5e-3, v = 50, gap = 2e-5, E = 210e9, nu = 0.3;
  const std::string refine = "refine: [{center: [0, 0, 0], radius: 1.0e-3, element_size: 2.5e-4}]";
  auto sphere = [&](const char* name, double x, double vx) {
    return std::string("  - {name: ") + name + ", material: steel, mesh: {shape: sphere, radius: " + num(R) +
           ", center: [" + num(x) + ", 0, 0], element_size: 1.4e-3, " + refine + "}, initial_velocity: [" +
           num(vx) + ", 0, 0]}\n";
  };
  Model m = build_model(scene_from_text(
      "hertz_refine", "name: hertz_refine\ntime: {end: 1.0}\nmaterials:\n"
                      "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
                      "bodies:\n" + sphere("left", -R - gap / 2, v / 2) + sphere("right", R + gap / 2, -v / 2) +
                      "contact: {friction: 0.0, restitution: 1.0}\n"));
  const double ms = m.body_mass[0] / 2, Rs = R / 2, Es = E / (2 * (1 - nu * nu));
  const double t_hertz = 2.87 * std::pow(ms * ms / (Rs * Es * Es * v), 0.2);
  const double d_max = std::pow(15 * ms * v * v / (16 * Es * std::sqrt(Rs)), 0.4);
  const double f_hertz = 4.0 / 3.0 * Es * std::sqrt(Rs) * std::pow(d_max, 1.5);
  Simulation sim(m, {});
  std::vector<double> t{sim.time()}, u{body_velocity(sim, 0).x()};
  double t_first = -1, t_last = -1;
  while (sim.time() < gap / v + 1.3 * t_hertz) {
    sim.step();
    t.push_back(sim.time());
    u.push_back(body_velocity(sim, 0).x());
    if (sim.ledger().contacts > 0) {
      if (t_first < 0) t_first = sim.time();
      t_last = sim.time();
    }
  }
  ASSERT_GT(t_first, 0.0) << "the spheres never touched";
  // Peak force: the secant slope of the left sphere's velocity over t_c / 50
  // (it lowers a half-sine's peak by (pi / 50)^2 / 24 = 2e-4).
  const double half = t_hertz / 100;
  double f_peak = 0;
  for (std::size_t i = 0, j = 0, k = 0; i < t.size(); ++i) {
    if (t[i] - half < t.front() || t[i] + half > t.back()) continue;
    while (t[j] < t[i] - half) ++j;
    k = std::max(k, j);
    while (t[k] < t[i] + half) ++k;
    f_peak = std::max(f_peak, std::abs(m.body_mass[0] * (u[k] - u[j]) / (t[k] - t[j])));
  }
  const double duration_error = (t_last - t_first) / t_hertz - 1, force_error = f_peak / f_hertz - 1;
  std::printf("refined Hertz: %d elements, %ld steps, duration %.4e s (Hertz %.4e, %+.2f %%), peak force %.4e N "
              "(Hertz %.4e, %+.2f %%)\n", static_cast<int>(m.mesh.num_elements()), sim.steps(),
              t_last - t_first, t_hertz, 100 * duration_error, f_peak, f_hertz, 100 * force_error);
  EXPECT_LT(std::abs(duration_error), 0.10);
  EXPECT_LT(std::abs(force_error), 0.12);
}
