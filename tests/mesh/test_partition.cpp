// partition_elements and extract_subdomain: every element in exactly one
// balanced part, repeatable; each rank's LocalMesh holds its owned elements
// and exactly one ghost layer, whole element stars of its touched nodes,
// canonical ordering independent of the global mesh's order, and exchange
// lists that agree pairwise between ranks.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>
#include <numeric>
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

/// The same mesh with nodes and elements listed in another (fixed) order.
Mesh permuted(const Mesh& m, std::vector<Index>& elem_perm) {
  const Index ne = m.num_elements(), nn = m.num_nodes();
  const int k = m.nodes_per_element();
  std::vector<Index> node_perm(nn);  // new node i is old node node_perm[i]
  std::iota(node_perm.begin(), node_perm.end(), 0);
  std::reverse(node_perm.begin(), node_perm.end());
  elem_perm.resize(ne);
  for (Index e = 0; e < ne; ++e)
    elem_perm[e] = static_cast<Index>((static_cast<int64_t>(e) * 7919) % ne);
  std::vector<Index> new_of(nn);
  for (Index i = 0; i < nn; ++i) new_of[node_perm[i]] = i;
  Mesh p;
  p.order = m.order;
  for (Index i = 0; i < nn; ++i) {
    p.reference.push_back(m.reference[node_perm[i]]);
    p.node_gid.push_back(m.node_gid[node_perm[i]]);
    p.node_body.push_back(m.node_body[node_perm[i]]);
  }
  for (Index e = 0; e < ne; ++e) {
    const Index old = elem_perm[e];
    for (int a = 0; a < k; ++a) p.conn.push_back(new_of[m.element(old)[a]]);
    p.elem_gid.push_back(m.elem_gid[old]);
    p.elem_body.push_back(m.elem_body[old]);
    p.elem_material.push_back(m.elem_material[old]);
  }
  p.build_node_elements();
  return p;
}

std::vector<GlobalId> gids_of(std::span<const Index> nodes, const Mesh& m) {
  std::vector<GlobalId> g;
  for (Index n : nodes) g.push_back(m.node_gid[n]);
  return g;
}

}  // namespace

TEST(Partition, EveryElementInOneBalancedPartRepeatably) {
  const Mesh mesh = box_mesh();
  const Index ne = mesh.num_elements();
  ASSERT_GT(ne, 1000);
  EXPECT_EQ(partition_elements(mesh, 1), std::vector<int>(ne, 0));
  for (int parts : {2, 3, 5}) {
    const std::vector<int> part = partition_elements(mesh, parts);
    ASSERT_EQ(static_cast<Index>(part.size()), ne);
    std::vector<Index> count(parts, 0);
    for (int p : part) {
      ASSERT_GE(p, 0);
      ASSERT_LT(p, parts);
      ++count[p];
    }
    // METIS' default k-way tolerance: the largest part within 1.03 x the mean.
    const double mean = static_cast<double>(ne) / parts;
    for (int p = 0; p < parts; ++p) {
      EXPECT_GT(count[p], 0) << parts << " parts";
      EXPECT_LE(count[p], 1.03 * mean + 1) << parts << " parts, part " << p;
    }
    EXPECT_EQ(partition_elements(mesh, parts), part) << "repeat with the same seed";
  }
}

TEST(Partition, Tet10GivesTheTet4DualGraphPartition) {
  // The dual graph uses the corner nodes only, so a TET10 mesh of the same
  // corners partitions like its TET4 mesh (same element order from Gmsh).
  const Mesh m1 = box_mesh(1, 0.2), m2 = box_mesh(2, 0.2);
  ASSERT_EQ(m1.num_elements(), m2.num_elements());
  EXPECT_EQ(partition_elements(m1, 3), partition_elements(m2, 3));
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
}

TEST(Partition, RejectsMorePartsThanElements) {
  const Mesh mesh = box_mesh(1, 0.5);
  EXPECT_THROW(partition_elements(mesh, mesh.num_elements() + 1), Error);
  EXPECT_THROW(partition_elements(mesh, 0), Error);
}

