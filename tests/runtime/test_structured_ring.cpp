// Issue 19, done-when 2 (small version): the expanding ring at 1e5 /s on a
// structured mesh whose radial planes are facets (bench/ring_mesh.py, written
// at test time), with a uniform +-5 % strength scatter, as in
// docs/validation.md "The ring on structured meshes: flat cracks" but on a
// ring of half the radius (R = 2.5 mm, a = 0.1 mm, h = 50 um: 7536 tets).
// It breaks into fragments whose mean size is that of Zhou, Molinari & Ramesh
// (ZMR) within the band the study measured, its cracks are flat (a^2 of
// crack per crack), and its energy ledger closes.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>

#include "runtime/fracture_stage.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;

namespace {

// Material of scenes/expanding_ring.yaml; the ring and the rate.
constexpr double kE = 275.0e9, kRho = 2750, kSigma = 300.0e6, kGc = 100.0;
constexpr double kR = 2.5e-3, kA = 1.0e-4, kRate = 1.0e5, kEnd = 0.8e-6;
constexpr int kAcross = 2;  // cells across the cross-section: h = a / 2

/// ZMR's mean fragment size, m: s0 4.5 / (1 + 4.5 (rate / eps0)^(2/3)) with
/// s0 = E Gc / sigma_c^2, eps0 = c sigma_c^3 / (E^2 Gc), c = sqrt(E / rho).
double zmr_size() {
  const double s0 = kE * kGc / (kSigma * kSigma);
  const double eps0 = std::sqrt(kE / kRho) * kSigma * kSigma * kSigma / (kE * kE * kGc);
  return s0 * 4.5 / (1 + 4.5 * std::pow(kRate / eps0, 2.0 / 3.0));
}

/// The structured ring's .msh, written by bench/ring_mesh.py (CI installs python3).
std::string ring_mesh(int cells_around) {
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "structured_ring";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "ring.msh").string();
  const std::string cmd = "/usr/bin/python3 " SHATTER_SOURCE_DIR "/bench/ring_mesh.py " + std::to_string(kR) + " " +
                          std::to_string(kA) + " " + std::to_string(kAcross) + " " + std::to_string(kAcross) + " " +
                          std::to_string(cells_around) + " " + path + " 2> /dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  return path;
}

std::string ring_scene(const std::string& mesh, int seed) {
  return "name: structured_ring\n"
         "time: {end: 8.0e-7}\n" +
         test::ring_aluminium(", scatter: {distribution: uniform, spread: 0.05, seed: " + std::to_string(seed) + "}") +
         "bodies:\n"
         "  - name: ring\n"
         "    material: alu\n"
         "    mesh: {file: " +
         mesh +
         "}\n"
         "    velocity_gradient: [[1.0e5, 0, 0], [0, 1.0e5, 0], [0, 0, 0]]\n";
}

}  // namespace

TEST(StructuredRing, FragmentsAtZmrSizeWithFlatCracksAndTheLedgerClosed) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
  const double circumference = 2 * std::numbers::pi * kR;
  const int around = static_cast<int>(std::lround(circumference * kAcross / kA));
  const double h = circumference / around;  // cell edge along the ring
  const std::string mesh = ring_mesh(around);
  int big_all = 0;
  constexpr int kSeeds = 3;  // one seed's count is a sample: +-6 % between seeds in the study
  for (int seed = 1; seed <= kSeeds; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    Model m = build_model(shatter::test::scene_from_text("structured_ring", ring_scene(mesh, seed)));
    ASSERT_EQ(m.mesh.num_elements(), 6 * kAcross * kAcross * around);
    Simulation sim(m, {});
    const Ledger start = sim.ledger();
    while (sim.time() < kEnd) sim.step();
    const Ledger end = sim.ledger();

    // Fragments of at least one cell along the ring (the others are chips
    // torn off the surface, not pieces between two through-cracks), their
    // length L_i = m_i / (rho a^2).
    const Fragments frags = sim.fracture()->fragments(sim.positions(), sim.velocities(), m.mass);
    int big = 0;
    for (const FragmentStats& f : frags.stats) big += f.mass / (kRho * kA * kA) >= h;
    ASSERT_GE(big, 2);
    big_all += big;
    const CrackArea crack = sim.fracture()->crack_area(frags);
    std::printf("seed %d: %ld fragments, %d of at least one cell (L/N_big = %.3f x ZMR); through-crack %.3f a^2 "
                "per crack; energy error %.2e\n",
                seed, static_cast<long>(frags.count()), big, circumference / big / zmr_size(),
                crack.between_fragments.value() / (big * kA * kA), (end.total() - start.total()) / start.total());

    // A closed ring in N_big pieces has N_big through-cracks, each at least
    // the cross-section a^2; flat ones are a^2 (measured 1.00-1.01 a^2 in the
    // study; 1.11-1.66 on the Gmsh tube).
    EXPECT_GE(crack.between_fragments.value(), big * kA * kA * (1 - 1e-9));
    EXPECT_LT(crack.between_fragments.value(), 1.05 * big * kA * kA);
    // Every debonded facet dissipated Gc; the partly opened ones add to it.
    EXPECT_GE(end.cohesive_dissipated, kGc * crack.debonded.value() * (1 - 1e-12));
    // No external work: the total stays (3.9e-5 of it in the study at
    // 1e5 /s; the chatter of reclosed facets gains energy for as long as
    // they chatter, docs/validation.md, short at this rate).
    EXPECT_LT(std::abs(end.total() - start.total()), 1e-3 * start.total())
        << "total " << end.total() << " from " << start.total();
  }
  // Mean size 2 pi R / N_big over the seeds against ZMR: 1.07-1.13 per seed
  // on the R = 5 mm ring of the study, 1.09-1.12 on its finer meshes; cracks
  // that zigzag (the Gmsh tube: 1.25-1.49) or a ring that breaks at every
  // plane at once (no scatter: 0.48 at 1e4 /s) land outside the band.
  const double ratio = kSeeds * circumference / big_all / zmr_size();
  std::printf("mean over the seeds: L/N_big = %.3f x ZMR\n", ratio);
  EXPECT_GT(ratio, 0.9) << big_all << " fragments of at least one cell";
  EXPECT_LT(ratio, 1.2) << big_all << " fragments of at least one cell";
}
