// Candidate pairs: find_candidates equals the O(n^2) definition on hard
// geometry, its pairs are well formed and canonical, and the list is the same
// for any thread count. The sparse bucket itself reports exactly the
// overlapping boxes, once each, also for boxes on bucket boundaries.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <random>

#include "contact/candidates.hpp"
#include "mesh/gmsh_input.hpp"

using namespace shatter;

namespace {

/// A triangle soup: positions of its nodes before and after the step.
struct Soup {
  std::vector<SurfaceTriangle> triangles;
  std::vector<Vec3> x_old, x_new;
  Index add_node(const Vec3& a, const Vec3& b) {
    x_old.push_back(a);
    x_new.push_back(b);
    return static_cast<Index>(x_old.size() - 1);
  }
  void add_triangle(const std::array<Vec3, 3>& x, const Vec3& motion, int body = 0) {
    triangles.push_back({{add_node(x[0], x[0] + motion), add_node(x[1], x[1] + motion),
                          add_node(x[2], x[2] + motion)},
                         body});
  }
};

/// Every pair is well formed: a vertex not on its face, edges without a
/// shared node, node order canonical; the list sorted and unique.
void expect_well_formed(const ContactPairs& pairs) {
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  EXPECT_TRUE(std::adjacent_find(pairs.begin(), pairs.end()) == pairs.end());
  for (const auto& p : pairs) {
    const auto& n = p.nodes;
    if (p.kind == ContactPair::VertexFace) {
      EXPECT_TRUE(n[0] != n[1] && n[0] != n[2] && n[0] != n[3]);
    } else {
      EXPECT_LT(n[0], n[1]);
      EXPECT_LT(n[2], n[3]);
      EXPECT_LT((std::array{n[0], n[1]}), (std::array{n[2], n[3]}));
      EXPECT_TRUE(n[0] != n[2] && n[0] != n[3] && n[1] != n[2] && n[1] != n[3]);
    }
  }
}

/// find_candidates == brute force on the same boxes, and the test is not vacuous.
void expect_equals_brute_force(const ContactSurface& s, std::span<const Vec3> x_old,
                               std::span<const Vec3> x_new, size_t min_pairs = 1) {
  const ContactPairs fast = find_candidates(s, x_old, x_new);
  const ContactPairs brute = find_candidates_brute_force(s, swept_boxes(s, x_old, x_new));
  EXPECT_GE(brute.size(), min_pairs);
  EXPECT_EQ(fast.size(), brute.size());
  EXPECT_TRUE(fast == brute);
  expect_well_formed(fast);
}

/// n triangles in the unit cube, sizes log-uniform over two decades up to
/// `largest`, each moving by up to its size.
Soup random_soup(unsigned seed, int n, double largest) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto random_vec = [&](double scale) -> Vec3 {
    return Vec3(unit(rng), unit(rng), unit(rng)) * scale;
  };
  Soup soup;
  for (int k = 0; k < n; ++k) {
    const double size = largest * std::pow(10.0, -2.0 * unit(rng));
    const Vec3 c = random_vec(1.0);
    soup.add_triangle({c + random_vec(size), c + random_vec(size), c + random_vec(size)},
                      random_vec(size), k % 3);
  }
  // a neighbour across an edge of every other triangle, so edges are shared
  for (int k = 0; k < n; k += 2) {
    const auto [a, b, c] = soup.triangles[k].nodes;
    const Index d = soup.add_node(
        soup.x_old[c] + (soup.x_old[a] - soup.x_old[c]) + (soup.x_old[b] - soup.x_old[c]),
        soup.x_new[a] + soup.x_new[b] - soup.x_new[c]);
    soup.triangles.push_back({{b, a, d}, soup.triangles[k].body});
  }
  return soup;
}

TEST(Candidates, RandomSoupsEqualBruteForce) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Soup soup = random_soup(seed, 600, 1.0);
    expect_equals_brute_force(make_contact_surface(soup.triangles), soup.x_old, soup.x_new, 100);
  }
}

