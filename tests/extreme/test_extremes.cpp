// Stability at the extremes (issue 7; the table with the measured figures is
// docs/extremes.md). Each case either runs to its end without NaN, with no
// penetration left after any step (the independent point-in-tet check of
// tests/run_checks.hpp), linear momentum kept and the energy ledger bounded, or
// stops through the `shatter` binary with exit status 1, a diagnosis naming
// the element, its position and the step, and a checkpoint of the last good
// state:
//   - material: nearly incompressible (nu = 0.499), soft against stiff (E ratio 1e6);
//   - contact geometry: impact at a large fraction of the wave speed, bodies
//     touching at t = 0, grazing faces, parallel edges, a vertex exactly on an
//     edge and on a vertex;
//   - element shape: a sliver and a needle hitting a block;
//   - a ring spinning fast enough to fly apart (with fracture; and without,
//     where the strain grows without bound);
//   - 1e6 steps of free vibration: energy drift per step;
//   - cubes stacked at rest under gravity: no jitter growth, no sinking.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <span>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "expect_close.hpp"
#include "kernels/tet4.hpp"
#include "run_checks.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;
using shatter::test::body_centre;
using shatter::test::body_velocity;
using shatter::test::count_penetrations;
using shatter::test::num;
using shatter::test::scene_from_text;
using shatter::test::write_scene;

namespace {

std::string vec(const Vec3& a) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.6g, %.6g, %.6g]", a.x(), a.y(), a.z());
  return buf;
}

/// What a watched run saw, step by step.
struct Watch {
  Ledger first, last;
  double max_energy_error = 0;  ///< max |Simulation::energy_error()|
  double max_dp = 0;            ///< max |p - p0| / sum m |v0|
  double p_scale = 0;           ///< sum m |v| at the start, kg m/s
  long contact_steps = 0;
  long steps = 0;
  int penetrations = 0;
  bool finite = true;
  std::vector<double> contact_dissipated;  ///< after every step, J
};

/// Steps `sim` to `end` (s), checking after every step: positions finite, momentum,
/// energy error and (with contact) the independent penetration check; then `after_step`.
Watch run_watched(Simulation& sim, double end, const std::function<void()>& after_step = {}) {
  Watch w;
  w.first = sim.ledger();
  const Model& m = sim.model();
  for (Index i = 0; i < m.mesh.num_nodes(); ++i)
    w.p_scale += m.mass[i] * sim.velocities()[i].norm();
  while (sim.time() < end - 1e-12 * end && w.finite) {
    sim.step();
    ++w.steps;
    for (const Vec3& x : sim.positions()) w.finite = w.finite && x.allFinite();
    w.finite = w.finite && std::isfinite(sim.ledger().total());
    w.max_energy_error = std::max(w.max_energy_error, std::abs(sim.energy_error()));
    w.max_dp = std::max(w.max_dp, (sim.ledger().momentum - w.first.momentum).norm() / w.p_scale);
    w.contact_dissipated.push_back(sim.ledger().contact_dissipated);
    if (sim.contact()) {
      w.contact_steps += sim.ledger().contacts > 0;
      w.penetrations += count_penetrations(sim);
    }
    if (after_step) after_step();
  }
  w.last = sim.ledger();
  return w;
}

/// The common verdict of a run that must complete: finite, no penetration, momentum
/// to round-off (no gravity, no boundary conditions), energy error below `energy_tol`,
/// contact_dissipated never decreasing.
void expect_clean(const Watch& w, double energy_tol, bool momentum_kept = true) {
  EXPECT_TRUE(w.finite) << "NaN or Inf after step " << w.steps;
  EXPECT_EQ(w.penetrations, 0);
  EXPECT_TRUE(test::never_decreases(w.contact_dissipated)) << "contact_dissipated";
  if (momentum_kept) {
    EXPECT_LT(w.max_dp, 1e-12);
  }
  EXPECT_LT(w.max_energy_error, energy_tol);
}

/// Writes a Gmsh v2 mesh of 4-node tets beside the test scenes (scene_text.hpp's
/// folder) and returns its file name; tets with negative volume get two nodes swapped.
std::string write_tets(const std::string& name, const std::vector<Vec3>& nodes,
                       std::vector<std::array<int, 4>> tets) {
  const auto path = std::filesystem::path(write_scene(name, "")).replace_extension(".msh");
  std::ofstream f(path);
  f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << nodes.size() << "\n";
  for (size_t i = 0; i < nodes.size(); ++i)
    f << i + 1 << " " << num(nodes[i].x()) << " " << num(nodes[i].y()) << " " << num(nodes[i].z())
      << "\n";
  f << "$EndNodes\n$Elements\n" << tets.size() << "\n";
  for (size_t e = 0; e < tets.size(); ++e) {
    auto& t = tets[e];
    if (tet_signed_volume(nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]) < 0)
      std::swap(t[2], t[3]);
    f << e + 1 << " 4 2 1 1 " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << " " << t[3] + 1
      << "\n";
  }
  f << "$EndElements\n";
  return path.filename().string();
}

/// A single-tet body: the mesh file of the four vertices scaled by `s` and moved by `shift`.
std::string one_tet(const std::string& name, std::array<Vec3, 4> v, double s, const Vec3& shift) {
  std::vector<Vec3> nodes;
  for (const Vec3& p : v) nodes.push_back(s * p + shift);
  return write_tets(name, nodes, {{0, 1, 2, 3}});
}

// A soft solid (c_d = 116 m/s) keeps the step long, so the contact cases run in a few
// hundred steps.
const char* kSoft =
    "  soft: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e7, poisson_ratio: 0.3}\n";

/// Two bodies given as YAML flow maps, frictionless elastic contact (or `law`).
std::string two_body_scene(const std::string& name, const std::string& materials,
                           const std::string& a, const std::string& b,
                           const std::string& law = "{friction: 0.0, restitution: 1.0}",
                           double end = 1.0) {
  return "name: " + name + "\ntime: {end: " + num(end) + "}\nmaterials:\n" + materials +
         "bodies:\n  - " + a + "\n  - " + b + "\ncontact: " + law + "\n";
}

