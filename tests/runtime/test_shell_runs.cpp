// Thin shells in the time loop (issue 17, docs/shells.md "The runtime"): a
// spherical shell from a scene (bodies[i].shell), run by Simulation: its
// lumped mass, momenta and energy while it spins and translates, its
// breathing frequency against membrane theory, a held cap, a checkpoint, the
// same bits for any thread count, and its mid-surface in fields.h5/xdmf.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <tuple>

#include "expect_close.hpp"
#include "mpi_environment.hpp"
#include "run_checks.hpp"
#include "runtime/checkpoint.hpp"
#include "kernels/loop_extraordinary.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;
using shatter::test::scene_from_text;

namespace {

constexpr double kYoung = 210.0e9, kPoisson = 0.3, kDensity = 7850;

/// A steel spherical shell of radius R and thickness t, meshed at h; `body`
/// lines are added to the body, `time` is the inside of time: {...}.
std::string sphere_scene(const std::string& name, double R, double t, double h, const std::string& body,
                         const std::string& time) {
  std::ostringstream os;
  os.precision(17);
  os << "name: " << name << "\ntime: {" << time << "}\n"
     << "materials:\n  steel: {model: neo_hookean, density: " << kDensity << ", youngs_modulus: " << kYoung
     << ", poisson_ratio: " << kPoisson << "}\n"
     << "bodies:\n  - name: ball\n    material: steel\n    shell: {thickness: " << t << "}\n"
     << "    mesh: {shape: sphere, radius: " << R << ", element_size: " << h << "}\n"
     << body;
  return os.str();
}

/// The model of sphere_scene(name, R, t, h, body) with time.end = 1 s (runs step by step).
Model sphere_model(const std::string& name, double R, double t, double h, const std::string& body) {
  return build_model(scene_from_text(name, sphere_scene(name, R, t, h, body, "end: 1.0")));
}

/// Linear and angular momentum of the model, from the positions and velocities.
std::pair<Vec3, Vec3> momenta(const Model& m, const Simulation& sim) {
  Vec3 P = Vec3::Zero(), L = Vec3::Zero();
  for (Index i = 0; i < m.mesh.num_nodes(); ++i) {
    const Vec3 p = m.mass[i] * sim.velocities()[i];
    P += p;
    L += sim.positions()[i].cross(p);
  }
  return {P, L};
}

/// What `steps` steps of a free run keep: the momenta before and after, the
/// largest |total - total(0)| over the steps and the kinetic energy at the start.
struct FreeRun {
  Vec3 P0, L0, P, L;
  double worst = 0, kinetic0 = 0;
};
FreeRun run_free(const Model& m, Simulation& sim, int steps) {
  FreeRun r;
  std::tie(r.P0, r.L0) = momenta(m, sim);
  const double total0 = sim.ledger().total();
  r.kinetic0 = sim.ledger().kinetic;
  for (int n = 0; n < steps; ++n) {
    sim.step();
    r.worst = std::max(r.worst, std::abs(sim.ledger().total() - total0));
  }
  std::tie(r.P, r.L) = momenta(m, sim);
  return r;
}

}  // namespace

// The lumped masses add up to rho t A (A the reference limit surface's area,
// partition of unity); the limit surface of a control net on the sphere lies
// inside it (at this coarse mesh, 310 vertices, 4.8 % inside).
TEST(ShellRuns, LumpedMassIsRhoTimesThicknessTimesArea) {
  const double R = 0.12, t = 0.0035;
  Model m = sphere_model("shell_mass", R, t, 0.03, "");
  ASSERT_EQ(m.shells.size(), 1u);
  const ShellBody& s = m.shells[0];
  EXPECT_EQ(m.mesh.num_elements(), 0);
  EXPECT_EQ(s.first_node, 0);
  EXPECT_EQ(m.mesh.num_nodes(), s.mesh.num_vertices());
  double total = 0;
  for (double mi : m.mass) {
    EXPECT_GT(mi, 0.0);
    total += mi;
  }
  EXPECT_CLOSE(total, kDensity * t * s.area, 1e-13, 0);
  EXPECT_CLOSE(m.body_mass[0], total, 1e-13, 0);
  const double R_limit = std::sqrt(s.area / (4 * std::numbers::pi));
  EXPECT_LT(R_limit, R);
  EXPECT_GT(R_limit, 0.94 * R);
}

