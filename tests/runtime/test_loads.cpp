// Regions, time functions, prescribed displacements and components, and
// surface loads (issue 20) through the whole loader and time loop: the
// nodes each region selects, load resultants, rollers that leave the free
// directions alone to round-off, displacements reached exactly, and the
// ledger (history.csv) closing with the loads' and reactions' work.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "expect_close.hpp"
#include "mpi_environment.hpp"
#include "kernels/error.hpp"
#include "runtime/loads.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;
using shatter::test::scene_from_text;
using shatter::test::steel_body_scene;

namespace {

/// The nodes whose component is prescribed by condition k.
std::vector<Index> condition_nodes(const Model& m, int k) {
  std::vector<Index> out;
  for (Index i = 0; i < m.mesh.num_nodes(); ++i)
    for (int c = 0; c < 3; ++c)
      if (m.bc_condition[i][c] == k) {
        out.push_back(i);
        break;
      }
  return out;
}

/// The nodes of body 0 where `on` holds.
template <class F>
std::vector<Index> nodes_where(const Model& m, F on) {
  std::vector<Index> out;
  for (Index i = 0; i < m.mesh.num_nodes(); ++i)
    if (on(m.mesh.reference[i])) out.push_back(i);
  return out;
}

/// history.csv as columns by name.
std::map<std::string, std::vector<double>> read_history(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream head(line);
  for (std::string name; std::getline(head, name, ',');) names.push_back(name);
  std::map<std::string, std::vector<double>> out;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (size_t k = 0; k < names.size() && std::getline(row, cell, ','); ++k) out[names[k]].push_back(std::stod(cell));
  }
  return out;
}

}  // namespace

// Each named face of each shape selects the nodes on that surface, no more
// (a cylinder's rim nodes are on top and side; a top face's triangles with
// three rim corners are not on the side).
TEST(Regions, NamedFacesSelectTheNodesOnTheirSurfaces) {
  struct Case {
    std::string mesh, face;
    std::function<bool(const Vec3&)> on;
  };
  const double tol = 1e-9;
  const std::vector<Case> cases = {
      {"shape: box, size: [0.02, 0.01, 0.01], center: [0.01, 0, 0], element_size: 0.004", "xmin",
       [=](const Vec3& X) { return std::abs(X.x()) < tol; }},
      {"shape: box, size: [0.02, 0.01, 0.01], center: [0.01, 0, 0], element_size: 0.004", "ymax",
       [=](const Vec3& X) { return std::abs(X.y() - 0.005) < tol; }},
      {"shape: cylinder, radius: 0.01, length: 0.02, element_size: 0.004", "top",
       [=](const Vec3& X) { return std::abs(X.z() - 0.01) < tol; }},
      {"shape: cylinder, radius: 0.01, length: 0.02, axis: [1, 0, 0], element_size: 0.004", "side",
       [=](const Vec3& X) { return std::abs(std::hypot(X.y(), X.z()) - 0.01) < 1e-7; }},
      {"shape: tube, inner_radius: 0.006, outer_radius: 0.01, length: 0.01, element_size: 0.003", "inner",
       [=](const Vec3& X) { return std::abs(std::hypot(X.x(), X.y()) - 0.006) < 1e-7; }},
      {"shape: tube, inner_radius: 0.006, outer_radius: 0.01, length: 0.01, element_size: 0.003", "outer",
       [=](const Vec3& X) { return std::abs(std::hypot(X.x(), X.y()) - 0.01) < 1e-7; }},
      {"shape: sphere, radius: 0.01, element_size: 0.004, order: 2", "surface",
       [=](const Vec3& X) { return std::abs(X.norm() - 0.01) < 1e-7; }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.mesh + " " + c.face);
    const Model m = build_model(scene_from_text(
        "face_" + c.face, steel_body_scene("face", c.mesh, "",
                                           "boundary_conditions:\n  - {body: b, region: {face: " + c.face +
                                               "}, velocity: [0, null, null]}\n")));
    const std::vector<Index> got = condition_nodes(m, 0), expected = nodes_where(m, c.on);
    EXPECT_GT(got.size(), 8u);
    EXPECT_EQ(got, expected);
  }
}