TEST(Candidates, TwoMovingMeshedBodiesEqualBruteForce) {
  ShapeSpec ball;
  ball.shape = "sphere";
  ball.radius = 0.5;
  ball.element_size = 0.2;
  ball.order = 2;
  ShapeSpec block;
  block.shape = "box";
  block.size = Vec3(1.2, 1.0, 0.8);
  block.center = Vec3(1.05, 0.1, 0);
  block.element_size = 0.25;
  block.order = 2;
  Mesh m = mesh_shape(ball, 0, 0, "ball");
  append_mesh(m, mesh_shape(block, 1, 0, "block"));
  const ContactSurface s = build_contact_surface(m);
  // ball moving at the block, block rotating slightly: 0.1 apart, closing 0.15
  std::vector<Vec3> x_new(m.reference);
  for (Index n = 0; n < m.num_nodes(); ++n) {
    const Vec3& X = m.reference[n];
    x_new[n] = m.node_body[n] == 0 ? Vec3(X + Vec3(0.1, 0.02, 0))
                                   : Vec3(X + 0.05 * Vec3(-X[1], X[0] - 1.05, 0));
  }
  const ContactPairs fast = find_candidates(s, m.reference, x_new);
  expect_equals_brute_force(s, m.reference, x_new, 1000);
  // both self contact and contact between the bodies are found
  bool across = false;
  for (const auto& p : fast) across = across || m.node_body[p.nodes[0]] != m.node_body[p.nodes[3]];
  EXPECT_TRUE(across);
}

/// A flat n x n grid of unit squares, two triangles each, in the plane z = z0,
/// shifted in plane by `shift`, with its own nodes.
void add_plane_grid(Soup& soup, int n, double z0, const Vec3& shift, const Vec3& motion) {
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec3 p = Vec3(i, j, z0) + shift;
      soup.add_triangle({p, p + Vec3(1, 0, 0), p + Vec3(1, 1, 0)}, motion);
      soup.add_triangle({p, p + Vec3(1, 1, 0), p + Vec3(0, 1, 0)}, motion);
    }
}

TEST(Candidates, CoplanarAndCoincidentGeometryEqualsBruteForce) {
  Soup soup;
  add_plane_grid(soup, 12, 0.0, Vec3::Zero(), Vec3::Zero());
  add_plane_grid(soup, 12, 0.0, Vec3::Zero(), Vec3::Zero());        // coincident copy
  add_plane_grid(soup, 12, 0.0, Vec3(0.5, 0.25, 0), Vec3::Zero());  // coplanar, shifted
  add_plane_grid(soup, 6, 0.0, Vec3(2, 2, 0), Vec3(0, 0, 0.5));     // lifting off the plane
  expect_equals_brute_force(make_contact_surface(soup.triangles), soup.x_old, soup.x_new, 1000);
}

TEST(Candidates, DegenerateTrianglesEqualBruteForce) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Soup soup;
  for (int k = 0; k < 500; ++k) {
    const Vec3 a(unit(rng), unit(rng), unit(rng));
    const Vec3 d = 0.05 * Vec3(unit(rng), unit(rng), unit(rng));
    const Vec3 motion = (k % 2) ? Vec3::Zero() : Vec3(0.01 * unit(rng), 0, 0);
    switch (k % 3) {
      case 0:
        soup.add_triangle({a, a, a}, motion);
        break;  // a point
      case 1:
        soup.add_triangle({a, a + d, a + 2.0 * d}, motion);
        break;  // collinear
      default:
        soup.add_triangle({a, a + d, a + d}, motion);
        break;  // two nodes coincide
    }
  }
  expect_equals_brute_force(make_contact_surface(soup.triangles), soup.x_old, soup.x_new, 10);
}

TEST(Candidates, VeryElongatedBoxesEqualBruteForce) {
  Soup soup = random_soup(11, 300, 1.0);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 60; ++k) {
    // needles and slivers 1000 times longer than wide, along every axis
    const int axis = k % 3;
    Vec3 along = Vec3::Zero();
    along[axis] = 1.0;
    const Vec3 p(unit(rng), unit(rng), unit(rng));
    const Vec3 a = p - 0.5 * along, b = p + 0.5 * along,
               c = p + 1e-3 * Vec3(unit(rng), unit(rng), unit(rng));
    soup.add_triangle({a, b, c}, (k % 4 == 0) ? Vec3(0, 0, 0.001) : Vec3::Zero());
  }
  expect_equals_brute_force(make_contact_surface(soup.triangles), soup.x_old, soup.x_new, 100);
}

