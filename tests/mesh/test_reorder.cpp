// reorder_for_locality: a permutation of nodes and elements that keeps the
// mesh (same elements by global id, same node coordinates by global id, same
// volumes), orders elements along the Morton curve and nodes by first use.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>

#include "mesh/mesh.hpp"
#include "mesh/reorder.hpp"

using namespace shatter;

namespace {
// A structured n^3 box of 6-tet cubes, elements listed in a scrambled order.
Mesh scrambled_box(int nx, int ny, int nz) {
  Mesh m;
  auto id = [&](int i, int j, int k) { return static_cast<Index>((k * (ny + 1) + j) * (nx + 1) + i); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        m.reference.emplace_back(i, j, k);
        m.node_gid.push_back(100 + m.node_gid.size());
        m.node_body.push_back(0);
      }
  // Kuhn split of each cube along the main diagonal 0 -> 7.
  const int paths[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4}, {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
  std::vector<std::array<Index, 4>> tets;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : paths) {
          int c = 0;
          std::array<Index, 4> t;
          t[0] = id(i, j, k);
          for (int s = 0; s < 3; ++s) {
            c |= p[s];
            t[s + 1] = id(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
          }
          const Vec3 &a = m.reference[t[0]], &b = m.reference[t[1]], &cc = m.reference[t[2]], &d = m.reference[t[3]];
          if ((b - a).dot((cc - a).cross(d - a)) < 0) std::swap(t[2], t[3]);
          tets.push_back(t);
        }
  // scramble: a fixed stride permutation of the element list
  const size_t ne = tets.size();
  size_t stride = 7919 % ne;
  while (std::gcd(stride, ne) != 1) ++stride;
  for (size_t e = 0; e < ne; ++e) {
    const auto& t = tets[(e * stride) % ne];
    m.conn.insert(m.conn.end(), t.begin(), t.end());
    m.elem_gid.push_back(1000 + static_cast<GlobalId>((e * stride) % ne));
    m.elem_body.push_back(0);
    m.elem_material.push_back(static_cast<int>((e * stride) % 3));
  }
  m.build_node_elements();
  return m;
}
Mesh scrambled_box(int n) { return scrambled_box(n, n, n); }
}  // namespace

TEST(Reorder, IsAPermutationThatKeepsTheMesh) {
  const Mesh before = scrambled_box(6);
  Mesh after = before;
  const MeshPermutation perm = reorder_for_locality(after);
  ASSERT_EQ(after.num_nodes(), before.num_nodes());
  ASSERT_EQ(after.num_elements(), before.num_elements());
  EXPECT_GT(after.revision, before.revision);
  std::vector<int> seen(before.num_nodes(), 0);
  for (Index v = 0; v < before.num_nodes(); ++v) {
    const Index w = perm.node_new_of_old[v];
    ++seen[w];
    EXPECT_EQ(after.reference[w], before.reference[v]);
    EXPECT_EQ(after.node_gid[w], before.node_gid[v]);
  }
  for (int s : seen) EXPECT_EQ(s, 1);
  for (Index e = 0; e < before.num_elements(); ++e) {
    const Index g = perm.elem_new_of_old[e];
    EXPECT_EQ(after.elem_gid[g], before.elem_gid[e]);
    EXPECT_EQ(after.elem_material[g], before.elem_material[e]);
    for (int a = 0; a < 4; ++a) EXPECT_EQ(after.element(g)[a], perm.node_new_of_old[before.element(e)[a]]);
    EXPECT_EQ(element_reference_volume(after, g), element_reference_volume(before, e));
  }
  // node -> element CSR rebuilt for the new ids
  for (Index v = 0; v < after.num_nodes(); ++v)
    for (Index k = after.node_elem_offsets[v]; k < after.node_elem_offsets[v + 1]; ++k) {
      const Index* c = after.element(after.node_elem[k]);
      EXPECT_TRUE(c[0] == v || c[1] == v || c[2] == v || c[3] == v);
    }
}

TEST(Reorder, ElementsFollowTheMortonCurveAndNodesTheirFirstUse) {
  Mesh m = scrambled_box(5);
  reorder_for_locality(m);
  Vec3 lo = Vec3::Zero(), hi = Vec3::Constant(5.0);
  std::uint64_t last = 0;
  Index next_new_node = 0;
  for (Index e = 0; e < m.num_elements(); ++e) {
    const Index* c = m.element(e);
    const Vec3 centroid = 0.25 * (m.reference[c[0]] + m.reference[c[1]] + m.reference[c[2]] + m.reference[c[3]]);
    const std::uint64_t code = morton_code(centroid, lo, hi);
    EXPECT_GE(code, last);
    last = code;
    for (int a = 0; a < 4; ++a) {
      EXPECT_LE(c[a], next_new_node);  // a node is either seen before or the next new id
      if (c[a] == next_new_node) ++next_new_node;
    }
  }
  EXPECT_EQ(next_new_node, m.num_nodes());
}

TEST(Reorder, AnElongatedBodysRunsOfElementsAreCompact) {
  // A 16 x 2 x 2 bar of unit cubes (6 tets each): every run of a sixteenth of
  // the elements spans little of its length (in a box of the bar's own
  // proportions the curve split the thickness first: a run spanned ~half).
  const int nx = 16;
  Mesh m = scrambled_box(nx, 2, 2);
  reorder_for_locality(m);
  const Index run = m.num_elements() / 16;
  double widest = 0;
  for (Index first = 0; first + run <= m.num_elements(); first += run) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (Index e = first; e < first + run; ++e)
      for (int a = 0; a < 4; ++a) {
        lo = std::min(lo, m.reference[m.element(e)[a]].x());
        hi = std::max(hi, m.reference[m.element(e)[a]].x());
      }
    widest = std::max(widest, hi - lo);
  }
  EXPECT_LE(widest, 0.25 * nx) << "a run of " << run << " elements spans " << widest << " of the bar's " << nx;
}