// A uniform pressure on a closed surface (a hollow sphere's outer and inner
// faces, TET10) has no resultant; on a box face its resultant is -p A n.
TEST(Loads, PressureResultants) {
  const Model sphere = build_model(scene_from_text(
      "pressure_sphere",
      steel_body_scene("s", "shape: sphere, radius: 0.01, inner_radius: 0.005, element_size: 0.004, order: 2", "",
                       "loads:\n  - {body: b, region: {face: surface}, pressure: 1.0e8}\n"
                       "  - {body: b, region: {face: inner}, pressure: 1.0e8}\n")));
  SurfaceLoads loads(sphere);
  loads.compute(sphere.mesh.reference, 0.0);
  Vec3 sum = Vec3::Zero();
  double scale = 0;
  for (const Vec3& f : loads.force()) sum += f, scale += f.norm();
  EXPECT_LT(sum.norm(), 1e-13 * scale);
  EXPECT_GT(scale, 0.5 * 1e8 * 4 * std::numbers::pi * 1e-4);  // about p times the surface area

  const Model box = build_model(scene_from_text(
      "pressure_box",
      steel_body_scene("p", "shape: box, size: [0.02, 0.01, 0.01], element_size: 0.004", "",
                       "loads:\n  - {body: b, region: {face: xmax}, pressure: 2.0e8, amplitude: {ramp: 1.0}}\n")));
  SurfaceLoads on_box(box);
  on_box.compute(box.mesh.reference, 0.25);
  sum = Vec3::Zero();
  for (const Vec3& f : on_box.force()) sum += f;
  EXPECT_LT((sum - Vec3(-0.25 * 2.0e8 * 1e-4, 0, 0)).norm(), 1e-12 * 0.25 * 2.0e8 * 1e-4);
}

// A roller (z held on the bottom face) under gravity along x and z: the body
// slides along x as if free, px(t) = M (vx0 + gx t) to round-off, and the
// bottom face's nodes never move along z.
TEST(Constraints, RollerLeavesTheFreeDirectionsFree) {
  Model m = build_model(scene_from_text(
      "roller", steel_body_scene("roller", "shape: box, size: [0.02, 0.01, 0.01], element_size: 0.004",
                                 "    initial_velocity: [3, 1, 0]\n",
                                 "gravity: [50, 0, -9.81]\n"
                                 "boundary_conditions:\n  - {body: b, region: {face: zmin}, velocity: [null, null, 0]}\n",
                                 "1.0e-5")));
  Simulation sim(m, {});
  while (sim.time() < m.scene.end_time) sim.step();
  const double M = m.body_mass[0];
  const Vec3 p = sim.ledger().momentum;
  EXPECT_CLOSE(p.x(), M * (3 + 50 * sim.time()), 1e-13, 0);
  EXPECT_CLOSE(p.y(), M * 1, 1e-13, 0);
  for (Index i : condition_nodes(m, 0)) EXPECT_EQ(sim.positions()[i].z(), m.mesh.reference[i].z());
}

// A displacement with an amplitude: the face's nodes are where the
// amplitude puts them at every step (to round-off of the position), free
// components free; the reactions' work keeps the ledger closed.
TEST(Constraints, PrescribedDisplacementIsReachedAndItsWorkBooked) {
  const double u = 2.0e-6, t_end = 2.0e-5;
  Model m = build_model(scene_from_text(
      "displacement",
      steel_body_scene("displacement", "shape: box, size: [0.02, 0.01, 0.01], element_size: 0.004, order: 2", "",
                       "boundary_conditions:\n  - {body: b, region: {face: xmin}, displacement: [0, 0, 0]}\n"
                       "  - {body: b, region: {face: xmax}, displacement: [" + shatter::test::num(u) +
                           ", null, null], amplitude: {smooth_step: [0, 1.0e-5]}}\n",
                       shatter::test::num(t_end))));
  Simulation sim(m, {});
  const std::vector<Index> pulled = condition_nodes(m, 1);
  double worst = 0, work_peak = 0;
  while (sim.time() < t_end) {
    sim.step();
    const double target = u * m.scene.boundary_conditions[1].amplitude.value(sim.time());
    for (Index i : pulled) worst = std::max(worst, std::abs(sim.positions()[i].x() - m.mesh.reference[i].x() - target));
    work_peak = std::max(work_peak, std::abs(sim.ledger().external_work));
  }
  EXPECT_LT(worst, 1e-15);
  EXPECT_GT(work_peak, 0.0);
  EXPECT_LT(std::abs(sim.energy_error()), 2e-3);
}