TEST(Candidates, SingleHugeTriangleAgainstManySmallOnes) {
  Soup soup;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 3000; ++k) {
    const Vec3 p(100 * unit(rng), 100 * unit(rng), 0.2 * unit(rng) - 0.1);
    soup.add_triangle({p, p + Vec3(0.1, 0, 0.05), p + Vec3(0, 0.1, -0.05)}, Vec3(0, 0, 0.01));
  }
  soup.add_triangle({Vec3(-1, -1, 0), Vec3(201, -1, 0), Vec3(-1, 201, 0)}, Vec3::Zero(), 1);
  const ContactSurface s = make_contact_surface(soup.triangles);
  expect_equals_brute_force(s, soup.x_old, soup.x_new, 3000);
  // The huge box sits on a level of its own size: the structure stays linear
  // (at most 2 x 2 cells per box) instead of filling its area with entries.
  const SweptBoxes boxes = swept_boxes(s, soup.x_old, soup.x_new);
  const SparseBucket bucket = build_sparse_bucket(boxes.triangles);
  EXPECT_LE(bucket.entry_box.size(), 4 * boxes.triangles.size());
  EXPECT_GE(bucket.num_levels(), 2);
}

TEST(Candidates, SameListForOneTwoFourThreads) {
  const Soup soup = random_soup(21, 4000, 0.1);
  const ContactSurface s = make_contact_surface(soup.triangles);
  std::vector<ContactPairs> results;
  for (int threads : {1, 2, 4}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    results.push_back(find_candidates(s, soup.x_old, soup.x_new));
  }
  ASSERT_GT(results[0].size(), 1000u);
  EXPECT_TRUE(results[1] == results[0]);
  EXPECT_TRUE(results[2] == results[0]);
}

TEST(Candidates, OwnedCandidatesAreThePairsOfTheKeptEdgesWithTheirPrimitive) {
  // Every third edge kept: the vertex-face pairs all stay, the edge-edge pairs of a kept
  // first edge stay, each with the index of its face or first edge.
  const Soup soup = random_soup(5, 3000, 0.1);
  const ContactSurface s = make_contact_surface(soup.triangles);
  const SweptBoxes boxes = swept_boxes(s, soup.x_old, soup.x_new);
  std::vector<std::uint8_t> kept(s.edges.size());
  for (size_t e = 0; e < kept.size(); ++e) kept[e] = e % 3 == 0;
  const OwnedPairs owned = find_owned_candidates(s, boxes, kept);
  ContactPairs expected;
  std::vector<Index> primitive;
  for (const ContactPair& p : find_candidates(s, boxes)) {
    Index q;
    if (p.kind == ContactPair::VertexFace) {
      const std::array<Index, 3> face{p.nodes[1], p.nodes[2], p.nodes[3]};
      q = static_cast<Index>(std::find(s.triangles.begin(), s.triangles.end(), face) - s.triangles.begin());
    } else {
      const std::array<Index, 2> edge{p.nodes[0], p.nodes[1]};
      const auto e = std::lower_bound(s.edges.begin(), s.edges.end(), edge) - s.edges.begin();
      if (!kept[e]) continue;
      q = s.num_triangles() + static_cast<Index>(e);
    }
    expected.push_back(p);
    primitive.push_back(q);
  }
  const auto edge_pairs = std::count_if(expected.begin(), expected.end(),
                                        [](const ContactPair& p) { return p.kind == ContactPair::EdgeEdge; });
  EXPECT_GT(edge_pairs, 100);
  EXPECT_GT(static_cast<long>(expected.size()) - edge_pairs, 100);
  EXPECT_TRUE(owned.pairs == expected);
  EXPECT_TRUE(owned.primitive == primitive);
}

TEST(Candidates, CanonicalOrderWithSmallAndLargeNodeIds) {
  // Node ids below 2^23 take the radix sort, larger ones the comparison sort: the
  // same canonical list, for 1 and 2 threads, with repeats dropped. Pairs that
  // tie on their first nodes and differ in the last, of both kinds.
  for (const Index largest : {Index{5000}, Index{(1 << 23) - 1}, Index{1 << 23}, Index{2000000000}}) {
    std::mt19937 rng(static_cast<unsigned>(largest));
    std::uniform_int_distribution<Index> node(0, largest), few(0, 3);
    ContactPairs pairs;
    for (int k = 0; k < 40000; ++k) {
      const auto kind = few(rng) % 2 ? ContactPair::EdgeEdge : ContactPair::VertexFace;
      pairs.push_back({kind, {few(rng) ? node(rng) : largest, few(rng), node(rng), few(rng) == 0 ? largest : node(rng)}});
      if (k % 5 == 0) pairs.push_back(pairs.back());
    }
    ContactPairs expected = pairs;
    std::sort(expected.begin(), expected.end());
    expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
    ASSERT_LT(expected.size(), pairs.size());
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      ContactPairs sorted = pairs;
      canonicalize(sorted);
      EXPECT_TRUE(sorted == expected) << "largest node " << largest << ", " << threads << " threads";
    }
  }
}

