// Issue 19, done-when 1 (small version): an alumina bar (E 370 GPa, nu 0.22,
// rho 3900, sigma_c 300 MPa, Gc 43 J/m^2: delta_c = 0.29 um, cohesive zone
// E Gc / sigma_c^2 = 0.18 mm) at a 2 mm mesh, which the law with the elastic
// rise refused, is pulled apart from both ends at 4.5 m/s: the two tension
// waves (171 MPa each) meet at mid-length above the strength. It breaks into
// fragments, dissipates Gc x the debonded crack area within 10 %, and its
// energy ledger holds within 1 % of the external work. With Weibull scatter
// it breaks with the ledger held too, bitwise the same for 1 and 2 threads.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

#include "runtime/fracture_stage.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;

namespace {

constexpr double kGc = 43.0, kEnd = 8.0e-6;

std::string bar_scene(const std::string& scatter) {
  return "name: alumina_bar\n"
         "time: {end: 8.0e-6}\n"
         "materials:\n"
         "  alumina:\n"
         "    model: neo_hookean\n"
         "    density: 3900\n"
         "    youngs_modulus: 370.0e9\n"
         "    poisson_ratio: 0.22\n"
         "    fracture: {strength: 300.0e6, energy: 43.0, beta: 1.0" +
         scatter +
         "}\n"
         "bodies:\n"
         "  - name: bar\n"
         "    material: alumina\n"
         "    mesh: {shape: box, size: [0.04, 0.01, 0.01], center: [0, 0, 0], element_size: 0.002}\n"
         "boundary_conditions:\n"
         "  - {body: bar, region: {box: [[-0.021, -1, -1], [-0.0199, 1, 1]]}, velocity: [-4.5, null, null]}\n"
         "  - {body: bar, region: {box: [[0.0199, -1, -1], [0.021, 1, 1]]}, velocity: [4.5, null, null]}\n";
}

struct BarRun {
  Ledger ledger, ledger0;
  CrackArea crack;
  Index fragments = 0;
  std::vector<Vec3> x;
};

BarRun pull_bar(const std::string& scatter, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  Model m = build_model(shatter::test::scene_from_text("alumina_bar", bar_scene(scatter)));
  Simulation sim(m, {});
  BarRun r;
  r.ledger0 = sim.ledger();
  while (sim.time() < kEnd) sim.step();
  r.ledger = sim.ledger();
  const Fragments& frags = sim.fracture()->fragment_labels();
  r.fragments = frags.count();
  r.crack = sim.fracture()->crack_area(frags);
  r.x.assign(sim.positions().begin(), sim.positions().end());
  return r;
}

void expect_broken_with_the_ledger_held(const BarRun& r) {
  EXPECT_GE(r.fragments, 2);
  // A crack through the 10 mm x 10 mm section at least.
  EXPECT_GT(r.crack.between_fragments.value(), 1.0e-4);
  // The debonded facets dissipated Gc each; the partly opened ones add to it.
  EXPECT_GE(r.ledger.cohesive_dissipated, kGc * r.crack.debonded.value() * (1 - 1e-12));
  // The ledger within 1 % of the external work.
  ASSERT_GT(r.ledger.external_work, 0.0);
  EXPECT_LT(std::abs(r.ledger.total() - r.ledger0.total()), 0.01 * r.ledger.external_work)
      << "total " << r.ledger.total() << " from " << r.ledger0.total() << ", external work "
      << r.ledger.external_work;
}

}  // namespace

TEST(AluminaBar, BreaksDissipatingGcTimesAreaWithTheLedgerHeld) {
  const BarRun r = pull_bar("", 2);
  expect_broken_with_the_ledger_held(r);
  // Dissipated = Gc x debonded area within 10 % (measured 3.7 %; the rest
  // is in facets opened part of the way, still cohesive).
  EXPECT_LT(r.ledger.cohesive_dissipated, 1.10 * kGc * r.crack.debonded.value());
}

TEST(AluminaBar, WeibullScatterRunsAndIsBitwiseForThreads12) {
  const std::string weibull = ", scatter: {distribution: weibull, modulus: 8, seed: 3}";
  const BarRun a = pull_bar(weibull, 1), b = pull_bar(weibull, 2);
  // (Dissipated / (Gc x debonded area): 1.126 here, more facets open part
  // of the way; docs/validation.md.)
  expect_broken_with_the_ledger_held(a);
  ASSERT_EQ(a.x.size(), b.x.size());
  EXPECT_EQ(0, std::memcmp(a.x.data(), b.x.data(), a.x.size() * sizeof(Vec3)));
  EXPECT_EQ(a.ledger.total(), b.ledger.total());
  EXPECT_EQ(a.ledger.cohesive_elements, b.ledger.cohesive_elements);
  // Another seed is another set of strengths: another crack.
  const BarRun c = pull_bar(", scatter: {distribution: weibull, modulus: 8, seed: 4}", 2);
  EXPECT_NE(c.ledger.cohesive_elements, a.ledger.cohesive_elements);
}