/// A model and its simulation, kept together (Simulation refers to the model).
struct Started {
  std::unique_ptr<Model> model;
  std::unique_ptr<Simulation> sim;
  Watch w;
  long overlapping_steps = 0;  ///< single-tet pairs: steps at which the tets overlap
};

/// With `fixed_step`, time.dt is set to half the step the defaults take first (0.25 x
/// the initial stable step: room for the elements to deform) and kept: single-tet bodies ring hard
/// after an impact, near the stability limit at the default step, where central difference's
/// energy oscillation is largest (the AdaptiveStep tests below); the shorter fixed step keeps
/// that oscillation out of the energy bounds of what a case probes.
Started start(const std::string& name, const std::string& yaml, bool fixed_step = false) {
  Started r;
  r.model = std::make_unique<Model>(build_model(scene_from_text(name, yaml)));
  if (fixed_step) r.model->scene.fixed_dt = 0.5 * Simulation(*r.model, RunOptions{}).stable_dt();
  r.sim = std::make_unique<Simulation>(*r.model, RunOptions{});
  return r;
}

/// Outcome of `shatter run` on a scene: exit status, stderr, whether a checkpoint exists.
struct BinaryRun {
  int status = -1;
  std::string err;
  bool checkpoint = false;
};

BinaryRun run_binary(const std::string& name, const std::string& yaml) {
  const std::string scene = write_scene(name, yaml);
  const auto out = std::filesystem::temp_directory_path() / ("shatter_extreme_" + name);
  std::filesystem::remove_all(out);
  const auto err = out.string() + ".stderr";
  const std::string cmd = std::string(SHATTER_BINARY_DIR) + "/apps/shatter run " + scene +
                          " --out " + out.string() + " --quiet > /dev/null 2> " + err;
  const int st = std::system(cmd.c_str());
  BinaryRun r;
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  std::ifstream f(err);
  std::stringstream ss;
  ss << f.rdbuf();
  r.err = ss.str();
  r.checkpoint = std::filesystem::is_regular_file(out / "checkpoint.h5");
  return r;
}

/// A run that stops must say where: the element, the step, the position, and leave a checkpoint.
void expect_diagnosis(const BinaryRun& r) {
  EXPECT_EQ(r.status, 1) << r.err;
  for (const char* word : {"step ", "element ", " near (", "checkpoint"})
    EXPECT_NE(r.err.find(word), std::string::npos) << "'" << word << "' missing from: " << r.err;
  EXPECT_TRUE(r.checkpoint);
}

/// A 2 cm cube of `material` (element size 1 cm) at `centre` moving at `v`, as a YAML flow map.
std::string cube(const std::string& name, const std::string& material, const Vec3& centre,
                 const Vec3& v) {
  return "{name: " + name + ", material: " + material +
         ", mesh: {shape: box, size: [0.02, 0.02, 0.02], center: " + vec(centre) +
         ", element_size: 0.01}, initial_velocity: " + vec(v) + "}";
}

/// Two bodies colliding (frictionless, elastic), run watched to `end`; the run must have had
/// contact.
Started run_cube_pair(const std::string& name, const std::string& materials, const std::string& a,
                      const std::string& b, double end) {
  Started r = start(name, two_body_scene(name, materials, a, b));
  r.w = run_watched(*r.sim, end);
  std::printf(
      "%s: %ld steps, dt %.3e, contact steps %ld, energy error max %.3e final %+.3e, v %s %s\n",
      name.c_str(), r.w.steps, r.sim->dt(), r.w.contact_steps, r.w.max_energy_error,
      r.sim->energy_error(), vec(body_velocity(*r.sim, 0)).c_str(),
      vec(body_velocity(*r.sim, 1)).c_str());
  EXPECT_GT(r.w.contact_steps, 0) << "no contact";
  return r;
}

}  // namespace

// nu = 0.499: the dilatational speed is 13 x the shear speed, so the step is 13 x
// shorter than the deformation needs, and TET4 locks (stiff but stable). Two rubber
// cubes meet at 2 x 1 m/s and separate.
TEST(Extreme, NearlyIncompressibleCubesCollide) {
  const Started r =
      run_cube_pair("incompressible",
                    "  rubber: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e6, "
                    "poisson_ratio: 0.499}\n",
                    cube("a", "rubber", Vec3(-0.0101, 0, 0), Vec3(1, 0, 0)),
                    cube("b", "rubber", Vec3(0.0101, 0.004, 0), Vec3(-1, 0, 0)), 4e-3);
  expect_clean(r.w, 0.03);
  EXPECT_LT(body_velocity(*r.sim, 0).x(), 0.0);
  EXPECT_GT(body_velocity(*r.sim, 1).x(), 0.0);
}

// E ratio 1e6: a soft cube (E = 1e5 Pa, c_d = 11.6 m/s) hits a stiff one (1e11 Pa) of
// the same density at rest. The stiff body sets the step (1000 x shorter than the
// soft body needs: the contact lasts ~2e4 steps); the soft body must not sink in.
TEST(Extreme, SoftAgainstStiffE1e6) {
  const Started r = run_cube_pair(
      "soft_stiff",
      "  softer: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e5, poisson_ratio: 0.3}\n"
      "  stiff: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e11, poisson_ratio: 0.3}\n",
      cube("soft", "softer", Vec3(-0.0101, 0, 0), Vec3(1, 0, 0)),
      cube("stiff", "stiff", Vec3(0.0101, 0, 0), Vec3::Zero()), 5e-3);
  expect_clean(r.w, 0.03);
  const Simulation& sim = *r.sim;
  // The stiff body was pushed; the soft one gave up most of its momentum.
  EXPECT_GT(body_velocity(sim, 1).x(), 0.5);
  EXPECT_LT(body_velocity(sim, 0).x(), 0.5);
}