TEST(Subdomain, OwnedElementsAndOneGhostLayer) {
  const Mesh mesh = box_mesh();
  const Index ne = mesh.num_elements();
  const int k = mesh.nodes_per_element();
  for (int parts : {1, 2, 3}) {
    const std::vector<int> part = partition_elements(mesh, parts);
    std::map<GlobalId, int> owner_count;
    for (int r = 0; r < parts; ++r) {
      const LocalMesh local = extract_subdomain(mesh, part, r);
      const Mesh& lm = local.mesh;
      // Expected by brute force: owned elements, their nodes, and every other
      // element that uses one of those nodes.
      std::set<Index> touched;
      for (Index e = 0; e < ne; ++e)
        if (part[e] == r) touched.insert(mesh.element(e), mesh.element(e) + k);
      std::set<GlobalId> owned, ghost;
      for (Index e = 0; e < ne; ++e) {
        const bool uses = std::any_of(mesh.element(e), mesh.element(e) + k,
                                      [&](Index n) { return touched.count(n); });
        if (part[e] == r) {
          owned.insert(mesh.elem_gid[e]);
        } else if (uses) {
          ghost.insert(mesh.elem_gid[e]);
        }
      }
      std::set<GlobalId> got_owned, got_ghost;
      for (Index e = 0; e < lm.num_elements(); ++e) {
        (local.owns_element(e) ? got_owned : got_ghost).insert(lm.elem_gid[e]);
        if (local.owns_element(e)) ++owner_count[lm.elem_gid[e]];
      }
      EXPECT_EQ(got_owned, owned) << parts << " parts, rank " << r;
      EXPECT_EQ(got_ghost, ghost) << parts << " parts, rank " << r;
      if (parts == 1) {
        EXPECT_TRUE(got_ghost.empty());
      }

      // Canonical order, and each local element is the global one.
      EXPECT_TRUE(std::is_sorted(lm.elem_gid.begin(), lm.elem_gid.end()));
      EXPECT_TRUE(std::adjacent_find(lm.node_gid.begin(), lm.node_gid.end(),
                                     std::greater_equal<>()) == lm.node_gid.end());
      std::map<GlobalId, Index> global_elem, global_node;
      for (Index e = 0; e < ne; ++e) global_elem[mesh.elem_gid[e]] = e;
      for (Index n = 0; n < mesh.num_nodes(); ++n) global_node[mesh.node_gid[n]] = n;
      for (Index e = 0; e < lm.num_elements(); ++e) {
        const Index g = global_elem.at(lm.elem_gid[e]);
        for (int a = 0; a < k; ++a)
          ASSERT_EQ(lm.node_gid[lm.element(e)[a]], mesh.node_gid[mesh.element(g)[a]]);
      }
      for (Index n = 0; n < lm.num_nodes(); ++n)
        ASSERT_EQ(lm.reference[n], mesh.reference[global_node.at(lm.node_gid[n])]);

      // Every touched node has its whole element star locally; its owner is
      // the smallest rank touching it.
      Index touched_here = 0;
      for (Index n = 0; n < lm.num_nodes(); ++n) {
        const Index g = global_node.at(lm.node_gid[n]);
        int min_rank = parts;
        for (Index p = mesh.node_elem_offsets[g]; p < mesh.node_elem_offsets[g + 1]; ++p)
          min_rank = std::min(min_rank, part[mesh.node_elem[p]]);
        EXPECT_EQ(local.node_owner[n], min_rank);
        EXPECT_EQ(local.node_touched[n] != 0, touched.count(g) == 1);
        if (!local.node_touched[n]) continue;
        ++touched_here;
        std::set<GlobalId> star, local_star;
        for (Index p = mesh.node_elem_offsets[g]; p < mesh.node_elem_offsets[g + 1]; ++p)
          star.insert(mesh.elem_gid[mesh.node_elem[p]]);
        for (Index p = lm.node_elem_offsets[n]; p < lm.node_elem_offsets[n + 1]; ++p)
          local_star.insert(lm.elem_gid[lm.node_elem[p]]);
        ASSERT_EQ(local_star, star) << "node " << lm.node_gid[n];
      }
      EXPECT_EQ(touched_here, static_cast<Index>(touched.size()));
    }
    EXPECT_EQ(static_cast<Index>(owner_count.size()), ne);
    for (const auto& [gid, count] : owner_count) ASSERT_EQ(count, 1) << "element " << gid;
  }
}

