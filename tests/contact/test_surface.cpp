// Contact surface extraction: a meshed ball's surface is a closed, oriented
// 2-manifold of genus 0 with outward normals enclosing the mesh volume, for
// TET4 and TET10; bodies are tagged; add_triangles equals a rebuild.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "contact/surface.hpp"
#include "expect_close.hpp"
#include "kernels/tet10.hpp"
#include "mesh/gmsh_input.hpp"

using namespace shatter;

namespace {

Mesh ball(int order, const Vec3& center, int body) {
  ShapeSpec s;
  s.shape = "sphere";
  s.radius = 1.0;
  s.center = center;
  s.element_size = 0.35;
  s.order = order;
  return mesh_shape(s, body, 0, "test");
}

Vec3 area_normal(const Mesh& m, const std::array<Index, 3>& t) {
  const Vec3 &a = m.reference[t[0]], &b = m.reference[t[1]], &c = m.reference[t[2]];
  return 0.5 * (b - a).cross(c - a);
}

/// Volume enclosed by the surface (divergence theorem): sum (centroid . area normal) / 3.
double enclosed_volume(const Mesh& m, const ContactSurface& s) {
  double v = 0;
  for (const auto& t : s.triangles) {
    const Vec3 c = (m.reference[t[0]] + m.reference[t[1]] + m.reference[t[2]]) / 3.0;
    v += c.dot(area_normal(m, t)) / 3.0;
  }
  return v;
}

double tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

/// Volume of the mesh with flat faces through all its nodes: TET4 elements
/// as they are; each TET10 as its 8 linear sub-tetrahedra (4 corner tets and
/// the mid-node octahedron split along the 4-8 diagonal), whose boundary is
/// the 16 flat sub-triangles of the element's faces.
double piecewise_flat_volume(const Mesh& m) {
  static const int kCorner[4][4] = {{0, 4, 6, 7}, {4, 1, 5, 9}, {6, 5, 2, 8}, {7, 9, 8, 3}};
  static const int kRing[4] = {5, 6, 7, 9};
  double v = 0;
  for (Index e = 0; e < m.num_elements(); ++e) {
    const Index* n = m.element(e);
    auto x = [&](int a) -> const Vec3& { return m.reference[n[a]]; };
    if (m.order == 1) {
      v += tet_volume(x(0), x(1), x(2), x(3));
      continue;
    }
    for (const auto& c : kCorner) v += tet_volume(x(c[0]), x(c[1]), x(c[2]), x(c[3]));
    for (int k = 0; k < 4; ++k)
      v += std::abs(tet_volume(x(4), x(8), x(kRing[k]), x(kRing[(k + 1) % 4])));
  }
  return v;
}

class BallSurface : public ::testing::TestWithParam<int> {};

TEST_P(BallSurface, IsClosedOrientedGenusZeroWithOutwardNormals) {
  const Mesh m = ball(GetParam(), Vec3(0.5, -1, 2), 3);
  const ContactSurface s = build_contact_surface(m);
  ASSERT_GT(s.num_triangles(), 100);
  ASSERT_EQ(s.body.size(), s.triangles.size());

  // Every undirected edge in exactly two triangles, every directed edge in
  // exactly one: a closed 2-manifold with consistent orientation.
  std::map<std::array<Index, 2>, int> directed;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, count] : directed) {
    EXPECT_EQ(count, 1) << "directed edge " << e[0] << "-" << e[1];
    EXPECT_EQ(directed.count({e[1], e[0]}), 1u)
        << "edge " << e[0] << "-" << e[1] << " has one triangle";
  }
  EXPECT_EQ(directed.size(), 2 * s.edges.size());
  EXPECT_EQ(static_cast<Index>(s.vertices.size()) - s.num_edges() + s.num_triangles(), 2);

  // Edges and vertices: sorted, unique, exactly those of the triangles.
  EXPECT_TRUE(std::is_sorted(s.edges.begin(), s.edges.end()));
  EXPECT_TRUE(std::adjacent_find(s.edges.begin(), s.edges.end()) == s.edges.end());
  EXPECT_TRUE(std::is_sorted(s.vertices.begin(), s.vertices.end()));
  EXPECT_TRUE(std::adjacent_find(s.vertices.begin(), s.vertices.end()) == s.vertices.end());
  for (const auto& e : s.edges) EXPECT_LT(e[0], e[1]);

  // Outward: enclosed volume equals the piecewise-flat mesh volume; every
  // normal of a ball points away from its centre.
  const double vol = piecewise_flat_volume(m);
  EXPECT_CLOSE(enclosed_volume(m, s), vol, 1e-12, 0);
  EXPECT_CLOSE(vol, 4.0 / 3.0 * std::numbers::pi, 0.1, 0);
  for (const auto& t : s.triangles) {
    const Vec3 c = (m.reference[t[0]] + m.reference[t[1]] + m.reference[t[2]]) / 3.0;
    EXPECT_GT((c - Vec3(0.5, -1, 2)).dot(area_normal(m, t)), 0.0);
  }
  for (int b : s.body) EXPECT_EQ(b, 3);
}