TEST(Candidates, EmptySurfaceHasNoCandidates) {
  const ContactSurface s;
  const std::vector<Vec3> x;
  EXPECT_TRUE(find_candidates(s, x, x).empty());
}

/// Brute-force ids of the boxes that overlap q, ascending.
std::vector<Index> overlapping(std::span<const Box> boxes, const Box& q) {
  std::vector<Index> ids;
  for (Index k = 0; k < static_cast<Index>(boxes.size()); ++k)
    if (boxes_overlap(q, boxes[k])) ids.push_back(k);
  return ids;
}

TEST(SparseBucket, BoxesOnBucketBoundariesAreReportedExactlyOnce) {
  // Boxes of side 0.5 and 1 on a half-integer lattice: the median side 0.5
  // gives cells of side 1 from the origin 0, so many faces lie exactly on
  // bucket boundaries, and touching boxes (closed intervals) must be found.
  std::vector<Box> boxes;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      for (int k = 0; k < 6; ++k) {
        const Vec3 lo = 0.5 * Vec3(i, j, k);
        const double side = ((i + j + k) % 3 == 0) ? 1.0 : 0.5;
        boxes.push_back({lo, lo + Vec3::Constant(side)});
      }
  boxes.push_back({Vec3(2, 2, 1), Vec3(2, 2, 1)});  // a point on a lattice corner
  const SparseBucket bucket = build_sparse_bucket(boxes);
  ASSERT_EQ(bucket.num_levels(), 1);
  ASSERT_EQ(bucket.cell_size[0], 1.0);
  ASSERT_EQ(bucket.origin[0], 0.0);
  ASSERT_EQ(bucket.origin[1], 0.0);
  std::vector<Box> queries(boxes);
  queries.push_back({Vec3(1, 1, 1), Vec3(1, 1, 1)});
  queries.push_back({Vec3(-1, -1, -1), Vec3(3, 3, 0)});
  queries.push_back({Vec3(0, 0, 0), Vec3(100, 100, 100)});
  for (const Box& q : queries) {
    std::vector<Index> found;
    query_sparse_bucket(bucket, boxes, q, [&](Index id) { found.push_back(id); });
    std::sort(found.begin(), found.end());
    EXPECT_TRUE(std::adjacent_find(found.begin(), found.end()) == found.end())
        << "duplicate report";
    EXPECT_EQ(found, overlapping(boxes, q));
  }
}

TEST(SparseBucket, FloatBoundsAreTheNearestFloatsOutside) {
  // float_below(x) is the largest float <= x and float_above(x) the smallest
  // >= x (std::nextafter's answer where the conversion rounds the wrong way),
  // for doubles of either sign, zero, subnormal, and beyond the float range.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-160, 140);
  std::vector<double> xs{0.0, -0.0, 1e-46, -1e-46, 1.0, -1.0, 0.1, -0.1, 3.5e38, -3.5e38, 1e300, -1e300};
  for (int k = 0; k < 100000; ++k) xs.push_back(std::ldexp(mantissa(rng), exponent(rng)));
  const float inf = std::numeric_limits<float>::infinity();
  for (const double x : xs) {
    const float below = float_below(x), above = float_above(x);
    ASSERT_LE(static_cast<double>(below), x) << x;
    ASSERT_GE(static_cast<double>(above), x) << x;
    ASSERT_GT(static_cast<double>(std::nextafter(below, inf)), x) << x;
    ASSERT_LT(static_cast<double>(std::nextafter(above, -inf)), x) << x;
  }
}

TEST(SparseBucket, SameStructureForOneAndTwoThreads) {
  const Soup soup = random_soup(4, 2000, 0.1);
  const ContactSurface s = make_contact_surface(soup.triangles);
  const SweptBoxes boxes = swept_boxes(s, soup.x_old, soup.x_new);
  SparseBucket one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = build_sparse_bucket(boxes.triangles);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = build_sparse_bucket(boxes.triangles);
  }
  EXPECT_EQ(one.cell_key, two.cell_key);
  EXPECT_EQ(one.cell_entries, two.cell_entries);
  EXPECT_EQ(one.entry_box, two.entry_box);
  EXPECT_LE(one.entry_box.size(), 4 * boxes.triangles.size());
}

}  // namespace
