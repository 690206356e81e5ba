// Shells in DCR contact (issue 17, docs/shells.md "Contact"): two spherical
// shells of the seeds' two-sphere impact (R = 1, t = 0.05, E = 21 000,
// nu = 0.3, rho = 0.0785) on a coarse mesh, oblique at 50 relative, with and
// without friction; a solid box thrown at a shell. After every step: linear
// and angular momentum to round-off, and no penetration, checked without DCR
// code: the distance from every control vertex of one body to the other
// body's control triangles (closest point on the triangle, by brute force) is
// at least the pair's h = t/2 + t/2 (shell-shell) or t/2 (shell-solid), less
// a tolerance scaled to t. The ledger: frictionless within a bound; with
// friction the total (dissipation booked) closes. The seeds' sphere on a plate, coarse.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>

#include "contact/surface.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"

using namespace shatter;
using shatter::test::scene_from_text;

namespace {

constexpr double kThickness = 0.05;

/// The seeds' two shells, centres 2.3 apart in x and 0.8 in y, each at 25 toward the other.
std::string two_spheres(const std::string& name, double mu, double element_size, double dt) {
  std::ostringstream os;
  os << "name: " << name << "\ntime: {end: 1.0, dt: " << dt << "}\n"
     << "materials:\n  seed: {model: neo_hookean, density: 0.0785, youngs_modulus: 21000, poisson_ratio: 0.3}\n"
     << "bodies:\n";
  for (const auto& [body, cx, cy, vx] : {std::tuple{"left", -1.15, -0.4, 25.0}, std::tuple{"right", 1.15, 0.4, -25.0}})
    os << "  - name: " << body << "\n    material: seed\n    shell: {thickness: " << kThickness << "}\n"
       << "    mesh: {shape: sphere, radius: 1.0, center: [" << cx << ", " << cy << ", 0.0], element_size: "
       << element_size << "}\n    initial_velocity: [" << vx << ", 0.0, 0.0]\n";
  os << "contact: {friction: " << mu << ", restitution: 1.0}\n";
  return os.str();
}

/// Distance from p to the triangle (a, b, c): the closest point by regions (vertex, edge, face).
double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const Vec3 n = ab.cross(ac);
  const double nn = n.squaredNorm();
  if (nn > 0) {
    // Barycentric coordinates of the projection on the plane.
    const double lb = ap.cross(ac).dot(n) / nn, lc = ab.cross(ap).dot(n) / nn;
    if (lb >= 0 && lc >= 0 && lb + lc <= 1) return std::abs(ap.dot(n)) / std::sqrt(nn);
  }
  auto segment = [&](const Vec3& u, const Vec3& v) {
    const Vec3 d = v - u;
    const double s = d.squaredNorm() > 0 ? std::clamp((p - u).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    return (p - (u + s * d)).norm();
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

/// The smallest distance from a surface vertex of one body to a surface triangle of another
/// (brute force over the contact surface's triangles, each body's vertices against the
/// others' triangles), relative to the thickness h that pair of bodies keeps apart
/// (reach[vertex] + reach[triangle]): min over pairs of distance / h.
double smallest_relative_distance(const ContactSurface& s, const std::vector<int>& node_body,
                                  const std::vector<double>& reach, std::span<const Vec3> x) {
  double worst = std::numeric_limits<double>::infinity();
  for (const Index v : s.vertices)
    for (size_t t = 0; t < s.triangles.size(); ++t) {
      const auto& tri = s.triangles[t];
      if (node_body[tri[0]] == node_body[v]) continue;
      const double h = reach[v] + reach[tri[0]];
      worst = std::min(worst, point_triangle_distance(x[v], x[tri[0]], x[tri[1]], x[tri[2]]) / h);
    }
  return worst;
}

/// Per node: the half-thickness of its shell, 0 for a solid's node.
std::vector<double> node_reach(const Model& m) {
  std::vector<double> r(m.mesh.num_nodes(), 0.0);
  for (const ShellBody& s : m.shells)
    for (Index v = 0; v < s.mesh.num_vertices(); ++v) r[s.first_node + v] = 0.5 * s.thickness;
  return r;
}

/// What a contact run kept over its steps.
struct ContactRun {
  double dP = 0, dL = 0;       ///< largest |P - P0| / sum m|v|, |L - L0| / sum m |x| |v|
  double distance = 1e300;     ///< smallest relative distance (smallest_relative_distance)
  double energy = 0;           ///< largest |total - total(0)| / total(0)
  double kinetic_strain = 0;   ///< final (K + U) / total(0) - 1
  double dissipated = 0;       ///< contact_dissipated at the end / total(0)
  long contacts = 0;           ///< steps with a resolved pair
};

ContactRun run(const Model& m, Simulation& sim, int steps) {
  ContactRun r;
  const ContactSurface surface = [&] {
    std::vector<SurfaceTriangle> tris;
    for (const ShellBody& s : m.shells)
      for (const auto& t : s.mesh.triangles)
        tris.push_back({{s.first_node + t[0], s.first_node + t[1], s.first_node + t[2]}, s.body});
    ContactSurface solid = build_contact_surface(m.mesh);
    for (size_t t = 0; t < solid.triangles.size(); ++t) tris.push_back({solid.triangles[t], solid.body[t]});
    return make_contact_surface(tris);
  }();
  const std::vector<double> reach = node_reach(m);
  double scale_p = 0, scale_l = 0;
  Vec3 P0 = Vec3::Zero(), L0 = Vec3::Zero();
  for (Index i = 0; i < m.mesh.num_nodes(); ++i) {
    const Vec3 p = m.mass[i] * sim.velocities()[i];
    P0 += p, L0 += sim.positions()[i].cross(p);
    scale_p += p.norm(), scale_l += sim.positions()[i].norm() * p.norm();
  }
  const double total0 = sim.ledger().total();
  for (int n = 0; n < steps; ++n) {
    sim.step();
    Vec3 P = Vec3::Zero(), L = Vec3::Zero();
    for (Index i = 0; i < m.mesh.num_nodes(); ++i) {
      const Vec3 p = m.mass[i] * sim.velocities()[i];
      P += p, L += sim.positions()[i].cross(p);
    }
    r.dP = std::max(r.dP, (P - P0).norm() / scale_p);
    r.dL = std::max(r.dL, (L - L0).norm() / scale_l);
    r.energy = std::max(r.energy, std::abs(sim.ledger().total() - total0) / total0);
    r.contacts += sim.ledger().contacts > 0;
    r.distance = std::min(r.distance, smallest_relative_distance(surface, m.mesh.node_body, reach, sim.positions()));
  }
  r.kinetic_strain = (sim.ledger().kinetic + sim.ledger().strain) / total0 - 1;
  r.dissipated = sim.ledger().contact_dissipated / total0;
  return r;
}

/// Prints the run's figures and checks what every contact run must keep: momenta to 1e-13, no
/// vertex within h of another body's triangles (less 1e-4 h: DCR's gap is 1e-6 of an edge),
/// at least `contacts` steps in contact, the ledger's total within `energy`.
void expect_contact_run(const std::string& what, const ContactRun& r, long contacts, double energy) {
  std::cout << what << ": steps in contact " << r.contacts << ", dP " << r.dP << ", dL " << r.dL
            << ", smallest distance / h " << r.distance << ", energy error " << r.energy << ", K + U "
            << r.kinetic_strain << ", dissipated " << r.dissipated << "\n";
  EXPECT_GT(r.contacts, contacts);
  EXPECT_LT(r.dP, 1e-13);
  EXPECT_LT(r.dL, 1e-13);
  EXPECT_GT(r.distance, 1 - 1e-4);
  EXPECT_LT(r.energy, energy);
}

}  // namespace

// Frictionless and elastic, coarse (310 control vertices a sphere), 300 steps of 1e-4
// (0.77 of the stable step) to t = 0.03: momenta to round-off at every step, no control
// vertex within t of the other shell's control net (less 1e-4 t: the gap DCR leaves is
// 1e-6 of an edge), the ledger's total within 2e-3 (measured 2.5e-4; the same scene of
// solid TET4 spheres, scenes/regression/spheres_impact.yaml, 1.3e-2).
TEST(ShellContact, TwoSpheresFrictionless) {
  Model m = build_model(scene_from_text("shell_spheres", two_spheres("shell_spheres", 0.0, 0.25, 1e-4)));
  Simulation sim(m, {});
  expect_contact_run("two shells, mu = 0", run(m, sim, 300), 100, 2e-3);
}

// With Coulomb friction mu = 0.5: the same momenta and distance, friction takes energy
// (contact_dissipated > 0.1 % of the total; measured 8.8 %), and the ledger, with it
// booked, closes to 2e-3 (measured 3.8e-4).
TEST(ShellContact, TwoSpheresWithFrictionCloseTheLedger) {
  Model m = build_model(scene_from_text("shell_spheres_mu", two_spheres("shell_spheres_mu", 0.5, 0.25, 1e-4)));
  Simulation sim(m, {});
  const ContactRun r = run(m, sim, 300);
  expect_contact_run("two shells, mu = 0.5", r, 100, 2e-3);
  EXPECT_GT(r.dissipated, 1e-3);
}

// A solid box (TET4) thrown at a shell sphere, off-centre and spinning: shell-solid
// pairs both ways (box vertices on the sheet's faces, sheet vertices on the box's faces,
// their edges), h = t/2. Momenta to round-off, the box's surface vertices and the
// sheet's control vertices at least t/2 from the other's triangles, the ledger (friction
// mu = 0.3 booked) within 1e-2 (measured 3.3e-3).
TEST(ShellContact, SolidBoxOnAShell) {
  std::ostringstream os;
  os << "name: shell_box\ntime: {end: 1.0, dt: 1.0e-4}\n"
     << "materials:\n  seed: {model: neo_hookean, density: 0.0785, youngs_modulus: 21000, poisson_ratio: 0.3}\n"
     << "bodies:\n  - name: ball\n    material: seed\n    shell: {thickness: " << kThickness << "}\n"
     << "    mesh: {shape: sphere, radius: 1.0, center: [0, 0, 0], element_size: 0.25}\n"
     << "  - name: box\n    material: seed\n"
     << "    mesh: {shape: box, size: [0.6, 0.6, 0.6], center: [0.2, 0.1, 1.45], element_size: 0.2}\n"
     << "    initial_velocity: [0, 0, -20]\n    angular_velocity: [10, 20, 0]\n"
     << "contact: {friction: 0.3, restitution: 1.0}\n";
  Model m = build_model(scene_from_text("shell_box", os.str()));
  Simulation sim(m, {});
  expect_contact_run("box on a shell", run(m, sim, 200), 20, 1e-2);
}

// The seeds' sphere-on-plate impact (scenes/shell_sphere_on_plate.yaml), coarse: a
// spherical shell (R = 0.12, t = 0.0035) at 25 onto a free disk plate (R = 0.35, the
// same t), E = 210 000, nu = 0.3, rho = 0.785; a closed shell against one with free,
// ghost-completed edges. 400 steps at the shells' stable step (to ~0.0055, the sphere
// dented and rebounding): momenta to round-off, no control vertex within t of the other
// shell's control net, the ledger within 2e-3 (measured 4.7e-4).
TEST(ShellContact, SphereOnAPlate) {
  std::ostringstream os;
  os << "name: shell_sphere_plate\ntime: {end: 1.0}\n"
     << "materials:\n  seed: {model: neo_hookean, density: 0.785, youngs_modulus: 210000, poisson_ratio: 0.3}\n"
     << "bodies:\n  - name: sphere\n    material: seed\n    shell: {thickness: 0.0035}\n"
     << "    mesh: {shape: sphere, radius: 0.12, center: [0, 0, 0.1286], element_size: 0.03}\n"
     << "    initial_velocity: [0, 0, -25]\n"
     << "  - name: plate\n    material: seed\n    shell: {thickness: 0.0035}\n"
     << "    mesh: {shape: disk, radius: 0.35, center: [0, 0, 0], element_size: 0.05}\n"
     << "contact: {friction: 0.0, restitution: 1.0}\n";
  Model m = build_model(scene_from_text("shell_sphere_plate", os.str()));
  Simulation sim(m, {});
  expect_contact_run("sphere on a plate", run(m, sim, 400), 100, 2e-3);
}