namespace {

/// Two steel cubes meeting head-on, each at `fraction` x c_d, run for 3 transit times.
std::string fast_scene(const std::string& name, double fraction) {
  const double E = 210e9, nu = 0.3, rho = 7850;
  const double c_d = std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu) * rho));
  const double v = fraction * c_d;
  return two_body_scene(
      name,
      "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n",
      "{name: a, material: steel, mesh: {shape: box, size: [0.01, 0.01, 0.01], center: [-0.00501, "
      "0, 0], "
      "element_size: 0.005}, initial_velocity: [" +
          num(v) + ", 0, 0]}",
      "{name: b, material: steel, mesh: {shape: box, size: [0.01, 0.01, 0.01], center: [0.00501, "
      "0.002, 0], "
      "element_size: 0.005}, initial_velocity: [" +
          num(-v) + ", 0, 0]}",
      "{friction: 0.0, restitution: 1.0}", 3.0 * 0.01 / c_d);
}

}  // namespace

// Two steel cubes meet head-on, each at 0.1, 0.5 and 1.0 x c_d (590 to 5900 m/s; the
// last compresses the contact zone at twice the wave speed): every run completes,
// momentum kept, nothing penetrates. The ledger loses 3-9 % (measured 8.6 %, 4.8 %,
// 3.2 %: the end-of-step projection loss of docs/contact.md, on 2 elements per edge).
TEST(Extreme, ImpactAtLargeFractionsOfWaveSpeed) {
  for (const double fraction : {0.1, 0.5, 1.0}) {
    SCOPED_TRACE(fraction);
    Started r = start("fast", fast_scene("fast", fraction));
    r.w = run_watched(*r.sim, r.model->scene.end_time);
    std::printf(
        "%.1f c_d: %ld steps, contact steps %ld, energy error max %.3e final %+.3e, capped %ld\n",
        fraction, r.w.steps, r.w.contact_steps, r.w.max_energy_error, r.sim->energy_error(),
        r.sim->ledger().contact_capped_steps);
    ASSERT_GT(r.w.contact_steps, 0);
    expect_clean(r.w, 0.12);
  }
}

// A fixed time.dt 3 x above the stable step: the run blows up within a few steps and
// must stop with exit status 1, the element, its position and the step named, and a
// checkpoint of the last good state, not run on with NaN.
TEST(Extreme, StepAboveStableLimitStopsWithDiagnosis) {
  const double c_d = std::sqrt(1.0e7 * 0.7 / (1.3 * 0.4 * 1000));
  Model m = build_model(scene_from_text(
      "unstable",
      "name: unstable\ntime: {end: 1.0}\nmaterials:\n" + std::string(kSoft) +
          "bodies:\n  - {name: b, material: soft, mesh: {shape: box, size: [0.02, 0.02, 0.02], "
          "element_size: 0.01}, velocity_gradient: [[10, 0, 0], [0, 0, 0], [0, 0, 0]]}\n"));
  const double stable = Simulation(m, RunOptions{}).stable_dt() / m.scene.safety;
  std::printf("stable step %.3e s (h / c_d with c_d %.1f m/s)\n", stable, c_d);
  const BinaryRun r = run_binary(
      "unstable",
      "name: unstable\ntime: {end: " + num(2000 * stable) + ", dt: " + num(3 * stable) +
          "}\noutput: {every: 0}\nmaterials:\n" + std::string(kSoft) +
          "bodies:\n  - {name: b, material: soft, mesh: {shape: box, size: [0.02, 0.02, 0.02], "
          "element_size: 0.01}, velocity_gradient: [[10, 0, 0], [0, 0, 0], [0, 0, 0]]}\n");
  std::printf("dt 3 x stable: exit %d: %s\n", r.status, r.err.c_str());
  expect_diagnosis(r);
}

// Two cubes whose faces coincide at t = 0 (z = 0 exactly), the upper one moving
// down at 1 m/s: contact from the first step on, no penetration, no capped step, and
// after it the lower cube moves down faster than the upper one.
// Fixed (was DISABLED: the sweeps reached their cap in step 1, 1075 penetrations, the upper
// cube went on through the lower one): coplanar edge pairs that start touching took their
// orientation from x_new, which the neighbours' projections flip every sweep, and edge pairs
// left crossed pulled the cubes together; DCR now orients pairs by the outward normals
// (kernels/dcr.hpp dcr_orientation). Measured: vz -0.807 / -0.193 (middle), -0.804 / -0.196
// (end). The energy bound of 3 % holds with contact.placement: middle (+0.14 %); the end
// placement loses 5.4 % on this coarse mesh (2 elements per edge; the same with a 1e-7 m gap:
// it is the end placement's impact loss of docs/contact.md, not the coincidence), held to 8 %.
TEST(Extreme, BodiesTouchingAtStart) {
  for (const auto& [placement, energy_tol] : {std::pair{"middle", 0.03}, std::pair{"end", 0.08}}) {
    SCOPED_TRACE(placement);
    Model m = build_model(scene_from_text(
        "touching", two_body_scene("touching", kSoft,
                                   "{name: lower, material: soft, mesh: {shape: box, size: [0.02, "
                                   "0.02, 0.02], center: [0, 0, -0.01], "
                                   "element_size: 0.01}}",
                                   "{name: upper, material: soft, mesh: {shape: box, size: [0.02, "
                                   "0.02, 0.02], center: [0.005, 0, 0.01], "
                                   "element_size: 0.01}, initial_velocity: [0, 0, -1]}",
                                   std::string("{friction: 0.0, restitution: 1.0, placement: ") +
                                       placement + "}")));
    Simulation sim(m, {});
    sim.step();
    EXPECT_GT(sim.ledger().contacts, 0) << "no contact in the first step";
    const Watch w = run_watched(sim, 2e-3);
    std::printf(
        "touching (%s): %ld steps, contact steps %ld, capped %ld, energy error max %.3e final "
        "%+.3e, vz "
        "%.3f %.3f\n",
        placement, w.steps, w.contact_steps, sim.ledger().contact_capped_steps, w.max_energy_error,
        sim.energy_error(), body_velocity(sim, 0).z(), body_velocity(sim, 1).z());
    expect_clean(w, energy_tol);
    EXPECT_EQ(sim.ledger().contact_capped_steps, 0);
    EXPECT_LT(body_velocity(sim, 0).z(), body_velocity(sim, 1).z());
    EXPECT_GT(body_centre(sim, 1).z() - body_centre(sim, 0).z(), 0.02 * (1 - 1e-3));
  }
}

