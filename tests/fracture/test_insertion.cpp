// Topology change under many cohesive insertions on meshed boxes: mass,
// momentum, node usage, splitting rule, closed surface per fragment, and
// complete fragmentation.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "expect_close.hpp"
#include "fracture/cohesive_elements.hpp"
#include "fracture/fragments.hpp"
#include "fracture_fixtures.hpp"
#include "kernels/tet4.hpp"

using namespace shatter;

namespace {

constexpr double kRho = 2500.0;

/// Nodal state owned by "the caller" (the runtime in a real run).
struct State {
  std::vector<Vec3> x, v;
  std::vector<double> mass;
};

State initial_state(const Mesh& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  State s;
  s.x = m.reference;
  for (Index n = 0; n < m.num_nodes(); ++n) s.v.emplace_back(u(rng), u(rng) + 3.0, u(rng));
  s.mass = test::lumped_masses(m, kRho);
  return s;
}

/// What the caller does after an insertion (Insertion::new_nodes).
void apply_insertion(const Mesh& m, const Insertion& ins, State& s) {
  s.x.resize(m.num_nodes());
  s.v.resize(m.num_nodes());
  for (const auto& [copy, parent] : ins.new_nodes) {
    s.x[copy] = s.x[parent];
    s.v[copy] = s.v[parent];
  }
  s.mass = test::lumped_masses(m, kRho);
}

Vec3 momentum(const State& s) {
  Vec3 p = Vec3::Zero();
  for (size_t n = 0; n < s.mass.size(); ++n) p += s.mass[n] * s.v[n];
  return p;
}

double total(const std::vector<double>& a) {
  double t = 0;
  for (double x : a) t += x;
  return t;
}

/// Are elements a and b connected around node n through intact facets
/// containing n? (Independent re-implementation of the splitting rule.)
bool connected_around(const Mesh& m, const Topology& t, Index n, Index a, Index b) {
  const int k = m.order == 1 ? 3 : 6;
  std::set<Index> seen = {a};
  std::vector<Index> todo = {a};
  while (!todo.empty()) {
    const Index e = todo.back();
    todo.pop_back();
    if (e == b) return true;
    for (int i = 0; i < 4; ++i) {
      const Index f = t.elem_facet[4 * e + i];
      if (t.facet_state[f] != FacetState::intact) continue;
      const auto fn = face_nodes(m, e, i);
      if (std::find(fn.begin(), fn.begin() + k, n) == fn.begin() + k) continue;
      const Index o = t.facet_elem[f][0] == e ? t.facet_elem[f][1] : t.facet_elem[f][0];
      if (seen.insert(o).second) todo.push_back(o);
    }
  }
  return false;
}

/// Sum over the surface of each fragment of +1 per directed corner edge and
/// -1 per reversed one: a closed oriented surface gives 0 for every edge.
/// Returns the number of unbalanced edges; `non_manifold` counts edges used by
/// more than two faces.
int unbalanced_surface_edges(const Mesh& m, const Topology& t, const Fragments& fr,
                             int& non_manifold) {
  std::map<std::array<GlobalId, 3>, std::array<int, 2>>
      edges;  // (fragment, lo, hi) -> (balance, uses)
  for (const auto& [e, face] : surface_faces(m, t)) {
    const auto fn = face_nodes(m, e, face);
    for (int j = 0; j < 3; ++j) {
      const Index a = fn[j], b = fn[(j + 1) % 3];
      auto& entry = edges[{fr.elem_fragment[e], std::min(a, b), std::max(a, b)}];
      entry[0] += a < b ? 1 : -1;
      entry[1] += 1;
    }
  }
  int unbalanced = 0;
  non_manifold = 0;
  for (const auto& [key, entry] : edges) {
    unbalanced += entry[0] != 0;
    non_manifold += entry[1] > 2;
  }
  return unbalanced;
}

void check_invariants(const Mesh& m, const Topology& t, const CohesiveElements& coh, const State& s,
                      double mass0, const Vec3& p0, double p_scale) {
  ASSERT_NO_THROW(validate_mesh(m, "after insertion"));  // every node used, no inverted element
  EXPECT_CLOSE(total(s.mass), mass0, 1e-13, 0);
  EXPECT_LT((momentum(s) - p0).norm(), 1e-14 * p_scale);
  const std::set<GlobalId> gids(m.node_gid.begin(), m.node_gid.end());
  EXPECT_EQ(static_cast<Index>(gids.size()), m.num_nodes());
  const int k = m.order == 1 ? 3 : 6;
  for (Index f = 0; f < t.num_facets(); ++f) {
    if (t.facet_state[f] != FacetState::intact) continue;
    // Intact facets keep both sides on the same nodes.
    auto a = face_nodes(m, t.facet_elem[f][0], t.facet_face[f][0]);
    auto b = face_nodes(m, t.facet_elem[f][1], t.facet_face[f][1]);
    std::sort(a.begin(), a.begin() + k);
    std::sort(b.begin(), b.begin() + k);
    EXPECT_TRUE(std::equal(a.begin(), a.begin() + k, b.begin()));
  }
  for (Index c = 0; c < coh.size(); ++c) {
    const Index f = coh.facet[c];
    const auto [e0, e1] = t.facet_elem[f];
    for (int j = 0; j < k; ++j) {
      const Index n0 = coh.side_nodes[12 * c + j], n1 = coh.side_nodes[12 * c + 6 + j];
      EXPECT_EQ(n0, m.element(e0)[coh.side_local[12 * c + j]]);
      EXPECT_EQ(n1, m.element(e1)[coh.side_local[12 * c + 6 + j]]);
      EXPECT_EQ(m.reference[n0], m.reference[n1]);
      // The sides share a node exactly where the star around it still holds together.
      EXPECT_EQ(n0 == n1, connected_around(m, t, n0, e0, e1));
    }
  }
}

void random_insertions(int order, double element_size) {
  std::mt19937 rng(12345);
  Mesh m = test::box_mesh(element_size, order);
  Topology t = build_topology(m);
  CohesiveElements coh;
  State s = initial_state(m, rng);
  const double mass0 = total(s.mass);
  double volume = 0;
  for (Index e = 0; e < m.num_elements(); ++e) volume += element_reference_volume(m, e);
  EXPECT_CLOSE(mass0, kRho * volume, 1e-13, 0);
  const Vec3 p0 = momentum(s);
  double p_scale = 0;
  for (Index n = 0; n < m.num_nodes(); ++n) p_scale += s.mass[n] * s.v[n].norm();

  const Index nodes0 = m.num_nodes();
  for (int round = 0; round < 12; ++round) {
    std::vector<Index> intact;
    for (Index f = 0; f < t.num_facets(); ++f)
      if (t.facet_state[f] == FacetState::intact) intact.push_back(f);
    std::shuffle(intact.begin(), intact.end(), rng);
    intact.resize(std::min<size_t>(intact.size(), t.num_facets() / 40));
    const std::uint64_t revision = m.revision;
    const Insertion ins = insert_cohesive_elements(m, t, coh, intact);
    EXPECT_EQ(ins.crack_faces.size(), 2 * intact.size());
    EXPECT_EQ(m.revision, revision + (ins.new_nodes.empty() ? 0 : 1));
    apply_insertion(m, ins, s);
    // Some cohesive elements debond completely.
    for (Index c = ins.first_cohesive; c < coh.size(); c += 3)
      t.facet_state[coh.facet[c]] = FacetState::free;
    check_invariants(m, t, coh, s, mass0, p0, p_scale);
    const Fragments fr = find_fragments(m, t, s.x, s.v, s.mass);
    // Closed and oriented; not strictly edge-manifold while cracks are partial:
    // where two crack facets meet at an edge whose end nodes still hold
    // together through intact facets, four faces share the edge (TET4 cannot
    // split an edge without splitting a node). Complete separation below is manifold.
    int non_manifold = 0;
    EXPECT_EQ(unbalanced_surface_edges(m, t, fr, non_manifold), 0);
    double fragment_mass = 0;
    Vec3 fragment_momentum = Vec3::Zero();
    for (const FragmentStats& st : fr.stats) {
      fragment_mass += st.mass;
      fragment_momentum += st.mass * st.velocity;
    }
    EXPECT_CLOSE(fragment_mass, mass0, 1e-13, 0);
    EXPECT_LT((fragment_momentum - p0).norm(), 1e-13 * p_scale);
  }
  EXPECT_GT(m.num_nodes(), nodes0);

  // Break and free every remaining interior facet: one fragment per element.
  std::vector<Index> rest;
  for (Index f = 0; f < t.num_facets(); ++f)
    if (t.facet_state[f] == FacetState::intact) rest.push_back(f);
  const Insertion ins = insert_cohesive_elements(m, t, coh, rest);
  apply_insertion(m, ins, s);
  for (Index f = 0; f < t.num_facets(); ++f) t.facet_state[f] = FacetState::free;
  check_invariants(m, t, coh, s, mass0, p0, p_scale);
  EXPECT_EQ(m.num_nodes(), m.num_elements() * m.nodes_per_element());
  const Fragments fr = find_fragments(m, t, s.x, s.v, s.mass);
  ASSERT_EQ(fr.count(), m.num_elements());
  GlobalId previous = -1;
  for (Index i = 0; i < fr.count(); ++i) {
    EXPECT_EQ(fr.stats[i].elements, 1);
    // Canonical numbering: fragment i holds the i-th smallest element global id.
    const Index e = static_cast<Index>(
        std::find(fr.elem_fragment.begin(), fr.elem_fragment.end(), i) - fr.elem_fragment.begin());
    EXPECT_GT(m.elem_gid[e], previous);
    previous = m.elem_gid[e];
    EXPECT_CLOSE(fr.stats[i].mass, kRho * element_reference_volume(m, e), 1e-13, 0);
    EXPECT_CLOSE(fr.stats[i].volume, element_reference_volume(m, e), 1e-13, 0);
  }
  int non_manifold = 0;
  EXPECT_EQ(unbalanced_surface_edges(m, t, fr, non_manifold), 0);
  EXPECT_EQ(non_manifold, 0);
}

}  // namespace