TEST(Reorder, IsDeterministicAndIdempotent) {
  Mesh a = scrambled_box(4), b = scrambled_box(4);
  reorder_for_locality(a);
  reorder_for_locality(b);
  EXPECT_EQ(a.conn, b.conn);
  EXPECT_EQ(a.elem_gid, b.elem_gid);
  const std::vector<Index> conn = a.conn;
  const MeshPermutation again = reorder_for_locality(a);
  EXPECT_EQ(a.conn, conn);
  for (Index v = 0; v < a.num_nodes(); ++v) EXPECT_EQ(again.node_new_of_old[v], v);
}

TEST(Reorder, MortonCodeInterleavesAxes) {
  const Vec3 lo = Vec3::Zero(), hi = Vec3::Constant(1.0);
  EXPECT_EQ(morton_code(lo, lo, hi), 0u);
  const double cell = 1.0 / (1 << 21);
  EXPECT_EQ(morton_code(Vec3(1.5 * cell, 0, 0), lo, hi), 1u);
  EXPECT_EQ(morton_code(Vec3(0, 1.5 * cell, 0), lo, hi), 2u);
  EXPECT_EQ(morton_code(Vec3(0, 0, 1.5 * cell), lo, hi), 4u);
  EXPECT_EQ(morton_code(Vec3(2, -1, 0.5), lo, hi), morton_code(Vec3(1, 0, 0.5), lo, hi));  // clamped
}

TEST(Reorder, RenumberedGlobalIdsFollowTheNewOrder) {
  const Mesh before = scrambled_box(4);
  Mesh after = before;
  const MeshPermutation perm = reorder_for_locality(after, GlobalIdPolicy::renumber);
  EXPECT_TRUE(std::is_sorted(after.node_gid.begin(), after.node_gid.end()));
  EXPECT_TRUE(std::is_sorted(after.elem_gid.begin(), after.elem_gid.end()));
  std::vector<GlobalId> a = before.elem_gid, b = after.elem_gid;
  std::sort(a.begin(), a.end());
  EXPECT_EQ(a, b);  // the same set of ids
  for (Index v = 0; v < before.num_nodes(); ++v)
    EXPECT_EQ(after.reference[perm.node_new_of_old[v]], before.reference[v]);
}