INSTANTIATE_TEST_SUITE_P(Orders, BallSurface, ::testing::Values(1, 2),
                         [](const auto& info) { return info.param == 1 ? "Tet4" : "Tet10"; });

TEST(ContactSurface, Tet10UsesEveryBoundaryNode) {
  const Mesh m = ball(2, Vec3::Zero(), 0);
  const ContactSurface s = build_contact_surface(m);
  // A boundary node is one on a boundary triangle; on the sphere they all lie
  // at radius 1 (Gmsh places TET10 boundary mid-nodes on the geometry).
  for (Index n : s.vertices) EXPECT_CLOSE(m.reference[n].norm(), 1.0, 1e-6, 0);
  // 4 sub-triangles per face: F = 4 F_corner, V = V_corner + E_corner.
  EXPECT_EQ(s.num_triangles() % 4, 0);
}

TEST(ContactSurface, TwoBodiesAreTaggedByElementBody) {
  Mesh m = ball(1, Vec3::Zero(), 0);
  append_mesh(m, ball(1, Vec3(3, 0, 0), 1));
  const ContactSurface s = build_contact_surface(m);
  int per_body[2] = {0, 0};
  for (Index t = 0; t < s.num_triangles(); ++t) {
    for (Index n : s.triangles[t]) EXPECT_EQ(m.node_body[n], s.body[t]);
    ++per_body[s.body[t]];
  }
  EXPECT_GT(per_body[0], 0);
  EXPECT_GT(per_body[1], 0);
  // two spheres: Euler characteristic 2 + 2
  EXPECT_EQ(s.num_vertices() - s.num_edges() + s.num_triangles(), 4);
}

std::vector<SurfaceTriangle> triangles_of(const ContactSurface& s, size_t from, size_t to) {
  std::vector<SurfaceTriangle> t;
  for (size_t k = from; k < to; ++k) t.push_back({s.triangles[k], s.body[k]});
  return t;
}

TEST(ContactSurface, AddTrianglesEqualsRebuildOnTheUnion) {
  for (int order : {1, 2}) {
    const ContactSurface whole = build_contact_surface(ball(order, Vec3::Zero(), 0));
    const size_t n = whole.triangles.size();
    // Grow a surface in uneven chunks (the crack faces of successive steps).
    ContactSurface grown = make_contact_surface(triangles_of(whole, 0, n / 3));
    for (size_t from = n / 3; from < n;) {
      const size_t to = std::min(n, from + 1 + from / 5);
      add_triangles(grown, triangles_of(whole, from, to));
      from = to;
    }
    EXPECT_EQ(grown, whole) << "order " << order;
    ContactSurface unchanged = whole;
    add_triangles(unchanged, {});
    EXPECT_EQ(unchanged, whole);
  }
}

