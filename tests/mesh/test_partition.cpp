// partition_granules: every granule in exactly one part, no part empty,
// balanced, repeatable with the seed; touching_ranks: the sorted, distinct
// parts of each node's element star; exchange_from: node lists grouped by
// rank in ascending rank order.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "kernels/error.hpp"
#include "mesh/gmsh_input.hpp"
#include "mesh/partition.hpp"

using namespace shatter;

namespace {

Mesh box_mesh(int order = 1, double h = 0.12) {
  ShapeSpec spec;
  spec.shape = "box";
  spec.size = Vec3(1.0, 0.8, 0.6);
  spec.element_size = h;
  spec.order = order;
  Mesh mesh = mesh_shape(spec, 0, 0, "test_partition");
  mesh.build_node_elements();
  return mesh;
}

/// Part of every element from the part of its granule.
std::vector<int> element_parts(const Mesh& mesh, Index granule, const std::vector<int>& granule_part) {
  std::vector<int> part(mesh.num_elements());
  for (Index e = 0; e < mesh.num_elements(); ++e) part[e] = granule_part[e / granule];
  return part;
}

}  // namespace

TEST(Partition, EveryGranuleInOneBalancedPartRepeatably) {
  const Mesh mesh = box_mesh();
  const Index ne = mesh.num_elements(), granule = 64, ng = (ne + granule - 1) / granule;
  ASSERT_GT(ng, 20);
  EXPECT_EQ(partition_granules(mesh, granule, 1), std::vector<int>(ng, 0));
  for (int parts : {2, 3, 5}) {
    const std::vector<int> part = partition_granules(mesh, granule, parts);
    ASSERT_EQ(static_cast<Index>(part.size()), ng);
    std::vector<Index> elements(parts, 0);
    for (Index g = 0; g < ng; ++g) {
      ASSERT_GE(part[g], 0);
      ASSERT_LT(part[g], parts);
      elements[part[g]] += std::min(ne, (g + 1) * granule) - g * granule;
    }
    // METIS' default k-way tolerance on the vertex weights (elements), 1.03 x
    // the mean, which whole granules can overshoot by less than one granule.
    const double mean = static_cast<double>(ne) / parts;
    for (int p = 0; p < parts; ++p) {
      EXPECT_GT(elements[p], 0) << parts << " parts, part " << p;
      EXPECT_LE(elements[p], 1.03 * mean + granule) << parts << " parts, part " << p;
    }
    EXPECT_EQ(partition_granules(mesh, granule, parts), part) << "repeat with the same seed";
    EXPECT_EQ(partition_granules(mesh, granule, parts, 7), partition_granules(mesh, granule, parts, 7))
        << "repeat with another seed";
  }
}

TEST(Partition, GranulesLeaveNoPartEmpty) {
  // Up to one granule per part, where METIS alone leaves parts empty.
  const Mesh mesh = box_mesh(1, 0.25);
  const Index granule = 64, ng = (mesh.num_elements() + granule - 1) / granule;
  ASSERT_GE(ng, 4);
  for (int parts = 2; parts <= ng; ++parts) {
    const std::vector<int> part = partition_granules(mesh, granule, parts);
    ASSERT_EQ(static_cast<Index>(part.size()), ng);
    std::vector<Index> count(parts, 0);
    for (int p : part) ++count[p];
    for (int p = 0; p < parts; ++p) EXPECT_GT(count[p], 0) << parts << " parts, part " << p;
    EXPECT_EQ(partition_granules(mesh, granule, parts), part) << "repeat";
  }
  EXPECT_THROW(partition_granules(mesh, granule, static_cast<int>(ng) + 1), Error);
  EXPECT_THROW(partition_granules(mesh, granule, 0), Error);
}

TEST(Partition, TouchingRanksOfTwoTetsAndAnUnusedNode) {
  // Tets (0 1 2 3) on part 2 and (1 2 3 4) on part 0 share the face 1 2 3;
  // node 5 belongs to no element.
  Mesh mesh;
  for (int n = 0; n < 6; ++n) {
    mesh.reference.push_back(Vec3(n, n % 2, n % 3));
    mesh.node_gid.push_back(n + 1);
    mesh.node_body.push_back(0);
  }
  mesh.conn = {0, 1, 2, 3, 1, 2, 3, 4};
  mesh.elem_gid = {1, 2};
  mesh.elem_body = {0, 0};
  mesh.elem_material = {0, 0};
  mesh.build_node_elements();
  const std::vector<int> elem_part{2, 0};
  const NodeRanks touch = touching_ranks(mesh, elem_part);
  ASSERT_EQ(touch.offsets.size(), 7u);
  const std::vector<std::vector<int>> expected{{2}, {0, 2}, {0, 2}, {0, 2}, {0}, {}};
  for (Index n = 0; n < 6; ++n) {
    const auto got = touch.of(n);
    EXPECT_EQ(std::vector<int>(got.begin(), got.end()), expected[n]) << "node " << n;
  }
}

TEST(Partition, TouchingRanksAreTheSortedPartsOfEachStar) {
  const Mesh mesh = box_mesh(2, 0.2);
  const Index granule = 32;
  const int k = mesh.nodes_per_element();
  for (int parts : {1, 3}) {
    const std::vector<int> elem_part = element_parts(mesh, granule, partition_granules(mesh, granule, parts));
    // Brute force from the connectivity, without the node -> element CSR.
    std::vector<std::set<int>> expected(mesh.num_nodes());
    for (Index e = 0; e < mesh.num_elements(); ++e)
      for (int a = 0; a < k; ++a) expected[mesh.element(e)[a]].insert(elem_part[e]);
    const NodeRanks touch = touching_ranks(mesh, elem_part);
    ASSERT_EQ(static_cast<Index>(touch.offsets.size()), mesh.num_nodes() + 1);
    Index shared = 0;
    for (Index n = 0; n < mesh.num_nodes(); ++n) {
      const auto got = touch.of(n);
      ASSERT_EQ(std::vector<int>(got.begin(), got.end()), std::vector<int>(expected[n].begin(), expected[n].end()))
          << parts << " parts, node " << n;
      shared += got.size() > 1;
    }
    if (parts > 1) {
      EXPECT_GT(shared, 0) << "the parts meet at nodes";
    }
  }
}

TEST(Partition, ExchangeFromGroupsNodesByAscendingRank) {
  const std::map<int, std::vector<Index>> by_rank{{4, {9, 11}}, {1, {3}}, {2, {0, 5, 6}}};
  const NodeExchange x = exchange_from(by_rank);
  ASSERT_EQ(x.num_ranks(), 3);
  EXPECT_EQ(x.ranks, (std::vector<int>{1, 2, 4}));
  EXPECT_EQ(x.offsets, (std::vector<Index>{0, 1, 4, 6}));
  EXPECT_EQ(x.nodes, (std::vector<Index>{3, 0, 5, 6, 9, 11}));
  for (int i = 0; i < x.num_ranks(); ++i) {
    const auto nodes = x.nodes_of(i);
    EXPECT_EQ(std::vector<Index>(nodes.begin(), nodes.end()), by_rank.at(x.ranks[i])) << "rank " << x.ranks[i];
  }
  const NodeExchange none = exchange_from({});
  EXPECT_EQ(none.num_ranks(), 0);
  EXPECT_EQ(none.offsets, std::vector<Index>{0});
  EXPECT_TRUE(none.nodes.empty());
}