// The limit surface at the vertices (the fields' mid-surface): a vertex's
// limit point is the same from every patch it is a regular corner of (to
// round-off, on a deformed net), its weights sum to 1, and at an extraordinary
// vertex Loop's limit mask agrees with the patch evaluated ever closer to
// that corner (the basis at v = w = eps: O(eps) away).
TEST(ShellRuns, LimitStencilsAgreeWithThePatches) {
  Model m = sphere_model("shell_limit", 0.12, 0.0035, 0.03, "");
  const ShellBody& s = m.shells[0];
  std::vector<Vec3> x = s.mesh.reference;
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] += 0.002 * Vec3(std::sin(3.0 * i), std::cos(5.0 * i), std::sin(7.0 * i + 1));
  auto limit = [&](Index v) {
    Vec3 p = Vec3::Zero();
    double sum = 0;
    for (Index k = s.limit_offsets[v]; k < s.limit_offsets[v + 1]; ++k)
      p += s.limit_weight[k] * x[s.limit_vertex[k]], sum += s.limit_weight[k];
    EXPECT_NEAR(sum, 1.0, 1e-14);
    return p;
  };
  Index compared = 0, extraordinary = 0;
  for (Index t = 0; t < s.mesh.num_triangles(); ++t)
    for (int c = 0; c < 3; ++c) {
      const Index v = s.mesh.triangles[t][c];
      const auto stencil = shell_corner_stencil(s, t, c);
      if (stencil.empty()) {
        // The extraordinary corner: the patch at v = w = eps tends to the mask's point.
        const double eps = 1e-5;
        with_valence(static_cast<int>(s.mesh.patch_size(t) - 6), [&](auto N) {
          if constexpr (N() != 6) {
            const auto b = loop_extraordinary_basis<N()>(eps, eps).N;
            Vec3 p = Vec3::Zero();
            for (int a = 0; a < N() + 6; ++a) p += b[a] * x[s.mesh.patch_of(t)[a]];
            EXPECT_LT((p - limit(v)).norm(), 10 * eps * 0.03) << "vertex " << v;
            ++extraordinary;
          }
        });
        continue;
      }
      Vec3 p = Vec3::Zero();
      for (const auto& [entry, w] : stencil) p += w * s.mesh.entry_position(x, entry);
      EXPECT_LT((p - limit(v)).norm(), 1e-14 * 0.12) << "vertex " << v << ", triangle " << t;
      ++compared;
    }
  EXPECT_GT(compared, 1000);
  EXPECT_GT(extraordinary, 50);
}

// The fields' membrane force on a sphere inflated uniformly by a strain eps
// (every control vertex scaled by 1 + eps, so is the limit surface): in every
// triangle n = E t eps / (1 - nu) (I - a3 a3) to O(eps, (t/R)^2) (plane-stress
// membrane theory): its in-plane trace to 0.2 %.
TEST(ShellRuns, MembraneForceOfAnInflatedSphere) {
  const double R = 0.12, t = 0.0035, eps = 1e-5;
  Model m = sphere_model("shell_inflate", R, t, 0.03, "");
  std::vector<Vec3> x = m.mesh.reference;
  for (Vec3& p : x) p *= 1 + eps;
  const std::vector<ShellResultants> r = ShellForces(m).resultants(x);
  ASSERT_EQ(r.size(), static_cast<size_t>(m.shells[0].mesh.num_triangles()));
  const double expected = kYoung * t * eps / (1 - kPoisson);
  for (size_t k = 0; k < r.size(); ++k) {
    EXPECT_NEAR(0.5 * r[k].n.trace(), expected, 2e-3 * expected) << "triangle " << k;
    // Isotropic in the tangent plane: eigenvalues (0, expected, expected), up to
    // the spread of the normal over the triangle's three points (~0.1 rad here).
    const Eigen::Vector3d lambda = Eigen::SelfAdjointEigenSolver<Mat3>(r[k].n).eigenvalues();
    EXPECT_LT(std::abs(lambda[0]), 0.03 * expected) << "triangle " << k;
    EXPECT_NEAR(lambda[1], expected, 0.03 * expected) << "triangle " << k;
    EXPECT_NEAR(lambda[2], expected, 0.03 * expected) << "triangle " << k;
  }
}

