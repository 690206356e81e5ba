// Shell control meshes: valences, boundaries, orientation and Loop patches
// of a regular lattice and of Gmsh surfaces; bad triangle meshes refused.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <iostream>
#include <numbers>

#include "expect_close.hpp"
#include "kernels/loop_extraordinary.hpp"
#include "kernels/shell_kl.hpp"
#include "mesh/mesh_test_helpers.hpp"
#include "mesh/shell_gmsh.hpp"
#include "mesh/shell_mesh.hpp"
#include "mesh/shell_subdivision.hpp"

using namespace shatter;
using shatter::test::input_error;

namespace {
const Vec3 kE1(1, 0, 0), kE2(0.5, std::sqrt(3.0) / 2, 0);

/// An n x n parallelogram of the equilateral lattice (edge 1, in z = 0),
/// vertex (i, j) = i e1 + j e2 at index i + n j; every other triangle of a
/// checkerboard of cells given clockwise when `flip`.
ShellMesh lattice(int n, bool flip = false) {
  std::vector<Vec3> x;
  std::vector<std::array<Index, 3>> tris;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) x.push_back(i * kE1 + j * kE2);
  auto id = [n](int i, int j) { return Index(i + n * j); };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const bool f = flip && (i + j) % 2 == 1;
      tris.push_back(f ? std::array{id(i, j), id(i, j + 1), id(i + 1, j)}
                       : std::array{id(i, j), id(i + 1, j), id(i, j + 1)});
      tris.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return build_shell_mesh(std::move(x), std::move(tris), "lattice");
}

/// The limit surface point of triangle t at (v, w), from its patch.
template <int K>
Vec3 patch_point(const ShellMesh& m, Index t, const Eigen::Matrix<double, K, 1>& N) {
  Vec3 x = Vec3::Zero();
  for (int a = 0; a < K; ++a) x += N[a] * m.reference[m.patch_of(t)[a]];
  return x;
}
Vec3 limit_point(const ShellMesh& m, Index t, double v, double w) {
  switch (m.patch_size(t)) {
    case 12:
      return patch_point<12>(m, t, loop_regular_basis(v, w).N);
    case 9:
      return patch_point<9>(m, t, loop_extraordinary_basis<3>(v, w).N);
    case 10:
      return patch_point<10>(m, t, loop_extraordinary_basis<4>(v, w).N);
    case 11:
      return patch_point<11>(m, t, loop_extraordinary_basis<5>(v, w).N);
    case 13:
      return patch_point<13>(m, t, loop_extraordinary_basis<7>(v, w).N);
    case 14:
      return patch_point<14>(m, t, loop_extraordinary_basis<8>(v, w).N);
    default:
      ADD_FAILURE() << "valence " << m.patch_size(t) - 6 << " not covered";
      return Vec3::Zero();
  }
}

/// The n x n square lattice of edge 1 (test::square_shell_lattice).
ShellMesh square(int n) { return shatter::test::square_shell_lattice(n, 1.0, "square"); }

Vec3 normal(const ShellMesh& m, Index t) {
  const auto& c = m.triangles[t];
  return (m.reference[c[1]] - m.reference[c[0]]).cross(m.reference[c[2]] - m.reference[c[0]]);
}
}  // namespace