namespace {

/// A cube sliding at 1 m/s along the top face of a longer block, its bottom face in the
/// plane of that face lifted by `gap` (m), mu = 0.5.
Started grazing(const std::string& name, double gap) {
  Started r = start(
      name,
      two_body_scene(name, kSoft,
                     "{name: below, material: soft, mesh: {shape: box, size: [0.08, 0.04, 0.02], "
                     "center: [0, 0, -0.01], element_size: 0.01}}",
                     "{name: slider, material: soft, mesh: {shape: box, size: [0.02, 0.02, 0.02], "
                     "center: [-0.025, 0.005, " +
                         num(0.01 + gap) +
                         "], element_size: 0.01}, "
                         "initial_velocity: [1, 0, 0]}",
                     "{friction: 0.5, restitution: 1.0}"));
  r.w = run_watched(*r.sim, 0.04);
  std::printf(
      "%s: %ld steps, contact steps %ld, energy error max %.3e, dissipated %.3e, v slider %s below "
      "%s\n",
      name.c_str(), r.w.steps, r.w.contact_steps, r.w.max_energy_error,
      r.sim->ledger().contact_dissipated, vec(body_velocity(*r.sim, 1)).c_str(),
      vec(body_velocity(*r.sim, 0)).c_str());
  return r;
}

/// Grazing must not kick: no normal velocity appears, no energy is lost to friction
/// (the normal force is zero), the slider keeps its speed, nothing penetrates.
void expect_undisturbed(const Started& r) {
  expect_clean(r.w, 1e-6);
  EXPECT_NEAR(body_velocity(*r.sim, 1).x(), 1.0, 1e-6);
  EXPECT_LT(body_velocity(*r.sim, 1).tail<2>().norm(), 1e-6);
  EXPECT_LT(body_velocity(*r.sim, 0).norm(), 1e-6);
}

}  // namespace

// Lifted by 1e-9 m (1e-7 of the element size): the faces slide past within the
// detection tolerance and nothing must happen.
TEST(Extreme, GrazingFacesAtTinyGapSlideUndisturbed) {
  expect_undisturbed(grazing("grazing_gap", 1e-9));
}

// Exactly in the plane (zero gap): the grazing limit of contact.
// Fixed (was DISABLED: the sweeps reached their cap in step 1, 28596 penetrations, the
// slider stopped to 0.15 m/s and kicked 0.06 m/s out of the plane): the coincident faces of
// BodiesTouchingAtStart, plus two grazes the pair tests took for contacts (a vertex of the
// block's face on the edge of the slider's side face; the end of the slider's vertical edge
// passing over an edge of the block's face). Measured: no contact pair in 5747 steps,
// velocities kept to 1e-28, energy 1.9e-12.
TEST(Extreme, GrazingFacesInContactSlideUndisturbed) {
  expect_undisturbed(grazing("grazing_touch", 0.0));
}