// A free shell spinning at ~10 m/s on its equator and translating: linear and
// angular momentum to round-off, and the ledger's total energy within 1e-6 of
// the kinetic energy (docs/shells.md "Measured through the runtime": 1e5 steps).
TEST(ShellRuns, SpinningSphereKeepsMomentaAndEnergy) {
  const double R = 0.12, t = 0.0035;
  Model m = sphere_model("shell_spin", R, t, 0.03, "    initial_velocity: [5, -2, 1]\n    angular_velocity: [0, 30, 80]\n");
  Simulation sim(m, {});
  const FreeRun r = run_free(m, sim, 3000);
  EXPECT_LT((r.P - r.P0).norm(), 1e-13 * r.P0.norm());
  EXPECT_LT((r.L - r.L0).norm(), 1e-13 * r.L0.norm());
  EXPECT_LT((sim.ledger().momentum - r.P0).norm(), 1e-13 * r.P0.norm());
  EXPECT_GT(sim.ledger().strain, 0.0);  // the spin stretches it: the shell elements run
  std::cout << "spinning shell: 3000 steps, dt " << sim.dt() << " s, |dP|/|P| " << (r.P - r.P0).norm() / r.P0.norm()
            << ", |dL|/|L| " << (r.L - r.L0).norm() / r.L0.norm() << ", energy error " << r.worst / r.kinetic0
            << " of the kinetic energy\n";
  EXPECT_LT(r.worst, 1e-6 * r.kinetic0);
}

// Breathing mode of a free spherical shell from an initial radial velocity
// (velocity_gradient = rate I): omega^2 = 2 E / (rho R^2 (1 - nu)) (membrane
// theory; bending adds O(t^2/R^2)), R the limit surface's radius. The kinetic
// energy (history.csv's column) has its minima twice per period.
TEST(ShellRuns, BreathingFrequencyMatchesMembraneTheory) {
  const double R = 1.0, t = 0.01;
  Model m = sphere_model("shell_breathe", R, t, 0.25,
                         "    velocity_gradient: [[1.0e-3, 0, 0], [0, 1.0e-3, 0], [0, 0, 1.0e-3]]\n");
  const double R_limit = std::sqrt(m.shells[0].area / (4 * std::numbers::pi));
  const double omega = std::sqrt(2 * kYoung / (kDensity * R_limit * R_limit * (1 - kPoisson)));
  Simulation sim(m, {});
  std::vector<double> minima;  // times of the kinetic energy's minima (parabola through three steps)
  double k2 = sim.ledger().kinetic, k1 = k2, t1 = 0;
  while (minima.size() < 5) {
    sim.step();
    const double k0 = sim.ledger().kinetic;
    if (k1 < k2 && k1 <= k0 && sim.steps() > 2) {
      const double dt = sim.time() - t1;  // steps of equal length here
      minima.push_back(t1 + 0.5 * dt * (k2 - k0) / (k2 - 2 * k1 + k0));
    }
    k2 = k1, k1 = k0, t1 = sim.time();
    ASSERT_LT(sim.time(), 20 * 2 * std::numbers::pi / omega);
  }
  const double period = 0.5 * (minima[4] - minima[0]);  // four half periods
  const double measured = 2 * std::numbers::pi / period;
  std::cout << "breathing shell: " << m.mesh.num_nodes() << " control vertices, omega " << measured
            << " rad/s, membrane theory " << omega << " (R_limit " << R_limit << "), error "
            << measured / omega - 1 << "\n";
  EXPECT_CLOSE(measured, omega, 0.02, 0);
}