TEST(ShellMesh, LatticePatchesFollowTheLoopBasisOrder) {
  // Every triangle has its 12-vertex patch at the lattice offsets of
  // kernels/loop_basis.hpp, boundary ones through ghost vertices (which a
  // flat lattice puts on lattice points), the parallelogram's corners too.
  const int n = 8;
  for (bool flip : {false, true}) {
    const ShellMesh m = lattice(n, flip);
    int regular = 0, boundary = 0, unsupported = 0;
    for (Index v = 0; v < m.num_vertices(); ++v) {
      const int i = v % n, j = v / n;
      const bool edge = i == 0 || j == 0 || i == n - 1 || j == n - 1;
      EXPECT_EQ(m.on_boundary[v], edge ? 1 : 0);
      if (!edge) {
        EXPECT_EQ(m.valence[v], 6);
      }
    }
    auto at_corner = [&](Index v) { return v == 0 || v == n - 1 || v == n * (n - 1) || v == n * n - 1; };
    for (Index t = 0; t < m.num_triangles(); ++t) {
      EXPECT_GT(normal(m, t).z(), 0) << "triangle " << t;  // all oriented as the first
      bool touches_edge = false, touches_corner = false;
      for (Index v : m.triangles[t]) {
        touches_edge = touches_edge || m.on_boundary[v];
        touches_corner = touches_corner || at_corner(v);
      }
      if (m.patch_kind[t] == ShellPatchKind::unsupported_boundary) {
        EXPECT_TRUE(touches_corner) << "triangle " << t;
        EXPECT_EQ(m.patch_size(t), 0);
        ++unsupported;
        continue;
      }
      ASSERT_EQ(m.patch_kind[t], touches_edge ? ShellPatchKind::boundary : ShellPatchKind::regular) << t;
      ASSERT_EQ(m.patch_size(t), 12);
      ++(touches_edge ? boundary : regular);
      const Index* p = m.patch_of(t);
      EXPECT_EQ(p[3], m.triangles[t][0]);
      EXPECT_EQ(p[6], m.triangles[t][1]);
      EXPECT_EQ(p[7], m.triangles[t][2]);
      const Vec3 x4 = m.reference[p[3]], e1 = m.reference[p[6]] - x4, e2 = m.reference[p[7]] - x4;
      for (int a = 0; a < 12; ++a)
        EXPECT_LT((m.entry_position(m.reference, p[a]) -
                   (x4 + kLoopRegularLattice[a][0] * e1 + kLoopRegularLattice[a][1] * e2))
                      .norm(),
                  1e-12)
            << "triangle " << t << " patch vertex " << a;
    }
    EXPECT_EQ(regular, 2 * (n - 3) * (n - 3));
    EXPECT_EQ(boundary + unsupported + regular, m.num_triangles());
    // the 60 and 120 degree corners too, by single reflections that agree
    EXPECT_EQ(unsupported, 0);
    // one row of ghosts outside each side, shared between patches
    EXPECT_LE(m.num_ghosts(), 4 * (n + 1));
  }
}

