// The contact surface listed where its faces are (runtime/named_surface.hpp), at 1, 2
// and 3 ranks: each rank names the boundary triangles of its owned elements and the
// edges whose smallest-named triangle is one of them; over the ranks the triangles in
// name order are the one-rank surface's, triangle for triangle, and every edge of the
// whole surface is listed once; and the triangles a rank lists around the nodes whose
// volume owner it is are the whole surface's there. TET4 and TET10 (whose faces are 4
// sub-triangles each).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "mpi_environment.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/model.hpp"
#include "runtime/named_surface.hpp"
#include "scene_text.hpp"

namespace shatter {
namespace {

std::string scene_text(int order) {
  const std::string mesh = "element_size: 0.004, order: " + std::to_string(order);
  return "name: named\ntime: {end: 1.0}\n"
         "materials:\n  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n"
         "bodies:\n"
         "  - {name: a, material: steel, mesh: {shape: sphere, radius: 0.01, " + mesh + "}}\n"
         "  - {name: b, material: steel, mesh: {shape: box, size: [0.02, 0.02, 0.02], center: [0.021, 0.003, 0], " +
         mesh + "}}\n"
         "contact: {}\n";
}

void check_order(int order) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const Scene scene = test::scene_from_text("named_o" + std::to_string(order), scene_text(order));
  const Model part = build_model(scene, MPI_COMM_WORLD), whole = build_model(scene);
  EXPECT_EQ(part.is_part(), ranks > 1);
  const Decomposition dec(part, MPI_COMM_WORLD);
  const NamedSurface mine = owned_surface(part, dec);
  for (const NamedTriangle& t : mine.triangles) {
    const Index e = part.local_element(t.name[0]);
    ASSERT_GE(e, 0);
    EXPECT_TRUE(dec.owns_element(e)) << "triangle of element " << t.name[0] << " named by a rank not owning it";
  }
  // Every rank's lists on every rank: a primitive as its words (append_words).
  std::vector<Index> flat, edges;
  for (const NamedTriangle& t : mine.triangles) append_words(t, flat);
  for (const NamedEdge& e : mine.edges) append_words(e, edges);
  flat = dec.allgather(flat);
  edges = dec.allgather(edges);
  std::vector<NamedTriangle> all;
  for (size_t k = 0; k + kNamedTriangleWords <= flat.size(); k += kNamedTriangleWords)
    all.push_back(read_triangle(&flat[k]));
  std::sort(all.begin(), all.end(), [](const NamedTriangle& a, const NamedTriangle& b) { return a.name < b.name; });
  std::vector<NamedEdge> named_edges;
  for (size_t k = 0; k + kNamedEdgeWords <= edges.size(); k += kNamedEdgeWords)
    named_edges.push_back(read_edge(&edges[k]));
  std::sort(named_edges.begin(), named_edges.end(),
            [](const NamedEdge& a, const NamedEdge& b) { return a.nodes < b.nodes; });
  std::vector<std::array<Index, 2>> all_edges;
  for (const NamedEdge& e : named_edges) all_edges.push_back(e.nodes);
  EXPECT_EQ(std::adjacent_find(all_edges.begin(), all_edges.end()), all_edges.end()) << "an edge listed twice";

  // The one-rank surface (whole mesh ids are whole ids), in the same order.
  const ContactSurface surface = build_contact_surface(whole.mesh);
  ASSERT_EQ(all.size(), surface.triangles.size());
  for (size_t t = 0; t < all.size(); ++t) {
    EXPECT_EQ(all[t].nodes, surface.triangles[t]) << "triangle " << t;
    EXPECT_EQ(all[t].body, surface.body[t]) << "triangle " << t;
    EXPECT_EQ(all[t].name[2], order == 1 ? 0 : static_cast<Index>(t % 4)) << "triangle " << t;
  }
  EXPECT_EQ(all_edges, surface.edges);
  const auto names = std::unique(all.begin(), all.end(),
                                 [](const NamedTriangle& a, const NamedTriangle& b) { return a.name == b.name; });
  EXPECT_EQ(names, all.end()) << "a name given twice";
  if (ranks > 1) {
    EXPECT_LT(mine.triangles.size(), surface.triangles.size());
    EXPECT_LT(mine.edges.size(), surface.edges.size());
  }

  // Around each surface node whose volume owner this rank is, its home triangles are the
  // whole surface's (names, nodes, bodies), in name order.
  const std::vector<NamedTriangle> home = home_triangles(part, dec);
  const VertexTriangles around = vertex_triangles(surface);
  long checked = 0;
  for (Index k = 0; k < surface.num_vertices(); ++k) {
    const Index whole_id = surface.vertices[k], n = part.local_node(whole_id);
    if (n < 0 || (ranks > 1 && (dec.node_ranks(n).empty() || dec.node_owner(n) != rank))) continue;
    std::vector<NamedTriangle> expected, got;
    for (Index i = around.offsets[k]; i < around.offsets[k + 1]; ++i) expected.push_back(all[around.items[i]]);
    for (const NamedTriangle& t : home)
      if (std::find(t.nodes.begin(), t.nodes.end(), whole_id) != t.nodes.end()) got.push_back(t);
    EXPECT_EQ(got, expected) << "triangles around node " << whole_id;
    ++checked;
  }
  long counts[2] = {checked, static_cast<long>(surface.vertices.size())};
  MPI_Allreduce(MPI_IN_PLACE, counts, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(counts[0], counts[1]) << "surface nodes with no volume owner, or with two";

  // Each primitive carries its nodes' volume owners (those each rank says it is) and the body.
  std::vector<Index> homes;
  for (const Index whole_id : surface.vertices)
    if (const Index n = part.local_node(whole_id);
        n >= 0 && (ranks == 1 || (!dec.node_ranks(n).empty() && dec.node_owner(n) == rank)))
      homes.insert(homes.end(), {whole_id, rank});
  homes = dec.allgather(homes);
  std::vector<int> owner_of(whole.mesh.num_nodes(), -1);
  for (size_t k = 0; k + 2 <= homes.size(); k += 2) owner_of[homes[k]] = static_cast<int>(homes[k + 1]);
  for (const NamedTriangle& t : all)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(t.owner[c], owner_of[t.nodes[c]]) << "node " << t.nodes[c];
  for (const NamedEdge& e : named_edges) {
    for (int c = 0; c < 2; ++c) EXPECT_EQ(e.owner[c], owner_of[e.nodes[c]]) << "node " << e.nodes[c];
    EXPECT_EQ(e.body, whole.mesh.node_body[e.nodes[0]]);
  }
}

TEST(NamedSurface, RanksNameTheWholeSurfaceOnceTet4) { check_order(1); }
TEST(NamedSurface, RanksNameTheWholeSurfaceOnceTet10) { check_order(2); }

}  // namespace
}  // namespace shatter