// A sphere whose bottom cap is held (a box region, all three components)
// while the rest is thrown upward: the held vertices do not move, the free ones
// do, and the ledger (reaction work included, 0 on a held support) keeps its
// total within 1e-3 of the kinetic energy it started with: the sudden start
// excites the highest modes, whose central-difference energy swings (measured
// 1.6e-4; a wrong support or mass would be off by O(1)).
TEST(ShellRuns, HeldCapKeepsTheLedger) {
  Model m = sphere_model("shell_held", 0.12, 0.0035, 0.03,
                         "    initial_velocity: [0, 0, 2]\nboundary_conditions:\n  - body: ball\n"
                         "    region: {box: [[-1, -1, -1], [1, 1, -0.1]]}\n    velocity: [0, 0, 0]\n");
  std::vector<Index> held;
  for (Index i = 0; i < m.mesh.num_nodes(); ++i)
    if (m.bc_mask[i] == 7) held.push_back(i);
  ASSERT_GT(held.size(), 3u);
  Simulation sim(m, {});
  const FreeRun r = run_free(m, sim, 500);
  for (Index i : held) EXPECT_EQ(sim.positions()[i], m.mesh.reference[i]);
  EXPECT_GT(sim.ledger().strain, 1e-3 * r.kinetic0);  // the cap pulls the shell back
  std::cout << "held cap: 500 steps, strain " << sim.ledger().strain << " J, energy error " << r.worst / r.kinetic0
            << " of the initial kinetic energy\n";
  EXPECT_LT(r.worst, 1e-3 * r.kinetic0);
}

// An open shell (a cylinder's side: its two circular edges free, their
// triangles completed by ghost vertices, docs/shells.md "The control mesh"),
// spinning, translating and breathing: momenta to round-off, and the energy
// swinging within 1e-3 of the kinetic energy without drift (measured 1.3e-4
// over 1770 steps; the free edges' accuracy is not validated).
TEST(ShellRuns, FreeCylinderKeepsMomentaAndEnergy) {
  std::ostringstream yaml;
  yaml << "name: shell_cylinder\ntime: {end: 1.0}\nmaterials:\n  steel: {model: neo_hookean, density: " << kDensity
       << ", youngs_modulus: " << kYoung << ", poisson_ratio: " << kPoisson << "}\n"
       << "bodies:\n  - name: tube\n    material: steel\n    shell: {thickness: 0.002}\n"
       << "    mesh: {shape: cylinder, radius: 0.1, length: 0.3, element_size: 0.03}\n"
       << "    initial_velocity: [1, 0, 0]\n    angular_velocity: [0, 0, 50]\n"
       << "    velocity_gradient: [[10, 0, 0], [0, 10, 0], [0, 0, 0]]\n";
  Model m = build_model(scene_from_text("shell_cylinder", yaml.str()));
  ASSERT_GT(m.shells[0].mesh.num_ghosts(), 0);  // the free edges' ghosts are in use
  Simulation sim(m, {});
  const FreeRun r = run_free(m, sim, 600);
  EXPECT_LT((r.P - r.P0).norm(), 1e-13 * r.P0.norm());
  EXPECT_LT((r.L - r.L0).norm(), 1e-13 * r.L0.norm());
  EXPECT_GT(sim.ledger().strain, 1e-3 * r.kinetic0);
  EXPECT_LT(r.worst, 1e-3 * r.kinetic0);
}