TEST(ShellMesh, GhostVerticesKeepContinuityAndMomentumBalance) {
  // On a curved, deformed lattice, ghost-completed patches meet their
  // neighbours, and their forces, scattered through the ghost rules, have no
  // resultant and no moment. The square lattice has a patch on every
  // triangle, its right-angled corners' too (ghosts reflected across both
  // edges); clamped (even ghosts), the patches still meet.
  const int n = 7;
  ShellMesh square_clamped = square(n);
  clamp_shell_edges(square_clamped, square_clamped.on_boundary);
  const ShellMesh meshes[] = {lattice(n), square(n), square_clamped};
  for (int which = 0; which < 3; ++which) {
  const ShellMesh& m = meshes[which];
  if (which > 0) {
    for (Index t = 0; t < m.num_triangles(); ++t) ASSERT_EQ(m.patch_size(t), 12) << "triangle " << t;
  }
  std::vector<Vec3> X = m.reference;
  for (Vec3& p : X) p.z() = 0.05 * (p.x() * p.x() - p.y() * p.y());
  std::vector<Vec3> x = X;
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] += 0.02 * Vec3(std::sin(3.0 * i), std::cos(5.0 * i), std::sin(7.0 * i));
  const auto basis = loop_regular_basis_at_quadrature<3>();
  const NeoHookean mat = NeoHookean::from_young_poisson(1e9, 0.3, 1000);
  std::vector<Vec3> f(x.size(), Vec3::Zero());
  double fnorm = 0;
  int ghosts_used = 0;
  for (Index t = 0; t < m.num_triangles(); ++t) {
    if (m.patch_size(t) != 12) continue;
    Eigen::Matrix<double, 3, 12> Xe, xe;
    for (int a = 0; a < 12; ++a) {
      Xe.col(a) = m.entry_position(X, m.patch_of(t)[a]);
      xe.col(a) = m.entry_position(x, m.patch_of(t)[a]);
    }
    const auto out = shell_internal_force<12, 3>(xe, basis, shell_reference<12, 3>(Xe, basis, 0.05), mat);
    fnorm = std::max(fnorm, out.f.norm());
    for (int a = 0; a < 12; ++a) {
      ghosts_used += m.patch_of(t)[a] >= m.num_vertices();
      m.scatter_entry(m.patch_of(t)[a], [&](Index v, double w) { f[v] += w * out.f.col(a); });
    }
  }
  ASSERT_GT(ghosts_used, 0);
  // neighbouring patches, ghost-completed or not, meet on their common edge
  const double corner_vw[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  auto limit = [&](Index t, double v, double w) {
    const auto N = loop_regular_basis(v, w).N;
    Vec3 p = Vec3::Zero();
    for (int a = 0; a < 12; ++a) p += N[a] * m.entry_position(x, m.patch_of(t)[a]);
    return p;
  };
  for (Index t = 0; t < m.num_triangles(); ++t)
    for (Index u = t + 1; u < m.num_triangles(); ++u) {
      if (m.patch_size(t) != 12 || m.patch_size(u) != 12) continue;
      int kt[2], ku[2], shared = 0;
      for (int i = 0; i < 3 && shared < 2; ++i)
        for (int j = 0; j < 3; ++j)
          if (m.triangles[t][i] == m.triangles[u][j]) kt[shared] = i, ku[shared++] = j;
      if (shared < 2) continue;
      auto mid = [&](const int k[2], int c) { return 0.5 * (corner_vw[k[0]][c] + corner_vw[k[1]][c]); };
      EXPECT_LT((limit(t, mid(kt, 0), mid(kt, 1)) - limit(u, mid(ku, 0), mid(ku, 1))).norm(), 1e-13 * n)
          << "triangles " << t << " and " << u;
    }
  if (which == 2) continue;  // a clamp takes moments
  Vec3 sum = Vec3::Zero(), moment = Vec3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    sum += f[i];
    moment += x[i].cross(f[i]);
  }
  EXPECT_LT(sum.norm(), 1e-12 * fnorm);
  EXPECT_LT(moment.norm(), 1e-12 * fnorm * n);
  }
}