namespace {

// Single-tet bodies, scaled to 2 cm, of the soft solid: what meets is exactly a pair of
// edges, a vertex and an edge, or two vertices. Body a is below z = 0 moving up, body b
// above it moving down, both at kV.
constexpr double kTet = 0.02, kGap = 0.001, kV = 0.5;

struct TetPair {
  std::array<Vec3, 4> lower,
      upper;  ///< unit-size vertices; lower touches z = 0 from below, upper from above
};

/// Whether two tetrahedra (nodes 0-3 and 4-7 of x) overlap by more than `depth` along
/// every separating-axis candidate: the 8 face normals and the 36 edge-edge cross products
/// (exact for convex bodies).
bool tets_overlap(std::span<const Vec3> x, double depth) {
  const int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  std::vector<Vec3> axes;
  for (int t : {0, 4})
    for (int f = 0; f < 4; ++f) {
      const int a = t + (f + 1) % 4, b = t + (f + 2) % 4, c = t + (f + 3) % 4;
      axes.push_back((x[b] - x[a]).cross(x[c] - x[a]));
    }
  for (const auto& ea : edges)
    for (const auto& eb : edges)
      axes.push_back((x[ea[1]] - x[ea[0]]).cross(x[4 + eb[1]] - x[4 + eb[0]]));
  for (const Vec3& axis : axes) {
    if (axis.norm() < 1e-12 * (x[1] - x[0]).squaredNorm()) continue;  // parallel edges: no axis
    const Vec3 n = axis.normalized();
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (int i = 0; i < 8; ++i) {
      lo[i / 4] = std::min(lo[i / 4], n.dot(x[i]));
      hi[i / 4] = std::max(hi[i / 4], n.dot(x[i]));
    }
    if (hi[0] < lo[1] + depth || hi[1] < lo[0] + depth) return false;
  }
  return true;
}

Started run_tet_pair(const std::string& name, const TetPair& p) {
  const std::string a = one_tet(name + "_a", p.lower, kTet, Vec3(0, 0, -0.5 * kGap));
  const std::string b = one_tet(name + "_b", p.upper, kTet, Vec3(0, 0, 0.5 * kGap));
  Started r = start(name,
                    two_body_scene(name, kSoft,
                                   "{name: a, material: soft, mesh: {file: " + a +
                                       "}, initial_velocity: [0, 0, " + num(kV) + "]}",
                                   "{name: b, material: soft, mesh: {file: " + b +
                                       "}, initial_velocity: [0, 0, " + num(-kV) + "]}"),
                    true);
  r.w = run_watched(*r.sim, 0.12,
                    [&] { r.overlapping_steps += tets_overlap(r.sim->positions(), 1e-6 * kTet); });
  std::printf(
      "%s: %ld steps, contact steps %ld, energy error max %.3e final %+.3e, vz a %.4f b %.4f\n",
      name.c_str(), r.w.steps, r.w.contact_steps, r.w.max_energy_error, r.sim->energy_error(),
      body_velocity(*r.sim, 0).z(), body_velocity(*r.sim, 1).z());
  return r;
}

/// The verdict of a tet-pair collision: it happened and stopped the approach (the
/// relative velocity changed by more than kV; single tets ring hard after the hit and
/// meet again, so they need not be apart at the end), nothing penetrated (neither a vertex
/// inside the other tet nor, by separating axes, any overlap deeper than 1e-6 of the tet
/// size at any step: an edge through the other tet has no vertex inside it), momentum
/// kept, energy within 5 %.
void expect_bounce(const Started& r) {
  ASSERT_GT(r.w.contact_steps, 0) << "the tets never touched";
  expect_clean(r.w, 0.05);
  EXPECT_EQ(r.overlapping_steps, 0) << "the tets overlapped (an edge through the other tet)";
  EXPECT_GT(body_velocity(*r.sim, 1).z() - body_velocity(*r.sim, 0).z() + 2 * kV, kV)
      << "the approach went on";
}

const std::array<Vec3, 4> kRidgeDown = {Vec3(0, -1, 0), Vec3(0, 1, 0), Vec3(-1, 0, -1),
                                        Vec3(1, 0, -1)};
const std::array<Vec3, 4> kApexUp = {Vec3(0, 0, 0), Vec3(1, 0, -1),
                                     Vec3(-0.5, 0.8660254037844386, -1),
                                     Vec3(-0.5, -0.8660254037844386, -1)};

std::array<Vec3, 4> mirrored(const std::array<Vec3, 4>& v) {
  std::array<Vec3, 4> m;
  for (int i = 0; i < 4; ++i) m[i] = Vec3(v[i].x(), v[i].y(), -v[i].z());
  return m;
}

}  // namespace

// The separating-axis check sees what the vertex-in-tet check cannot: the parallel-edge
// pair pushed 0.3 of its size into each other overlaps with no vertex inside the other.
TEST(Extreme, SeparatingAxisCheckSeesEdgeThroughTet) {
  std::vector<Vec3> x;
  for (const Vec3& p : kRidgeDown) x.push_back(p);
  for (const Vec3& p : mirrored(kRidgeDown)) x.push_back(p + Vec3(0, 0, -0.3));
  EXPECT_TRUE(tets_overlap(x, 1e-6));
  for (int i = 4; i < 8; ++i) x[i].z() += 0.3 + 1e-3;
  EXPECT_FALSE(tets_overlap(x, 1e-6));
}

// The top edge of the lower tet and the bottom edge of the upper one are parallel and
// lie in the same vertical plane: they meet along their whole length at once.
TEST(Extreme, ParallelEdgesMeet) {
  expect_bounce(run_tet_pair("parallel_edges", {kRidgeDown, mirrored(kRidgeDown)}));
}

// The apex of the upper tet lands exactly on the midpoint of the lower tet's top edge.
TEST(Extreme, VertexHitsEdgeExactly) {
  expect_bounce(run_tet_pair("vertex_edge", {kRidgeDown, mirrored(kApexUp)}));
}

// Apex on apex, the two tets turned alike (their edges pairwise in the same vertical
// planes): the two vertices meet exactly.
TEST(Extreme, VertexHitsVertexExactly) {
  expect_bounce(run_tet_pair("vertex_vertex", {kApexUp, mirrored(kApexUp)}));
}

namespace {

/// A single bad-shape tet (vertices `v`, scaled to 2 cm) falling at 0.5 m/s onto a block.
/// `free_flight` (if given) receives the energy error of every step after the tet has
/// left the block.
Started run_bad_tet_on_block(const std::string& name, const std::array<Vec3, 4>& v, bool fixed_step,
                             std::vector<double>* free_flight = nullptr) {
  double zmin = 1e300;
  for (const Vec3& p : v) zmin = std::min(zmin, p.z());
  const std::string file = one_tet(name, v, kTet, Vec3(0.002, 0.001, kGap - kTet * zmin));
  const std::string yaml =
      two_body_scene(name, kSoft,
                     "{name: block, material: soft, mesh: {shape: box, size: [0.04, 0.04, 0.02], "
                     "center: [0, 0, -0.01], element_size: 0.01}}",
                     "{name: tet, material: soft, mesh: {file: " + file +
                         "}, initial_velocity: [0, 0, " + num(-kV) + "]}");
  Started r = start(name, yaml, fixed_step);
  bool hit = false;
  r.w = run_watched(*r.sim, 10 * kGap / kV, [&] {
    const bool touching = r.sim->ledger().contacts > 0;
    hit = hit || touching;
    if (free_flight && hit && !touching) free_flight->push_back(r.sim->energy_error());
  });
  std::printf(
      "%s (%s step): %ld steps, dt %.3e, contact steps %ld, energy error max %.3e final %+.3e, vz "
      "block %.4f "
      "tet %.4f\n",
      name.c_str(), fixed_step ? "fixed" : "adaptive", r.w.steps, r.sim->dt(), r.w.contact_steps,
      r.w.max_energy_error, r.sim->energy_error(), body_velocity(*r.sim, 0).z(),
      body_velocity(*r.sim, 1).z());
  return r;
}

constexpr double kThin = 0.01;
const std::array<Vec3, 4> kSliver = {Vec3(-1, 0, kThin), Vec3(1, 0, kThin), Vec3(0, -1, -kThin),
                                     Vec3(0, 1, -kThin)};
const std::array<Vec3, 4> kNeedle = {Vec3(0, 0, 0), Vec3(kThin, 0, 1),
                                     Vec3(-0.5 * kThin, 0.866 * kThin, 1),
                                     Vec3(-0.5 * kThin, -0.866 * kThin, 1)};

}  // namespace