// A checkpoint of a shell run (its control vertices are the model's nodes)
// continues bitwise as the run that never stopped.
TEST(ShellRuns, RestoredRunIsBitwiseTheUninterruptedOne) {
  const Scene scene = scene_from_text(
      "shell_ckpt", sphere_scene("shell_ckpt", 0.12, 0.0035, 0.03,
                                 "    initial_velocity: [3, -1, 2]\n    angular_velocity: [200, 500, -300]\n", "end: 1.0"));
  Model whole_model = build_model(scene);
  Simulation whole(whole_model, {});
  for (int s = 0; s < 60; ++s) whole.step();
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shell_ckpt";
  std::filesystem::create_directories(dir);
  {
    Model first_model = build_model(scene);
    Simulation first(first_model, {});
    for (int s = 0; s < 25; ++s) first.step();
    SimulationState state;
    first.save_state(state);
    write_checkpoint(dir / "checkpoint.h5", first_model, state);
  }
  Model second_model = build_model(scene);
  Simulation second(second_model, {});
  second.restore_state(read_checkpoint(dir / "checkpoint.h5", second_model));
  for (int s = 0; s < 35; ++s) second.step();
  EXPECT_EQ(second.time(), whole.time());
  EXPECT_EQ(second.ledger().total(), whole.ledger().total());
  ASSERT_EQ(second.positions().size(), whole.positions().size());
  EXPECT_EQ(0, std::memcmp(second.positions().data(), whole.positions().data(), whole.positions().size() * sizeof(Vec3)));
  EXPECT_EQ(0,
            std::memcmp(second.velocities().data(), whole.velocities().data(), whole.velocities().size() * sizeof(Vec3)));
}

// Same input, any thread count: the same bits (ShellForces sums each vertex's
// patch slots in a fixed order).
TEST(ShellRuns, BitwiseIdenticalForThreads124) {
  shatter::test::expect_same_bits_for_threads(
      scene_from_text("shell_det", sphere_scene("shell_det", 0.12, 0.0035, 0.03,
                                                "    initial_velocity: [3, -1, 2]\n"
                                                "    velocity_gradient: [[300, 50, 0], [0, -200, 80], [10, 0, 100]]\n"
                                                "    angular_velocity: [200, 500, -300]\n",
                                                "end: 1.0")),
      100);
}

// fields.h5 holds the shells' control triangles and the nodes' displacement;
// fields.xdmf names them as a Triangle grid.
TEST(ShellRuns, FieldsHoldTheMidSurface) {
  const auto dir = std::filesystem::path(SHATTER_BINARY_DIR "/test_scratch") / "shell_fields";
  std::filesystem::remove_all(dir);
  Model m = build_model(scene_from_text(
      "shell_fields", sphere_scene("shell_fields", 0.12, 0.0035, 0.03,
                                   "    initial_velocity: [5, 0, 0]\noutput: {every: 10}\n", "end: 2.0e-6, dt: 1.0e-7")));
  RunOptions opt;
  opt.out_dir = dir;
  opt.quiet = true;
  {
    Simulation sim(m, opt);
    sim.run();
  }
  std::ifstream in(dir / "fields.xdmf");
  const std::string xdmf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(xdmf.find("TopologyType=\"Triangle\""), std::string::npos);
  EXPECT_EQ(xdmf.find("Tetrahedron"), std::string::npos);  // no solids: no empty grid
  const hid_t file = H5Fopen((dir / "fields.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t coordinates = H5Dopen2(file, "/mesh/0/shell_coordinates", H5P_DEFAULT);
  ASSERT_GE(coordinates, 0);
  std::vector<Vec3> X(m.shells[0].mesh.num_vertices());
  H5Dread(coordinates, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, X.data());
  H5Dclose(coordinates);
  for (const Vec3& p : X) EXPECT_LT(p.norm(), 0.12);  // the limit surface lies inside the control net
  const hid_t set = H5Dopen2(file, "/mesh/0/shell_topology", H5P_DEFAULT);
  ASSERT_GE(set, 0);
  const hid_t space = H5Dget_space(set);
  hsize_t dims[2] = {0, 0};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], static_cast<hsize_t>(m.shells[0].mesh.num_triangles()));
  EXPECT_EQ(dims[1], 3u);
  H5Sclose(space);
  H5Dclose(set);
  // The limit surface's displacement in frame 10: the translation, 5 m/s x 1 us
  // (the weights sum to 1), the shell being unstrained.
  const hid_t disp = H5Dopen2(file, "/step_000010/shell_displacement", H5P_DEFAULT);
  ASSERT_GE(disp, 0);
  std::vector<Vec3> u(X.size());
  H5Dread(disp, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, u.data());
  H5Dclose(disp);
  H5Fclose(file);
  for (const Vec3& ui : u) EXPECT_LT((ui - Vec3(5.0e-6, 0, 0)).norm(), 1e-15);
}