TEST(ShellMesh, FlatSquareStaysFlatAndUnstressed) {
  // Every patch of a flat square lattice, corners and clamped edges
  // included, reproduces the plane: in the reference configuration and
  // after a rigid motion (odd ghosts) no force and no energy; moved as a
  // whole in its plane, clamped, the same.
  const int n = 6;
  const auto basis = loop_regular_basis_at_quadrature<3>();
  const NeoHookean mat = NeoHookean::from_young_poisson(1e9, 0.3, 1000);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  for (bool clamped : {false, true}) {
    ShellMesh m = square(n);
    if (clamped) clamp_shell_edges(m, m.on_boundary);
    std::vector<Vec3> x = m.reference;
    for (Vec3& p : x) p = clamped ? Vec3(p + Vec3(0.3, -0.2, 0)) : Vec3(R * p + Vec3(0.3, -0.2, 0.5));
    double area = 0;
    for (Index t = 0; t < m.num_triangles(); ++t) {
      ASSERT_EQ(m.patch_size(t), 12);
      Eigen::Matrix<double, 3, 12> Xe, xe;
      for (int a = 0; a < 12; ++a) {
        Xe.col(a) = m.entry_position(m.reference, m.patch_of(t)[a]);
        xe.col(a) = m.entry_position(x, m.patch_of(t)[a]);
      }
      const auto ref = shell_reference<12, 3>(Xe, basis, 0.01);
      for (const auto& q : ref) area += q.area_weight;
      const auto out = shell_internal_force<12, 3>(xe, basis, ref, mat);
      // against a 1 % stretch's force (E t 0.01 x 1 m) and energy (E t 0.01^2 / 2 x 1 m^2)
      EXPECT_LT(out.f.norm(), 1e-12 * 1e9 * 0.01 * 0.01) << "triangle " << t << (clamped ? " clamped" : "");
      EXPECT_LT(std::abs(out.energy), 1e-12 * 0.5 * 1e9 * 0.01 * 1e-4) << "triangle " << t;
      for (int q = 0; q < 3; ++q) {
        Vec3 p = Vec3::Zero();
        for (int a = 0; a < 12; ++a) p += basis[q].N[a] * xe.col(a);
        EXPECT_LT(std::abs((clamped ? p : Vec3(R.transpose() * (p - Vec3(0.3, -0.2, 0.5)))).z()), 1e-13);
      }
    }
    EXPECT_NEAR(area, (n - 1) * (n - 1), 1e-12);  // the limit surface is the square
  }
}

TEST(ShellMesh, LumpedMassOfAnInteriorVertexIsItsShareOfTheArea) {
  // Every triangle within two rings of the centre vertex is regular; its mass
  // is rho t x the lattice area per vertex, sqrt(3)/2 (edge 1).
  const int n = 9;
  const ShellMesh m = lattice(n);
  const Index centre = 4 + n * 4;
  const double t = 0.01, rho = 1000;
  const auto basis = loop_regular_basis_at_quadrature<3>();
  double mass = 0;
  for (Index e = 0; e < m.num_triangles(); ++e) {
    if (m.patch_kind[e] != ShellPatchKind::regular) continue;
    Eigen::Matrix<double, 3, 12> X;
    for (int a = 0; a < 12; ++a) X.col(a) = m.reference[m.patch_of(e)[a]];
    const auto ref = shell_reference<12, 3>(X, basis, t);
    const auto me = shell_lumped_mass<12, 3>(basis, ref, t, rho);
    for (int a = 0; a < 12; ++a)
      if (m.patch_of(e)[a] == centre) mass += me[a];
  }
  EXPECT_CLOSE(mass, rho * t * std::sqrt(3.0) / 2, 1e-13, 0);
}