// A real inelastic impact still books its loss (docs/contact.md "The ledger with e < 1"):
// the apex of a single tet strikes a plate held fixed at 1 m/s, e = 0.5 (e = 1 for
// comparison), no gravity, a fixed step of 1/20 of the stable one. The apex's impact on the
// fixed face is a one-node collision: its relative normal kinetic energy is m_apex v^2 / 2
// and e keeps e^2 of it, so the contact step must book (1 - e^2) m_apex v^2 / 2 to within
// the first-order work term the ledger adds (measured 2e-5 of it at this step); e = 1 books 0.
TEST(Extreme, InelasticImpactBooksItsKineticEnergyLoss) {
  const double v = 1.0;
  for (const double e : {0.5, 1.0}) {
    SCOPED_TRACE(e);
    const std::string file =
        one_tet("apex_down", mirrored(kApexUp), kTet, Vec3(0.002, 0.001, 1e-3 * kTet));
    const std::string yaml =
        two_body_scene("apex", kSoft,
                       "{name: plate, material: soft, mesh: {shape: box, size: [0.04, 0.04, 0.02], "
                       "center: [0, 0, -0.01], element_size: 0.01}}",
                       "{name: tet, material: soft, mesh: {file: " + file +
                           "}, initial_velocity: [0, 0, " + num(-v) + "]}",
                       "{friction: 0.0, restitution: " + num(e) + "}") +
        "boundary_conditions:\n  - {body: plate, region: {box: [[-1, -1, -1], [1, 1, 1.0e-7]]}, "
        "velocity: [0, 0, 0]}\n";
    Model m = build_model(scene_from_text("apex", yaml));
    m.scene.fixed_dt = 0.05 * Simulation(m, RunOptions{}).stable_dt() / m.scene.safety;
    Simulation sim(m, {});
    Index apex = -1;
    for (Index i = 0; i < m.mesh.num_nodes(); ++i)
      if (m.mesh.node_body[i] == 1 &&
          (apex < 0 || sim.positions()[i].z() < sim.positions()[apex].z()))
        apex = i;
    while (sim.ledger().contacts == 0 && sim.time() < 1.0) sim.step();
    const double expected = 0.5 * (1 - e * e) * m.mass[apex] * v * v;
    std::printf("apex impact, e = %g: booked %.6e J, (1 - e^2) m v^2 / 2 = %.6e J, apex vz %.4f\n",
                e, sim.ledger().contact_dissipated, expected, sim.velocities()[apex].z());
    ASSERT_GT(sim.ledger().contacts, 0);
    EXPECT_CLOSE(sim.ledger().contact_dissipated, expected, 0.01, 1e-12 * m.mass[apex] * v * v);
    EXPECT_CLOSE(sim.velocities()[apex].z(), e * v, 0.01, 0);
  }
}

// A sliver (four nearly coplanar vertices, height 1/100 of the width: its smallest
// altitude sets a step 25 x shorter than the block's) and a needle (base 1/100 of its
// length, tip down) fall onto a block and bounce off, ringing; fixed step (see start()).
// The energy bound is 5 % for the needle (4.5e-6 measured) and 7.5 % for the sliver:
// since issue 18 the ledger books the contact's first-order work for e = 1 too, and for
// the sliver, which rings near the stability limit (K dt^2 / m ~ 1), the second-order
// terms that estimate leaves are as large as it: contact_work ends at -7.7e-7 J (5.8 % of
// the energy fed in, by the estimate) where kinetic + strain rose by about 3 %; the error,
// max 3.8 % without the term, is max 6.9 %, final -2.2 % with it (docs/extremes.md).
TEST(Extreme, SliverAndNeedleHitABlock) {
  for (const auto& [name, v, energy_tol] :
       {std::tuple{"sliver", kSliver, 0.075}, std::tuple{"needle", kNeedle, 0.05}}) {
    SCOPED_TRACE(name);
    const Started r = run_bad_tet_on_block(name, v, true);
    ASSERT_GT(r.w.contact_steps, 0);
    expect_clean(r.w, energy_tol);
    EXPECT_GT(body_velocity(*r.sim, 1).z() - body_velocity(*r.sim, 0).z(), 0.0)
        << "the tet did not bounce";
  }
}

// The same with the default, adaptive step (StepControl). It was re-evaluated from the
// deformed elements every step, followed the ringing sliver's vibration and pumped
// energy into it: +54 % in 11 600 steps (docs/extremes.md). Held now, it stays
// constant through the free flight after the bounce, and the ledger with it: the mean
// energy error over the last third of the free flight equals that over the first third
// to 1e-3 (measured: equal to 1e-6; the step that followed the state: 0.1). What is
// left is central difference's bounded oscillation, O((omega dt)^2) of the energy of a
// sliver ringing near the stability limit (measured -1.5 ... +11.4 %, mean 4.9 %, set by
// the impact; with the contact's first-order work booked for e = 1, issue 18: largest
// 13.0 %, mean -6.6 %, the estimate's second-order remainder, see the fixed-step test),
// so the bound on the error itself is 15 %, not the fixed-step case's at half this step.
TEST(Extreme, AdaptiveStepSliverHitsABlock) {
  std::vector<double> err;
  const Started r = run_bad_tet_on_block("sliver", kSliver, false, &err);
  expect_clean(r.w, 0.15);
  ASSERT_GT(err.size(), 9000u);
  const size_t third = err.size() / 3;
  double early = 0, late = 0;
  for (size_t k = 0; k < third; ++k) {
    early += err[k] / third;
    late += err[err.size() - third + k] / third;
  }
  std::printf(
      "sliver free flight: %zu steps, mean energy error %.6e (first third) %.6e (last third)\n",
      err.size(), early, late);
  EXPECT_LT(std::abs(late - early), 1e-3);
}