TEST(Insertion, RandomInsertionsTet4KeepInvariants) {
  random_insertions(1, 0.15);
}

TEST(Insertion, RandomInsertionsTet10KeepInvariants) {
  random_insertions(2, 0.3);
}

TEST(Insertion, NodeNamesAreDerivedFromTheStar) {
  Mesh m = test::box_mesh(0.3, 1);
  Topology t = build_topology(m);
  CohesiveElements coh;
  std::vector<Index> all;
  for (Index f = 0; f < t.num_facets(); ++f)
    if (t.facet_state[f] == FacetState::intact) all.push_back(f);
  // The same facets given in any order produce the same mesh.
  Mesh m2 = m;
  Topology t2 = t;
  CohesiveElements coh2;
  std::vector<Index> reversed(all.rbegin(), all.rend());
  insert_cohesive_elements(m, t, coh, all);
  insert_cohesive_elements(m2, t2, coh2, reversed);
  EXPECT_EQ(m.conn, m2.conn);
  EXPECT_EQ(m.node_gid, m2.node_gid);
  // Every copy is named base + 10 g + a + 1 after its only element g, slot a.
  for (Index e = 0; e < m.num_elements(); ++e)
    for (int a = 0; a < 4; ++a) {
      const Index n = m.element(e)[a];
      if (m.node_gid[n] <= t.split_gid_base) continue;
      EXPECT_EQ(m.node_gid[n], t.split_gid_base + 10 * m.elem_gid[e] + a + 1);
    }
}