// A tube under an internal pressure pulse, held by a roller: history.csv's
// ledger closes, total = kinetic + strain - external_work constant within
// 1e-3 of the largest energy, and the loads did work.
TEST(Loads, HistoryLedgerClosesUnderAPressurePulse) {
  const std::filesystem::path out = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "loads_ledger";
  std::filesystem::remove_all(out);
  Model m = build_model(scene_from_text(
      "loads_ledger",
      steel_body_scene("loads_ledger",
                       "shape: tube, inner_radius: 0.01, outer_radius: 0.016, length: 0.01, element_size: 0.003", "",
                       "boundary_conditions:\n  - {body: b, region: {face: bottom}, velocity: [null, null, 0]}\n"
                       "loads:\n  - {body: b, region: {face: inner}, pressure: 3.0e8, amplitude: {half_sine: [0, 2.0e-5]}}\n"
                       "  - {body: b, region: {face: top}, traction: [0, 2.0e7, 0], amplitude: [[0, 0], [1.0e-5, 1], [2.0e-5, 1]]}\n",
                       "3.0e-5")));
  RunOptions options;
  options.out_dir = out;
  options.quiet = true;
  Simulation sim(m, options);
  sim.run();
  auto h = read_history(out / "history.csv");
  ASSERT_GT(h["total"].size(), 10u);
  double largest = 0, drift = 0;
  for (size_t k = 0; k < h["total"].size(); ++k) {
    const double balance = h["kinetic"][k] + h["strain"][k] - h["external_work"][k];
    EXPECT_NEAR(balance, h["total"][k], 1e-9 * (1 + std::abs(balance)));
    largest = std::max({largest, h["kinetic"][k] + h["strain"][k], std::abs(h["external_work"][k])});
    drift = std::max(drift, std::abs(h["total"][k] - h["total"][0]));
  }
  EXPECT_GT(largest, 1e-3);
  EXPECT_LT(drift, 1e-3 * largest) << "drift " << drift << " J of " << largest << " J";
}

// DCR and a held component (contact/dcr.hpp, DcrOptions::held): a block
// thrown obliquely, with friction, at a plate whose top face is held along z
// (a symmetry plane). The plate's top nodes never move along z, yet take the
// friction's tangential impulses: momentum along x and y, which no condition
// holds, is conserved to round-off, and the plate is dragged along. (When a
// held node was immovable in every component, the plate took no x momentum.)
TEST(Constraints, ContactMovesAHeldNodeInItsFreeComponentsOnly) {
  Model m = build_model(scene_from_text(
      "held_contact",
      "name: held_contact\ntime: {end: 3.0e-3}\nmaterials:\n"
      "  soft: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e7, poisson_ratio: 0.3}\n"
      "bodies:\n"
      "  - {name: plate, material: soft, mesh: {shape: box, size: [0.08, 0.08, 0.01], center: [0, 0, -0.005], "
      "element_size: 0.01}}\n"
      "  - {name: block, material: soft, mesh: {shape: box, size: [0.02, 0.02, 0.02], center: [0, 0, 0.0105], "
      "element_size: 0.01}, initial_velocity: [3, 2, -2]}\n"
      "boundary_conditions:\n  - {body: plate, region: {face: zmax}, velocity: [null, null, 0]}\n"
      "contact: {friction: 0.3, restitution: 1.0}\n"));
  Simulation sim(m, {});
  const Vec3 p0 = sim.ledger().momentum;
  long contacts = 0;
  while (sim.time() < m.scene.end_time) {
    sim.step();
    contacts += sim.ledger().contacts;
  }
  ASSERT_GT(contacts, 0);
  const Vec3 p = sim.ledger().momentum;
  EXPECT_LT(std::abs(p.x() - p0.x()), 1e-12 * p0.norm());
  EXPECT_LT(std::abs(p.y() - p0.y()), 1e-12 * p0.norm());
  Vec3 plate = Vec3::Zero();
  for (Index i = 0; i < m.mesh.num_nodes(); ++i)
    if (m.mesh.node_body[i] == 0) plate += m.mass[i] * sim.velocities()[i];
  EXPECT_GT(plate.x(), 1e-3 * p0.x()) << "the plate took no friction impulse";
  for (Index i : condition_nodes(m, 0)) {
    EXPECT_EQ(sim.positions()[i].z(), m.mesh.reference[i].z());
    EXPECT_EQ(sim.velocities()[i].z(), 0.0);
  }
}