namespace {

/// An aluminium ring (R = 5 mm, 1 x 1 mm section; the expanding ring's material of
/// docs/validation.md) spinning about its axis at `omega`, with or without fracture.
std::string spinning_ring(const std::string& name, double omega, bool fracture, double end) {
  return "name: " + name + "\ntime: {end: " + num(end) +
         "}\nmaterials:\n"
         "  alu: {model: neo_hookean, density: 2750, youngs_modulus: 275.0e9, poisson_ratio: 0.3" +
         std::string(fracture ? ", fracture: {strength: 300.0e6, energy: 100.0}" : "") +
         "}\n"
         "bodies:\n"
         "  - {name: ring, material: alu, mesh: {shape: tube, inner_radius: 4.5e-3, outer_radius: "
         "5.5e-3, "
         "length: 1.0e-3, element_size: 5.0e-4}, angular_velocity: [0, 0, " +
         num(omega) + "]}\n";
}

}  // namespace

// Spun at a rim speed of 570 m/s the ring's hoop stress rho v^2 is 3 x its strength:
// it cracks and flies apart. Mass, linear momentum and the ledger with the cohesive
// terms are kept; angular momentum to round-off.
TEST(Extreme, SpinningRingFliesApart) {
  const double omega = 570.0 / 5e-3;
  Started r = start("spin_fracture", spinning_ring("spin_fracture", omega, true, 3e-6));
  const Vec3 L0 = r.sim->ledger().angular_momentum;
  double mass0 = 0;
  for (double mi : r.model->mass) mass0 += mi;
  r.w = run_watched(*r.sim, r.model->scene.end_time);
  const long fragments =
      r.sim->fracture()->fragments(r.sim->positions(), r.sim->velocities(), r.model->mass).count();
  double mass = 0;
  for (double mi : r.model->mass) mass += mi;
  const double dL = (r.sim->ledger().angular_momentum - L0).norm() / L0.norm();
  std::printf(
      "spin (fracture): %ld steps, %ld cohesive, %ld fragments, energy error max %.3e, dL %.2e, "
      "mass %.2e\n",
      r.w.steps, r.sim->ledger().cohesive_elements, fragments, r.w.max_energy_error, dL,
      mass / mass0 - 1);
  EXPECT_GE(fragments, 4);
  expect_clean(r.w, 2e-3);
  // Round-off (measured 6.5e-16): the cohesive forces include the variation of the
  // current normal, so they are the gradient of a rotation-invariant energy (without
  // that term: 5.9e-8, docs/extremes.md).
  EXPECT_LT(dL, 1e-13);
  EXPECT_CLOSE(mass, mass0, 1e-13, 0);
}

// Without fracture, at a rim speed of 0.6 c_d the neo-Hookean ring has no steady
// state: it stretches without bound. The run either completes with momenta and
// energy kept or stops with a diagnosis; here it completes, and the strain energy
// it reaches is reported.
TEST(Extreme, SpinningRingWithoutFractureStretches) {
  const double c_d = std::sqrt(275e9 * 0.7 / (1.3 * 0.4 * 2750));
  const double omega = 0.6 * c_d / 5e-3;
  Started r = start("spin_elastic", spinning_ring("spin_elastic", omega, false, 4e-6));
  const Vec3 L0 = r.sim->ledger().angular_momentum;
  r.w = run_watched(*r.sim, r.model->scene.end_time);
  double r_max = 0;
  for (const Vec3& x : r.sim->positions()) r_max = std::max(r_max, x.head<2>().norm());
  const double dL = (r.sim->ledger().angular_momentum - L0).norm() / L0.norm();
  std::printf(
      "spin (elastic): %ld steps, strain/KE0 %.3f, r_max %.3f mm, energy error max %.3e, dL %.2e\n",
      r.w.steps, r.sim->ledger().strain / r.w.first.kinetic, 1e3 * r_max, r.w.max_energy_error, dL);
  expect_clean(r.w, 1e-3);
  EXPECT_LT(dL, 1e-12);
  EXPECT_GT(r_max, 6e-3) << "the ring did not stretch";
}