TEST(Fragments, CutPiecesMoveRigidly) {
  // Break and free every facet between the elements whose centroid lies left of
  // x = 0.45 and the others. Each side may fall into several pieces (elements
  // joined to their side only through an edge or a node come loose), but no
  // fragment straddles the cut, and in a rigid rotation v = w x X each piece
  // moves with the velocity of its centre of mass.
  std::mt19937 rng(3);
  Mesh m = test::box_mesh(0.15, 1);
  Topology t = build_topology(m);
  auto left = [&](Index e) {
    const Index* c = m.element(e);
    return (m.reference[c[0]] + m.reference[c[1]] + m.reference[c[2]] + m.reference[c[3]]).x() / 4 <
           0.45;
  };
  std::vector<Index> cut;
  for (Index f = 0; f < t.num_facets(); ++f)
    if (t.is_interior(f) && left(t.facet_elem[f][0]) != left(t.facet_elem[f][1])) cut.push_back(f);
  CohesiveElements coh;
  State s = initial_state(m, rng);
  const Vec3 w(0.3, -1.0, 2.0);
  for (Index n = 0; n < m.num_nodes(); ++n) s.v[n] = w.cross(m.reference[n]);
  const Insertion ins = insert_cohesive_elements(m, t, coh, cut);
  apply_insertion(m, ins, s);
  for (const Index f : cut) t.facet_state[f] = FacetState::free;
  const Fragments fr = find_fragments(m, t, s.x, s.v, s.mass);
  ASSERT_GE(fr.count(), 2);
  std::vector<double> volume(fr.count(), 0.0);
  std::vector<int> side(fr.count(), -1);
  std::vector<GlobalId> smallest(fr.count(), std::numeric_limits<GlobalId>::max());
  for (Index e = 0; e < m.num_elements(); ++e) {
    const Index i = fr.elem_fragment[e];
    if (side[i] < 0) side[i] = left(e);
    EXPECT_EQ(side[i], int(left(e)));
    volume[i] += element_reference_volume(m, e);
    smallest[i] = std::min(smallest[i], m.elem_gid[e]);
  }
  EXPECT_TRUE(std::is_sorted(smallest.begin(), smallest.end()));
  double total_volume = 0;
  for (Index i = 0; i < fr.count(); ++i) {
    const FragmentStats& st = fr.stats[i];
    EXPECT_CLOSE(st.volume, volume[i], 1e-13, 0);
    EXPECT_CLOSE(st.mass, kRho * volume[i], 1e-13, 0);
    EXPECT_LT((st.velocity - w.cross(st.centre)).norm(), 1e-13 * w.norm());
    total_volume += st.volume;
  }
  EXPECT_CLOSE(total_volume, 1.0 * 0.8 * 0.6, 1e-13, 0);
}