// The faces of bonded cohesive facets stay out of the contact surface
// (build_contact_surface with a skip list): skipping every face of some
// elements removes exactly their boundary triangles.
TEST(ContactSurface, SkippedFacesAreLeftOut) {
  const Mesh m = ball(1, Vec3::Zero(), 0);
  const ContactSurface whole = build_contact_surface(m);
  std::vector<std::pair<Index, int>> skip;
  std::vector<std::array<Index, 3>> skipped_keys;
  for (Index e = 0; e < m.num_elements(); e += 7)
    for (int f = 0; f < 4; ++f) {
      skip.emplace_back(e, f);
      std::array<Index, 3> key;
      for (int k = 0, j = 0; k < 4; ++k)
        if (k != 3 - f) key[j++] = m.element(e)[k];
      std::sort(key.begin(), key.end());
      skipped_keys.push_back(key);
    }
  std::sort(skipped_keys.begin(), skipped_keys.end());
  std::vector<SurfaceTriangle> kept;
  for (Index t = 0; t < whole.num_triangles(); ++t) {
    std::array<Index, 3> key = whole.triangles[t];
    std::sort(key.begin(), key.end());
    if (!std::binary_search(skipped_keys.begin(), skipped_keys.end(), key)) kept.push_back({whole.triangles[t], 0});
  }
  ASSERT_LT(kept.size(), whole.triangles.size()) << "no boundary face was skipped";
  EXPECT_EQ(build_contact_surface(m, skip), make_contact_surface(kept));
}

TEST(ContactSurface, ExtendingAMeshSurfaceEqualsBuildingTheUnion) {
  Mesh a = ball(1, Vec3::Zero(), 0);
  const Mesh b = ball(1, Vec3(3, 0, 0), 1);
  const Index shift = a.num_nodes();
  const ContactSurface sb = build_contact_surface(b);
  std::vector<SurfaceTriangle> extra;
  for (Index t = 0; t < sb.num_triangles(); ++t)
    extra.push_back(
        {{sb.triangles[t][0] + shift, sb.triangles[t][1] + shift, sb.triangles[t][2] + shift}, 1});
  ContactSurface extended = build_contact_surface(a);
  add_triangles(extended, extra);
  append_mesh(a, b);
  EXPECT_EQ(extended, build_contact_surface(a));
}

}  // namespace

// edge_face_normal (DCR's exact edge cones, issue 18): on a meshed box, every surface edge's
// triangle in which it runs a -> b and the one in which it runs b -> a add up to the edge's
// surface_normal, and turning from the first to the second about a -> b is a convex or flat
// edge: the 12 edges of the box turn by 90 degrees, the face diagonals by none.
TEST(ContactSurface, EdgeFaceNormalsSplitTheEdgeNormalIntoItsTwoTriangles) {
  ShapeSpec spec;
  spec.shape = "box";
  spec.size = Vec3(1.0, 0.8, 0.6);
  spec.center = Vec3(0.3, -0.2, 0.1);
  spec.element_size = 0.3;
  const Mesh m = mesh_shape(spec, 0, 0, "test");
  const ContactSurface s = build_contact_surface(m);
  const VertexTriangles around = vertex_triangles(s);
  const TriangleNormals tn = triangle_normals(s, m.reference);
  auto on_face = [&](const Vec3& x) {  // how many of the box's planes x lies on
    int k = 0;
    for (int c = 0; c < 3; ++c)
      k += std::abs(std::abs(x[c] - spec.center[c]) - spec.size[c] / 2) < 1e-9;
    return k;
  };
  int box_edges = 0;
  for (const auto& [a, b] : s.edges) {
    const Vec3 f = edge_face_normal(s, around, tn, a, b), g = edge_face_normal(s, around, tn, b, a);
    const Vec3 n = surface_normal(s, around, tn, a, b), e = m.reference[b] - m.reference[a];
    ASSERT_GT(f.norm(), 0.0);
    ASSERT_GT(g.norm(), 0.0);
    EXPECT_LE((f + g - n).norm(), 1e-14 * (f.norm() + g.norm()));
    const double turn = f.normalized().cross(g.normalized()).dot(e.normalized());  // sin of the turn
    const bool box_edge = on_face(m.reference[a]) >= 2 && on_face(m.reference[b]) >= 2 &&
                          std::abs(f.normalized().dot(g.normalized())) < 0.5;
    if (box_edge) {
      ++box_edges;
      EXPECT_NEAR(turn, 1.0, 1e-12);
    } else {
      EXPECT_NEAR(turn, 0.0, 1e-12);
    }
  }
  EXPECT_GE(box_edges, 12);
}
