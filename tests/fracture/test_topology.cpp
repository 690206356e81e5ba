// Facet adjacency of meshed boxes: counts, pairing, orientation, ids.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "expect_close.hpp"
#include "fracture_fixtures.hpp"
#include "kernels/tet4.hpp"
#include "mesh/topology.hpp"

using namespace shatter;

namespace {

Vec3 facet_area_vector(const Mesh& m, Index e, int face) {
  const auto n = face_nodes(m, e, face);
  return 0.5 * (m.reference[n[1]] - m.reference[n[0]]).cross(m.reference[n[2]] - m.reference[n[0]]);
}

void check_topology(const Mesh& m) {
  const Topology t = build_topology(m);
  const int k = m.order == 1 ? 3 : 6;
  Index interior = 0, boundary = 0;
  double boundary_area = 0;
  std::set<GlobalId> gids(t.facet_gid.begin(), t.facet_gid.end());
  EXPECT_EQ(static_cast<Index>(gids.size()), t.num_facets());
  for (Index f = 0; f < t.num_facets(); ++f) {
    const auto [e0, e1] = t.facet_elem[f];
    // Every local face points away from its element.
    const Index* c = m.element(e0);
    const Vec3 centre =
        0.25 * (m.reference[c[0]] + m.reference[c[1]] + m.reference[c[2]] + m.reference[c[3]]);
    const auto n0 = face_nodes(m, e0, t.facet_face[f][0]);
    EXPECT_GT(facet_area_vector(m, e0, t.facet_face[f][0]).dot(m.reference[n0[0]] - centre), 0);
    EXPECT_EQ(t.elem_facet[4 * e0 + t.facet_face[f][0]], f);
    // Numbered by element 0, then its local face (the facet check's walk reads the elements 0 in order).
    if (f > 0) {
      EXPECT_LT(4 * t.facet_elem[f - 1][0] + t.facet_face[f - 1][0], 4 * e0 + t.facet_face[f][0]);
    }
    if (e1 < 0) {
      ++boundary;
      boundary_area += facet_area_vector(m, e0, t.facet_face[f][0]).norm();
      EXPECT_EQ(t.facet_state[f], FacetState::free);
      continue;
    }
    ++interior;
    EXPECT_EQ(t.facet_state[f], FacetState::intact);
    EXPECT_LT(m.elem_gid[e0], m.elem_gid[e1]);
    EXPECT_EQ(t.elem_facet[4 * e1 + t.facet_face[f][1]], f);
    EXPECT_EQ(t.facet_gid[f], 4 * m.elem_gid[e0] + t.facet_face[f][0]);
    // Both sides hold the same k nodes (mid-edge ones included) with opposite orientation.
    const auto n1 = face_nodes(m, e1, t.facet_face[f][1]);
    std::vector<Index> a(n0.begin(), n0.begin() + k), b(n1.begin(), n1.begin() + k);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    const Vec3 s0 = facet_area_vector(m, e0, t.facet_face[f][0]),
               s1 = facet_area_vector(m, e1, t.facet_face[f][1]);
    EXPECT_LT((s0 + s1).norm(), 1e-12 * s0.norm());
  }
  EXPECT_EQ(4 * m.num_elements(), 2 * interior + boundary);
  EXPECT_CLOSE(boundary_area, 2 * (1.0 * 0.8 + 0.8 * 0.6 + 0.6 * 1.0), 1e-12, 0);
}

}  // namespace

TEST(Topology, Tet4BoxFacets) {
  check_topology(test::box_mesh(0.2, 1));
}

TEST(Topology, Tet10BoxFacets) {
  check_topology(test::box_mesh(0.3, 2));
}

TEST(Topology, NodeStarsMatchConnectivity) {
  const Mesh m = test::box_mesh(0.25, 1);
  for (Index n = 0; n < m.num_nodes(); ++n)
    for (const Index e : node_star(m, n)) {
      const Index* c = m.element(e);
      EXPECT_TRUE(std::find(c, c + 4, n) != c + 4);
    }
}