TEST(ShellMesh, GmshSphereIsClosedOutwardAndItsPatchesLieOnTheSphere) {
  ShellShapeSpec s;
  s.shape = "sphere";
  s.radius = 0.12;
  s.center = Vec3(0.1, -0.2, 0.3);
  s.element_size = 0.02;
  const ShellMesh m = mesh_shell_shape(s, "sphere");
  // closed: V - E + F = 2, no boundary
  Index edges = 0;
  for (Index v = 0; v < m.num_vertices(); ++v) {
    edges += m.valence[v];
    EXPECT_EQ(m.on_boundary[v], 0);
  }
  EXPECT_EQ(m.num_vertices() - edges / 2 + m.num_triangles(), 2);
  int counts[5] = {0, 0, 0, 0, 0};
  const auto basis = loop_regular_basis_at_quadrature<1>();
  for (Index t = 0; t < m.num_triangles(); ++t) {
    const auto& c = m.triangles[t];
    const Vec3 centroid = (m.reference[c[0]] + m.reference[c[1]] + m.reference[c[2]]) / 3;
    EXPECT_GT(normal(m, t).dot(centroid - s.center), 0) << "triangle " << t;  // outward
    ++counts[static_cast<int>(m.patch_kind[t])];
    if (m.patch_kind[t] == ShellPatchKind::extraordinary) {
      EXPECT_EQ(m.patch_size(t), m.valence[c[0]] + 6);
      EXPECT_NE(m.valence[c[0]], 6);
      EXPECT_EQ(m.patch_of(t)[1], c[1]);
      EXPECT_EQ(m.patch_of(t)[2], c[2]);
    }
    if (m.patch_kind[t] != ShellPatchKind::regular) continue;
    // the limit surface of a regular patch lies within 2 % of the radius
    Eigen::Matrix<double, 3, 12> X;
    for (int a = 0; a < 12; ++a) X.col(a) = m.reference[m.patch_of(t)[a]];
    EXPECT_CLOSE((X * basis[0].N - s.center).norm(), s.radius, 0.02, 0);
  }
  EXPECT_GT(counts[0], 0);
  EXPECT_GT(counts[1], 0);
  EXPECT_EQ(counts[3] + counts[4], 0);
  // Neighbouring patches (regular or extraordinary) give the same limit
  // surface on their common edge: the patch orders agree with the bases.
  const double corner_vw[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  int shared = 0, shared_extraordinary = 0;
  for (Index t = 0; t < m.num_triangles(); ++t)
    for (Index u = t + 1; u < m.num_triangles(); ++u) {
      if (m.patch_size(t) == 0 || m.patch_size(u) == 0) continue;
      int kt[2], ku[2], n = 0;
      for (int i = 0; i < 3 && n < 2; ++i)
        for (int j = 0; j < 3; ++j)
          if (m.triangles[t][i] == m.triangles[u][j]) kt[n] = i, ku[n++] = j;
      if (n < 2) continue;
      ++shared;
      shared_extraordinary += m.patch_size(t) != 12 || m.patch_size(u) != 12;
      for (double f : {0.25, 0.5}) {  // a point of the edge, seen from both sides
        auto along = [&](const int k[2], int c) { return (1 - f) * corner_vw[k[0]][c] + f * corner_vw[k[1]][c]; };
        const Vec3 xt = limit_point(m, t, along(kt, 0), along(kt, 1));
        const Vec3 xu = limit_point(m, u, along(ku, 0), along(ku, 1));
        EXPECT_LT((xt - xu).norm(), 1e-13 * s.radius) << "triangles " << t << " and " << u;
      }
    }
  EXPECT_GT(shared, m.num_triangles());
  EXPECT_GT(shared_extraordinary, 10);
  std::cout << "sphere: " << m.num_vertices() << " vertices, " << m.num_triangles() << " triangles: " << counts[0]
            << " regular, " << counts[1] << " extraordinary, " << counts[2] << " with several; " << shared
            << " shared edges checked, " << shared_extraordinary << " next to an extraordinary patch\n";
  EXPECT_EQ(counts[0] + counts[1] + counts[2], m.num_triangles());
}

TEST(ShellMesh, LoopSubdivisionKeepsTheLimitSurfaceAndSeparatesExtraordinaryVertices) {
  ShellShapeSpec s;
  s.shape = "sphere";
  s.radius = 0.12;
  s.element_size = 0.03;
  const ShellMesh coarse = mesh_shell_shape(s, "sphere");
  const ShellMesh fine = loop_subdivide(coarse, "sphere");
  Index edges = 0;
  for (Index v = 0; v < coarse.num_vertices(); ++v) edges += coarse.valence[v];
  EXPECT_EQ(fine.num_vertices(), coarse.num_vertices() + edges / 2);
  ASSERT_EQ(fine.num_triangles(), 4 * coarse.num_triangles());
  int several = 0, compared = 0;
  for (Index t = 0; t < fine.num_triangles(); ++t)
    several += fine.patch_kind[t] == ShellPatchKind::several_extraordinary;
  EXPECT_EQ(several, 0);
  // Where the coarse triangle has a patch, the limit surface is the same:
  // at its centroid (the centroid of its central sub-triangle 4t + 3) and at
  // (0.1, 0.1) (sub-triangle 4t at (0.2, 0.2)).
  for (Index t = 0; t < coarse.num_triangles(); ++t) {
    if (coarse.patch_size(t) == 0) continue;
    ++compared;
    EXPECT_LT((limit_point(coarse, t, 1.0 / 3, 1.0 / 3) - limit_point(fine, 4 * t + 3, 1.0 / 3, 1.0 / 3)).norm(),
              1e-14 * s.radius)
        << "triangle " << t;
    EXPECT_LT((limit_point(coarse, t, 0.1, 0.1) - limit_point(fine, 4 * t, 0.2, 0.2)).norm(), 1e-14 * s.radius)
        << "triangle " << t;
  }
  EXPECT_GT(compared, coarse.num_triangles() / 2);
}

TEST(ShellMesh, GmshOpenSurfacesHaveBoundaries) {
  for (const char* shape : {"disk", "rectangle", "cylinder"}) {
    ShellShapeSpec s;
    s.shape = shape;
    s.radius = 0.5;
    s.length = 1.0;
    s.width = 1.0;
    s.height = 0.6;
    s.axis = Vec3(1, 0, 0);
    s.element_size = 0.1;
    const ShellMesh m = mesh_shell_shape(s, shape);
    Index edges = 0, boundary_vertices = 0, supported = 0, boundary_triangles = 0;
    for (Index v = 0; v < m.num_vertices(); ++v) {
      edges += m.valence[v];
      boundary_vertices += m.on_boundary[v];
    }
    // Euler characteristic: 1 for a disk or a rectangle, 0 for a tube
    EXPECT_EQ(m.num_vertices() - edges / 2 + m.num_triangles(), std::string(shape) == "cylinder" ? 0 : 1) << shape;
    EXPECT_GT(boundary_vertices, 0) << shape;
    for (Index t = 0; t < m.num_triangles(); ++t) {
      bool touches = false;
      for (Index v : m.triangles[t]) touches = touches || m.on_boundary[v];
      const bool boundary_kind =
          m.patch_kind[t] == ShellPatchKind::boundary || m.patch_kind[t] == ShellPatchKind::unsupported_boundary;
      EXPECT_EQ(boundary_kind, touches);
      supported += m.patch_kind[t] == ShellPatchKind::boundary;
      boundary_triangles += touches;
    }
    std::cout << shape << ": " << supported << " of " << boundary_triangles
              << " boundary triangles completed by ghost vertices";
    // After the runtime's Loop step every triangle has its patch, and the
    // ghost-completed ones meet their neighbours with the same limit point
    // and tangent plane at the middle of each shared edge.
    const ShellMesh fine = loop_subdivide(m, shape);
    const auto basis = [](double v, double w) {  // N, dN/dv, dN/dw
      Eigen::Matrix<double, 12, 3> b;
      const auto l = loop_regular_basis(v, w);
      b << l.N, l.d1, l.d2;
      return b;
    };
    std::map<std::pair<Index, Index>, std::pair<Index, int>> first;  // edge -> (triangle, its edge k)
    int checked = 0;
    double worst_point = 0, worst_normal = 0;
    for (Index t = 0; t < fine.num_triangles(); ++t) {
      ASSERT_GT(fine.patch_size(t), 0) << shape << " triangle " << t;
      if (fine.patch_kind[t] != ShellPatchKind::boundary && fine.patch_kind[t] != ShellPatchKind::regular) continue;
      for (int k = 0; k < 3; ++k) {
        const Index p = fine.triangles[t][k], q = fine.triangles[t][(k + 1) % 3];
        const auto it = first.find({q, p});
        if (it == first.end()) {
          first[{p, q}] = {t, k};
          continue;
        }
        // the middle of edge k of triangle t, in (v, w)
        auto at = [&](Index u, int e) {
          constexpr double c[3][2] = {{0, 0}, {1, 0}, {0, 1}};
          const auto b = basis(0.5 * (c[e][0] + c[(e + 1) % 3][0]), 0.5 * (c[e][1] + c[(e + 1) % 3][1]));
          Eigen::Matrix<double, 3, 3> x = Eigen::Matrix<double, 3, 3>::Zero();
          for (int a = 0; a < 12; ++a) x += fine.entry_position(fine.reference, fine.patch_of(u)[a]) * b.row(a);
          return x;
        };
        const auto x1 = at(t, k), x2 = at(it->second.first, it->second.second);
        const Vec3 n1 = x1.col(1).cross(x1.col(2)).normalized(), n2 = x2.col(1).cross(x2.col(2)).normalized();
        worst_point = std::max(worst_point, (x1.col(0) - x2.col(0)).norm());
        worst_normal = std::max(worst_normal, (n1 - n2).norm());
        ++checked;
      }
    }
    std::cout << "; after one Loop step all " << fine.num_triangles() << " have patches, " << checked
              << " shared edges of lattice patches: limit points within " << worst_point << " m, normals within "
              << worst_normal << "\n";
    EXPECT_LT(worst_point, 1e-14);
    EXPECT_LT(worst_normal, 1e-12);
  }
  EXPECT_NE(input_error([] {
              mesh_shell_shape({.shape = "cone", .element_size = 0.1}, "bodies[0].mesh");
            }).find("bodies[0].mesh.shape: expected one of sphere, disk, rectangle, cylinder"),
            std::string::npos);
}

TEST(ShellMesh, BadTriangleMeshesAreRefused) {
  const std::vector<Vec3> x = {Vec3(0, 0, 0), Vec3(1, 0, 0),  Vec3(0, 1, 0), Vec3(1, 1, 0),
                               Vec3(0, 0, 1), Vec3(-1, 0, 0), Vec3(0, -1, 0)};
  auto error = [&](std::vector<std::array<Index, 3>> tris, std::vector<Vec3> points) {
    return input_error([&] { build_shell_mesh(std::move(points), std::move(tris), "file.msh"); });
  };
  EXPECT_NE(error({{0, 1, 7}}, x).find("file.msh: triangle 0 names vertex 7 of 7"), std::string::npos);
  EXPECT_NE(error({{0, 1, 1}}, x).find("triangle 0 repeats vertex 1"), std::string::npos);
  EXPECT_NE(error({{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}, x).find("the edge of vertices 0 and 1 has 3 or more"),
            std::string::npos);
  // two triangles meeting at vertex 0 only (a bow tie)
  EXPECT_NE(
      error({{0, 1, 2}, {0, 3, 4}}, {x[0], x[1], x[2], x[5], x[6]}).find("triangles at vertex 0 do not form one fan"),
      std::string::npos);
  EXPECT_NE(error({{0, 1, 2}}, x).find("vertex 3 is in no triangle"), std::string::npos);
  // a Moebius strip of 5 quads (10 triangles) is not orientable
  std::vector<Vec3> strip;
  std::vector<std::array<Index, 3>> tris;
  const int k = 5;
  for (int i = 0; i < k; ++i) {
    const double a = 2 * std::numbers::pi * i / k;
    for (int s : {-1, 1}) {
      const double h = 0.3 * s;
      strip.emplace_back((1 + h * std::cos(a / 2)) * std::cos(a), (1 + h * std::cos(a / 2)) * std::sin(a),
                         h * std::sin(a / 2));
    }
  }
  for (int i = 0; i < k; ++i) {
    const Index a0 = 2 * i, a1 = 2 * i + 1;
    const Index b0 = i + 1 < k ? 2 * i + 2 : 1, b1 = i + 1 < k ? 2 * i + 3 : 0;  // the half twist
    tris.push_back({a0, b0, a1});
    tris.push_back({a1, b0, b1});
  }
  EXPECT_NE(error(tris, strip).find("not orientable"), std::string::npos);
}
