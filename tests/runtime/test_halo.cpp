// Halo exchange on a METIS decomposition of a meshed box, at any rank count:
// lumped masses and TET4 internal forces summed from owned elements through
// the halo equal the serial ones to round-off (bitwise when the rank order is
// the serial order, i.e. on one rank); computed by each rank from the whole
// local star of its nodes (owner-computes, no summation) they equal the
// serial ones bitwise; every rank sharing a node holds the same bits;
// update_ghosts copies owners' values exactly; explicit steps with the
// owner-computes scheme (ghost-only position updates) stay bitwise serial.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <unordered_map>
#include <vector>

#include "mpi_environment.hpp"
#include "kernels/error.hpp"
#include "kernels/tet4.hpp"
#include "mesh/partition.hpp"
#include "runtime/element_forces.hpp"
#include "runtime/halo.hpp"
#include "runtime/model.hpp"
#include "scene_text.hpp"

namespace shatter {
namespace {

/// The global model, built on every rank (Gmsh meshes deterministically), its
/// partition into the ranks of MPI_COMM_WORLD, and this rank's LocalMesh.
struct Decomposed {
  int rank = 0, size = 1;
  Model model;
  std::vector<int> part;
  LocalMesh local;
  std::vector<Index> global_node;  ///< [local node] global node index
  std::vector<Index> global_elem;  ///< [local element] global element index
  std::vector<Index> gid_order;    ///< global elements by ascending elem_gid
};

const Decomposed& decomposed() {
  static const Decomposed d = [] {
    Decomposed d;
    MPI_Comm_rank(MPI_COMM_WORLD, &d.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d.size);
    const std::string name = "halo_box_rank" + std::to_string(d.rank);
    d.model = build_model(test::scene_from_text(
        name,
        "name: halo_box\n"
        "time: {end: 1.0}\n"
        "materials:\n"
        "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: "
        "0.3}\n"
        "bodies:\n"
        "  - name: b\n"
        "    material: steel\n"
        "    mesh: {shape: box, size: [0.02, 0.016, 0.012], element_size: 0.0015, order: 1}\n"));
    const Mesh& g = d.model.mesh;
    d.part = partition_elements(g, d.size);
    d.local = extract_subdomain(g, d.part, d.rank);
    std::unordered_map<GlobalId, Index> node_of, elem_of;
    for (Index n = 0; n < g.num_nodes(); ++n) node_of[g.node_gid[n]] = n;
    for (Index e = 0; e < g.num_elements(); ++e) elem_of[g.elem_gid[e]] = e;
    for (GlobalId gid : d.local.mesh.node_gid) d.global_node.push_back(node_of.at(gid));
    for (GlobalId gid : d.local.mesh.elem_gid) d.global_elem.push_back(elem_of.at(gid));
    d.gid_order.resize(g.num_elements());
    std::iota(d.gid_order.begin(), d.gid_order.end(), 0);
    std::sort(d.gid_order.begin(), d.gid_order.end(),
              [&](Index a, Index b) { return g.elem_gid[a] < g.elem_gid[b]; });
    return d;
  }();
  return d;
}

/// A smooth, non-affine deformation of the reference coordinates (strains ~1e-2).
Vec3 deformed(const Vec3& X) {
  return X + Vec3(0.01 * std::sin(60 * X.y()) * X.x() + 2e-4 * std::cos(90 * X.z()),
                  0.02 * X.x() * std::cos(40 * X.z()) - 0.01 * X.y(),
                  30 * X.x() * X.y() + 0.005 * X.z());
}

/// Internal forces of the given global elements, scattered in the given order
/// into a zeroed array over global nodes.
std::vector<Vec3> scatter_forces(const Model& model, std::span<const Vec3> x,
                                 std::span<const Index> elems) {
  std::vector<Vec3> f(model.mesh.num_nodes(), Vec3::Zero());
  const NeoHookean& mat = model.materials[0];
  for (Index e : elems) {
    const Index* c = model.mesh.element(e);
    const Tet4Force out = tet4_internal_force(x[c[0]], x[c[1]], x[c[2]], x[c[3]],
                                              model.tet4_Dm_inv[e], model.element_volume[e], mat);
    for (int a = 0; a < 4; ++a) f[c[a]] += out.f.col(a);
  }
  return f;
}

/// Largest |f_i| over all nodes and components: the scale of force errors.
double max_abs(std::span<const Vec3> f) {
  double m = 0;
  for (const Vec3& v : f) m = std::max(m, v.cwiseAbs().maxCoeff());
  return m;
}

/// Count over ranks of the local nodes for which pred(n) holds.
long long global_count(Index n, auto pred) {
  long long c = 0, total = 0;
  for (Index i = 0; i < n; ++i) c += pred(i) ? 1 : 0;
  MPI_Allreduce(&c, &total, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  return total;
}

TEST(Halo, LumpedMassesEqualTheSerialOnes) {
  const Decomposed& d = decomposed();
  const Mesh& g = d.model.mesh;
  const Mesh& lm = d.local.mesh;
  const Index nn = lm.num_nodes();
  // Serial reference: each node's star summed from +0 in ascending element
  // gid (what recompute_node_masses does while elements are in gid order).
  std::vector<double> serial(g.num_nodes(), 0.0);
  for (Index e : d.gid_order)
    for (int a = 0; a < 4; ++a) serial[g.element(e)[a]] += d.model.element_node_mass[4 * e + a];
  if (std::is_sorted(g.elem_gid.begin(), g.elem_gid.end())) {
    for (Index n = 0; n < g.num_nodes(); ++n) ASSERT_EQ(serial[n], d.model.mass[n]) << "node " << n;
  }

  // Halo: partials from owned elements, summed in rank order.
  Halo halo(d.local, MPI_COMM_WORLD);
  std::vector<double> halo_mass(nn, 0.0), local_star(nn, 0.0);
  for (Index e = 0; e < lm.num_elements(); ++e)
    for (int a = 0; a < 4; ++a) {
      const double m = d.model.element_node_mass[4 * d.global_elem[e] + a];
      if (d.local.owns_element(e)) halo_mass[lm.element(e)[a]] += m;
      local_star[lm.element(e)[a]] += m;  // owner-computes: owned and ghost elements
    }
  halo.sum_nodal(halo_mass, 1);
  halo.update_ghosts(halo_mass, 1);
  halo.update_ghosts(local_star, 1);  // ghost-only nodes lack part of their star
  for (Index n = 0; n < nn; ++n) {
    const double ref = serial[d.global_node[n]];
    EXPECT_NEAR(halo_mass[n], ref, 1e-14 * ref) << "node " << lm.node_gid[n];
    ASSERT_EQ(local_star[n], ref) << "node " << lm.node_gid[n];
  }
  const long long differ =
      global_count(nn, [&](Index n) { return halo_mass[n] != serial[d.global_node[n]]; });
  if (d.size == 1) {
    EXPECT_EQ(differ, 0);
  }
  if (d.rank == 0)
    std::printf(
        "[ ranks %d ] halo-summed masses not bitwise serial at %lld node copies of %d nodes\n",
        d.size, differ, static_cast<int>(g.num_nodes()));
}

TEST(Halo, InternalForcesEqualTheSerialOnes) {
  const Decomposed& d = decomposed();
  const Mesh& g = d.model.mesh;
  const Mesh& lm = d.local.mesh;
  const Index nn = lm.num_nodes();
  std::vector<Vec3> x(g.num_nodes());
  for (Index n = 0; n < g.num_nodes(); ++n) x[n] = deformed(g.reference[n]);
  const std::vector<Vec3> serial = scatter_forces(d.model, x, d.gid_order);
  const double scale = max_abs(serial);
  // The production loop (colored blocks) agrees with the gid-ordered reference to round-off.
  std::vector<Vec3> colored(g.num_nodes());
  ElementForces(d.model).compute(x, colored);
  for (Index n = 0; n < g.num_nodes(); ++n)
    ASSERT_LE((colored[n] - serial[n]).cwiseAbs().maxCoeff(), 1e-13 * scale);

  // Local positions: reference coordinates deformed by the same map on every rank.
  std::vector<Vec3> xl(nn);
  for (Index n = 0; n < nn; ++n) xl[n] = deformed(lm.reference[n]);
  auto local_forces = [&](bool owned_only) {
    std::vector<Index> elems;
    for (Index e = 0; e < lm.num_elements(); ++e)
      if (!owned_only || d.local.owns_element(e)) elems.push_back(e);
    std::vector<Vec3> f(nn, Vec3::Zero());
    for (Index e : elems) {
      const Index ge = d.global_elem[e];
      const Index* c = lm.element(e);
      const Tet4Force out =
          tet4_internal_force(xl[c[0]], xl[c[1]], xl[c[2]], xl[c[3]], d.model.tet4_Dm_inv[ge],
                              d.model.element_volume[ge], d.model.materials[0]);
      for (int a = 0; a < 4; ++a) f[c[a]] += out.f.col(a);
    }
    return f;
  };

  Halo halo(d.local, MPI_COMM_WORLD);
  std::vector<Vec3> summed = local_forces(true);
  halo.sum_nodal(summed);
  const std::vector<Vec3> star = local_forces(false);
  for (Index n = 0; n < nn; ++n) {
    if (!d.local.node_touched[n]) continue;
    const Vec3& ref = serial[d.global_node[n]];
    EXPECT_LE((summed[n] - ref).cwiseAbs().maxCoeff(), 1e-13 * scale) << "node " << lm.node_gid[n];
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(star[n][c], ref[c]) << "node " << lm.node_gid[n] << " component " << c;
  }
  const long long differ = global_count(nn, [&](Index n) {
    return d.local.node_touched[n] && summed[n] != serial[d.global_node[n]];
  });
  if (d.size == 1) {
    EXPECT_EQ(differ, 0);
  }
  if (d.rank == 0)
    std::printf(
        "[ ranks %d ] halo-summed forces not bitwise serial at %lld node copies of %d nodes\n",
        d.size, differ, static_cast<int>(g.num_nodes()));

  // Every rank touching a node holds the owner's bits: updating from the
  // owners changes nothing on touched nodes.
  std::vector<Vec3> updated = summed;
  halo.update_ghosts(updated);
  for (Index n = 0; n < nn; ++n)
    if (d.local.node_touched[n]) {
      ASSERT_TRUE(updated[n] == summed[n]) << "node " << lm.node_gid[n];
    }
}

// The scheme recommended in docs/parallel.md: every rank integrates all the
// nodes it touches from their whole local star (forces accumulated in
// ascending element gid), and receives only the positions of ghost-only
// nodes. Central-difference steps then reproduce the serial run bit for bit.
TEST(Halo, OwnerComputesStepsAreBitwiseSerial) {
  const Decomposed& d = decomposed();
  const Model& model = d.model;
  const Mesh& g = model.mesh;
  const Mesh& lm = d.local.mesh;
  const Index nn = lm.num_nodes();
  const double dt = 5e-8;
  const int steps = 4;
  auto initial_velocity = [](const Vec3& X) { return Vec3(3 * X.y(), -200 * X.x() * X.z(), 1.0); };
  // One step on nodes [0, n) with masses m; forces(x, f) overwrites f.
  auto step = [&](std::vector<Vec3>& x, std::vector<Vec3>& v, std::vector<Vec3>& f,
                  const std::vector<double>& m, auto integrates, auto forces) {
    for (size_t n = 0; n < x.size(); ++n)
      if (integrates(n)) {
        v[n] -= (0.5 * dt / m[n]) * f[n];
        x[n] += dt * v[n];
      }
    forces(x, f);
    for (size_t n = 0; n < x.size(); ++n)
      if (integrates(n)) v[n] -= (0.5 * dt / m[n]) * f[n];
  };

  // Serial: global arrays, elements in gid order.
  std::vector<Vec3> xs(g.num_nodes()), vs(g.num_nodes()), fs;
  std::vector<double> ms(g.num_nodes(), 0.0);
  for (Index e : d.gid_order)
    for (int a = 0; a < 4; ++a) ms[g.element(e)[a]] += model.element_node_mass[4 * e + a];
  for (Index n = 0; n < g.num_nodes(); ++n) {
    xs[n] = deformed(g.reference[n]);
    vs[n] = initial_velocity(g.reference[n]);
  }
  auto serial_forces = [&](const std::vector<Vec3>& x, std::vector<Vec3>& f) {
    f = scatter_forces(model, x, d.gid_order);
  };
  serial_forces(xs, fs);
  for (int s = 0; s < steps; ++s)
    step(
        xs, vs, fs, ms, [](size_t) { return true; }, serial_forces);

  // Distributed: local arrays, all local elements in local (= gid) order.
  Halo halo(d.local, MPI_COMM_WORLD);
  std::vector<Vec3> xl(nn), vl(nn), fl(nn);
  std::vector<double> ml(nn, 0.0);
  for (Index e = 0; e < lm.num_elements(); ++e)
    for (int a = 0; a < 4; ++a)
      ml[lm.element(e)[a]] += model.element_node_mass[4 * d.global_elem[e] + a];
  for (Index n = 0; n < nn; ++n) {
    xl[n] = deformed(lm.reference[n]);
    vl[n] = initial_velocity(lm.reference[n]);
  }
  auto local_forces = [&](std::vector<Vec3>& x, std::vector<Vec3>& f) {
    halo.update_ghosts(x, GhostCopies::ghost_only);
    std::fill(f.begin(), f.end(), Vec3::Zero());
    for (Index e = 0; e < lm.num_elements(); ++e) {
      const Index ge = d.global_elem[e];
      const Index* c = lm.element(e);
      const Tet4Force out =
          tet4_internal_force(x[c[0]], x[c[1]], x[c[2]], x[c[3]], model.tet4_Dm_inv[ge],
                              model.element_volume[ge], model.materials[0]);
      for (int a = 0; a < 4; ++a) f[c[a]] += out.f.col(a);
    }
  };
  auto touched = [&](size_t n) { return d.local.node_touched[n] != 0; };
  local_forces(xl, fl);
  for (int s = 0; s < steps; ++s)
    step(xl, vl, fl, ml, touched,
         [&](std::vector<Vec3>& x, std::vector<Vec3>& f) { local_forces(x, f); });

  for (Index n = 0; n < nn; ++n) {
    if (!touched(n)) continue;
    const Index gn = d.global_node[n];
    ASSERT_TRUE(xl[n] == xs[gn] && vl[n] == vs[gn]) << "node " << lm.node_gid[n];
    ASSERT_NE(xl[n], deformed(lm.reference[n])) << "the nodes moved";
  }
}

TEST(Halo, SplitSumOverlapsWorkAndEqualsTheBlockingOne) {
  const Decomposed& d = decomposed();
  const Index nn = d.local.mesh.num_nodes();
  Halo halo(d.local, MPI_COMM_WORLD);
  std::vector<double> a(2 * static_cast<size_t>(nn));
  for (Index n = 0; n < nn; ++n) {
    const GlobalId gid = d.local.mesh.node_gid[n];
    a[2 * n] = d.local.node_touched[n] ? 1.0 / (gid + d.rank + 1) : 0.0;
    a[2 * n + 1] = d.local.node_touched[n] ? std::sqrt(double(gid) * (d.rank + 2)) : 0.0;
  }
  std::vector<double> b = a;
  halo.sum_nodal(a, 2);
  halo.begin_sum(b, 2);
  EXPECT_THROW(halo.begin_update(b, 2), Error);  // one exchange at a time
  double interior_work = 0;
  for (Index n = 0; n < nn; ++n) interior_work += std::sin(double(n));
  EXPECT_TRUE(std::isfinite(interior_work));
  halo.end_sum(b, 2);
  EXPECT_EQ(a, b);
  EXPECT_THROW(halo.end_sum(b, 2), Error);
  EXPECT_THROW(halo.sum_nodal(std::span<double>(b).first(b.size() - 1), 2), Error);
}

TEST(Halo, UpdateGhostsCopiesTheOwnersValues) {
  const Decomposed& d = decomposed();
  const Mesh& lm = d.local.mesh;
  const Index nn = lm.num_nodes();
  Halo halo(d.local, MPI_COMM_WORLD);
  const double nan = std::nan("");
  std::vector<Vec3> x(nn), v(nn);
  for (Index n = 0; n < nn; ++n) {
    const bool own = d.local.owns_node(n);
    x[n] = own ? deformed(lm.reference[n]) : Vec3::Constant(nan);
    v[n] = own ? Vec3(lm.node_gid[n], -0.5 * lm.node_gid[n], 1.0 / lm.node_gid[n])
               : Vec3::Constant(nan);
  }
  std::vector<Vec3> only = x;
  halo.update_ghosts(only, GhostCopies::ghost_only);
  halo.update_ghosts(x);
  halo.begin_update(std::span<const double>(v.data()->data(), 3 * v.size()), 3);
  halo.end_update(std::span<double>(v.data()->data(), 3 * v.size()), 3);
  for (Index n = 0; n < nn; ++n) {
    const double gid = lm.node_gid[n];
    ASSERT_TRUE(x[n] == deformed(lm.reference[n])) << "node " << lm.node_gid[n];
    ASSERT_TRUE(v[n] == Vec3(gid, -0.5 * gid, 1.0 / gid)) << "node " << lm.node_gid[n];
    const bool refreshed = d.local.owns_node(n) || !d.local.node_touched[n];
    ASSERT_EQ(only[n] == x[n], refreshed) << "ghost_only update of node " << lm.node_gid[n];
  }
  if (d.rank == 0) {
    const Decomposed& dd = d;
    std::printf(
        "[ ranks %d ] rank 0: %d elements (%d owned), %d nodes; sum %zu B in %d messages, "
        "update %zu B in %d messages, ghost-only update %zu B (3 doubles per node)\n",
        dd.size, static_cast<int>(lm.num_elements()),
        static_cast<int>(std::count(dd.local.elem_owner.begin(), dd.local.elem_owner.end(), 0)),
        static_cast<int>(nn), halo.sum_bytes(3), halo.sum_messages(), halo.update_bytes(3),
        halo.update_messages(), halo.update_bytes(3, GhostCopies::ghost_only));
  }
}

}  // namespace
}  // namespace shatter