namespace {

struct Drift {
  double max_error = 0;  ///< max |energy error| over the run
  double per_step = 0;   ///< least-squares slope of the energy error against the step
};

/// 1e6 steps of a single free tet (4 nodes; a breathing, shearing and spinning initial
/// velocity field, no contact), energy error sampled every 1000 steps.
Drift vibrate_million_steps(bool fixed_step) {
  const std::string file =
      one_tet("vibrating_tet", {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, kTet,
              Vec3::Zero());
  Started r = start("vibration",
                    "name: vibration\ntime: {end: 1.0e3}\nmaterials:\n" + std::string(kSoft) +
                        "bodies:\n  - {name: tet, material: soft, mesh: {file: " + file +
                        "}, velocity_gradient: [[20, 5, 0], [0, -10, 3], [4, 0, 15]]}\n",
                    fixed_step);
  Simulation& sim = *r.sim;
  const long steps = 1000000, every = 1000;
  std::vector<double> s, e;
  Drift d;
  for (long k = 1; k <= steps; ++k) {
    sim.step();
    if (k % every == 0) {
      s.push_back(static_cast<double>(k));
      e.push_back(sim.energy_error());
      d.max_error = std::max(d.max_error, std::abs(e.back()));
    }
  }
  const double n = static_cast<double>(s.size());
  double ms = 0, me = 0;
  for (size_t k = 0; k < s.size(); ++k) {
    ms += s[k] / n;
    me += e[k] / n;
  }
  double sxy = 0, sxx = 0;
  for (size_t k = 0; k < s.size(); ++k) {
    sxy += (s[k] - ms) * (e[k] - me);
    sxx += (s[k] - ms) * (s[k] - ms);
  }
  d.per_step = sxy / sxx;
  std::printf(
      "vibration (%s step): %ld steps, dt %.3e s, energy error max %.3e, drift %.3e per step (%.3e "
      "over the "
      "run)\n",
      fixed_step ? "fixed" : "adaptive", steps, sim.dt(), d.max_error, d.per_step,
      d.per_step * steps);
  return d;
}

}  // namespace

// 1e6 steps at a fixed step: central difference is symplectic, so the energy oscillates
// (O(dt^2): 0.7 % here, strain and kinetic energy trading places at large amplitude) but
// does not drift: less than 1e-3 over the run (measured -6.4e-12 per step, -6.4e-6 in all).
TEST(Extreme, MillionStepsOfFreeVibrationDoNotDrift) {
  const Drift d = vibrate_million_steps(true);
  EXPECT_TRUE(std::isfinite(d.max_error));
  EXPECT_LT(d.max_error, 0.03);
  EXPECT_LT(std::abs(d.per_step) * 1e6, 1e-3);
}

// The same with the default, adaptive step (StepControl). Re-evaluated every step from
// the deformed tet, the step used to follow the vibration: the energy error climbed to
// 1.0 (total doubled) at a drift of +1.2e-6 per step. Held, it is the fixed-step case at
// about twice the step: measured drift -9.4e-11 per step, oscillation 2.7 %.
TEST(Extreme, AdaptiveStepFreeVibrationDoesNotDrift) {
  const Drift d = vibrate_million_steps(false);
  EXPECT_TRUE(std::isfinite(d.max_error));
  EXPECT_LT(d.max_error, 0.03);
  EXPECT_LT(std::abs(d.per_step) * 1e6, 1e-3);
}

// Three cubes stacked on a plate held fixed, under gravity, with the seeds' cube
// material (E = 21000, rho = 0.0785, edge 1; mu = 0.5, e = 0), each set 1e-4 above the
// one below. Set down without velocity, the stack must settle and stay: the kinetic energy
// late in the run must be below its early peak (no jitter growth), and the top cube's centre
// must end where the gaps closed and the elastic compression put it,
// 2.5 - (2.5 + 1.5 + 0.25) rho g L / E = 2.5 - 1.56e-4, within 1e-4 (no sinking).
// The ledger stays within 2e-4 m g L (measured -5.4e-5 J = 7e-5 m g L; the set-down frees
// m g x the closed gaps, 4.6e-4 J, which e = 0 dissipates): it books the impulses' loss in
// resting contact together with the work of the contact's moves (docs/contact.md "The ledger
// with e < 1"); with the loss alone it gained 1.8e-2 J while the stack rested.
TEST(Extreme, StackedCubesRestUnderGravity) {
  const int n_cubes = 3;
  const double gap = 1e-4;
  std::string bodies =
      "  - {name: plate, material: cube, mesh: {shape: box, size: [2, 2, 1], center: [0, 0, -0.5], "
      "element_size: 0.5}}\n";
  for (int k = 0; k < n_cubes; ++k)
    bodies += "  - {name: c" + std::to_string(k) +
              ", material: cube, mesh: {shape: box, size: [1, 1, 1], center: [" + num(0.1 * k) +
              ", 0, " + num(0.5 + k + gap * (k + 1)) + "], element_size: 0.5}}\n";
  const double end = 0.5;
  Started r = start(
      "stack",
      "name: stack\ntime: {end: " + num(end) +
          "}\nmaterials:\n  cube: {model: neo_hookean, density: 0.0785, youngs_modulus: 21000, "
          "poisson_ratio: 0.3}\nbodies:\n" +
          bodies +
          "boundary_conditions:\n  - {body: plate, region: {box: [[-2, -2, -2], [2, 2, 0.1]]}, "
          "velocity: [0, 0, 0]}\n"
          "gravity: [0, 0, -9.81]\ncontact: {friction: 0.5, restitution: 0.0}\n");
  Simulation& sim = *r.sim;
  const Vec3 top0 = body_centre(sim, n_cubes);
  const double total0 = sim.ledger().total();
  // Kinetic energy: largest over the first and the last fifth of the run.
  double ke_early = 0, ke_late = 0;
  int penetrations = 0;
  long steps = 0;
  while (sim.time() < end - 1e-12) {
    sim.step();
    ++steps;
    penetrations += count_penetrations(sim);
    if (sim.time() < 0.2 * end) ke_early = std::max(ke_early, sim.ledger().kinetic);
    if (sim.time() > 0.8 * end) ke_late = std::max(ke_late, sim.ledger().kinetic);
  }
  const double rho = 0.0785, g = 9.81, E = 21000;
  const double settled = 2.5 - (2.5 + 1.5 + 0.25) * rho * g / E;
  const double sink = settled - body_centre(sim, n_cubes).z();
  const Ledger& l = sim.ledger();
  std::printf(
      "stack: %ld steps, KE max early %.3e late %.3e (m g L %.3e), top cube %.3e below the settled "
      "height "
      "(moved %.3e), ledger total %+.3e J (contact_dissipated %.3e J, capped %ld)\n",
      steps, ke_early, ke_late, rho * g, sink, top0.z() - body_centre(sim, n_cubes).z(), l.total(),
      l.contact_dissipated, l.contact_capped_steps);
  EXPECT_EQ(penetrations, 0);
  EXPECT_LT(ke_late, ke_early);
  EXPECT_LT(std::abs(sink), 1e-4);
  EXPECT_LT(std::abs(l.total() - total0), 2e-4 * rho * g);
}