TEST(Subdomain, ExchangeListsAgreeBetweenRanks) {
  const Mesh mesh = box_mesh(2, 0.2);
  const int parts = 3;
  const std::vector<int> part = partition_elements(mesh, parts);
  std::vector<LocalMesh> locals;
  for (int r = 0; r < parts; ++r) locals.push_back(extract_subdomain(mesh, part, r));
  auto list = [&](const NodeExchange& x, int q, const LocalMesh& l) {
    const auto it = std::find(x.ranks.begin(), x.ranks.end(), q);
    return it == x.ranks.end()
               ? std::vector<GlobalId>{}
               : gids_of(x.nodes_of(static_cast<int>(it - x.ranks.begin())), l.mesh);
  };
  Index ghost_only = 0;
  for (int r = 0; r < parts; ++r) {
    const LocalMesh& lr = locals[r];
    for (int q = 0; q < parts; ++q) {
      if (q == r) continue;
      EXPECT_EQ(list(lr.shared, q, lr), list(locals[q].shared, r, locals[q])) << r << " <-> " << q;
      EXPECT_EQ(list(lr.ghost_send, q, lr), list(locals[q].ghost_recv, r, locals[q]))
          << r << " -> " << q;
      EXPECT_EQ(list(lr.ghost_only_send, q, lr), list(locals[q].ghost_only_recv, r, locals[q]))
          << r << " -> " << q;
    }
    // Every node owned elsewhere is received exactly once, from its owner.
    std::vector<int> received(lr.mesh.num_nodes(), 0), received_only(lr.mesh.num_nodes(), 0);
    for (int i = 0; i < lr.ghost_only_recv.num_ranks(); ++i)
      for (Index n : lr.ghost_only_recv.nodes_of(i)) {
        ++received_only[n];
        EXPECT_EQ(lr.node_owner[n], lr.ghost_only_recv.ranks[i]);
      }
    for (int i = 0; i < lr.ghost_recv.num_ranks(); ++i)
      for (Index n : lr.ghost_recv.nodes_of(i)) {
        ++received[n];
        EXPECT_EQ(lr.node_owner[n], lr.ghost_recv.ranks[i]);
      }
    for (Index n = 0; n < lr.mesh.num_nodes(); ++n) {
      EXPECT_EQ(received[n], lr.owns_node(n) ? 0 : 1);
      EXPECT_EQ(received_only[n], lr.node_touched[n] ? 0 : 1);
      ghost_only += !lr.node_touched[n];
    }
  }
  EXPECT_GT(ghost_only, 0) << "the ghost layer brings nodes no owned element uses";
}

TEST(Subdomain, DoesNotDependOnTheGlobalMeshOrder) {
  const Mesh mesh = box_mesh();
  std::vector<Index> elem_perm;
  const Mesh other = permuted(mesh, elem_perm);
  const std::vector<int> part = partition_elements(mesh, 3);
  std::vector<int> other_part(part.size());
  for (size_t e = 0; e < part.size(); ++e) other_part[e] = part[elem_perm[e]];
  for (int r = 0; r < 3; ++r) {
    const LocalMesh a = extract_subdomain(mesh, part, r),
                    b = extract_subdomain(other, other_part, r);
    EXPECT_EQ(a.mesh.conn, b.mesh.conn);
    EXPECT_EQ(a.mesh.elem_gid, b.mesh.elem_gid);
    EXPECT_EQ(a.mesh.node_gid, b.mesh.node_gid);
    EXPECT_EQ(a.mesh.reference, b.mesh.reference);
    EXPECT_EQ(a.elem_owner, b.elem_owner);
    EXPECT_EQ(a.node_owner, b.node_owner);
    EXPECT_EQ(a.shared.nodes, b.shared.nodes);
    EXPECT_EQ(a.ghost_send.nodes, b.ghost_send.nodes);
    EXPECT_EQ(a.ghost_recv.nodes, b.ghost_recv.nodes);
    EXPECT_EQ(a.ghost_only_send.nodes, b.ghost_only_send.nodes);
  }
}
