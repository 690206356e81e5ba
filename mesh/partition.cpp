#include "mesh/partition.hpp"

#include <metis.h>

#include <algorithm>
#include <map>

#include "kernels/error.hpp"

namespace shatter {
namespace {

/// Indices 0..n-1 sorted by gid[i]; throws on a repeated gid.
std::vector<Index> order_by_gid(const std::vector<Index>& items, const std::vector<GlobalId>& gid,
                                const char* what) {
  std::vector<Index> sorted = items;
  std::sort(sorted.begin(), sorted.end(), [&](Index a, Index b) { return gid[a] < gid[b]; });
  for (size_t i = 1; i < sorted.size(); ++i)
    SHATTER_REQUIRE(
        gid[sorted[i - 1]] != gid[sorted[i]],
        "extract_subdomain: " << what << " global id " << gid[sorted[i]] << " appears twice");
  return sorted;
}

}  // namespace

NodeExchange exchange_from(const std::map<int, std::vector<Index>>& by_rank) {
  NodeExchange x;
  for (const auto& [q, nodes] : by_rank) {
    x.ranks.push_back(q);
    x.nodes.insert(x.nodes.end(), nodes.begin(), nodes.end());
    x.offsets.push_back(static_cast<Index>(x.nodes.size()));
  }
  return x;
}

NodeRanks touching_ranks(const Mesh& mesh, std::span<const int> elem_part) {
  NodeRanks t;
  const Index nn = mesh.num_nodes();
  t.offsets.assign(static_cast<size_t>(nn) + 1, 0);
  std::vector<int> star;
  for (Index n = 0; n < nn; ++n) {
    star.clear();
    for (Index p = mesh.node_elem_offsets[n]; p < mesh.node_elem_offsets[n + 1]; ++p)
      star.push_back(elem_part[mesh.node_elem[p]]);
    std::sort(star.begin(), star.end());
    star.erase(std::unique(star.begin(), star.end()), star.end());
    t.ranks.insert(t.ranks.end(), star.begin(), star.end());
    t.offsets[n + 1] = static_cast<Index>(t.ranks.size());
  }
  return t;
}


std::vector<int> partition_granules(const Mesh& mesh, Index granule, int parts, int seed) {
  const Index ne = mesh.num_elements(), ng = (ne + granule - 1) / granule;
  SHATTER_REQUIRE(parts >= 1 && parts <= ng, "partition_granules: cannot cut " << ng << " granules into " << parts
                                                                                << " parts");
  if (parts == 1) return std::vector<int>(ng, 0);
  // Edges: granule pairs sharing a node, weighted by the number of shared nodes.
  std::vector<std::pair<idx_t, idx_t>> pairs;
  std::vector<idx_t> star;
  for (Index n = 0; n < mesh.num_nodes(); ++n) {
    star.clear();
    for (Index p = mesh.node_elem_offsets[n]; p < mesh.node_elem_offsets[n + 1]; ++p)
      star.push_back(mesh.node_elem[p] / granule);
    std::sort(star.begin(), star.end());
    star.erase(std::unique(star.begin(), star.end()), star.end());
    for (size_t i = 0; i < star.size(); ++i)
      for (size_t j = 0; j < star.size(); ++j)
        if (i != j) pairs.push_back({star[i], star[j]});
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<idx_t> xadj(ng + 1, 0), adjncy, adjwgt, vwgt(ng);
  for (size_t p = 0; p < pairs.size();) {
    size_t q = p;
    while (q < pairs.size() && pairs[q] == pairs[p]) ++q;
    ++xadj[pairs[p].first + 1];
    adjncy.push_back(pairs[p].second);
    adjwgt.push_back(static_cast<idx_t>(q - p));
    p = q;
  }
  for (Index g = 0; g < ng; ++g) {
    xadj[g + 1] += xadj[g];
    vwgt[g] = std::min(ne, (g + 1) * granule) - g * granule;
  }
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = seed;
  options[METIS_OPTION_NUMBERING] = 0;
  idx_t nv = ng, ncon = 1, nparts = parts, edgecut = 0;
  std::vector<idx_t> part(ng);
  const int status = METIS_PartGraphKway(&nv, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr,
                                         adjwgt.data(), &nparts, nullptr, nullptr, options, &edgecut, part.data());
  SHATTER_REQUIRE(status == METIS_OK, "partition_granules: METIS_PartGraphKway failed with status " << status);
  // With few granules per part METIS may leave a part empty (6 granules in 4
  // parts): each empty part takes the last granule of the part with the most
  // (the first such part), so every rank has work; deterministic like METIS.
  std::vector<int> out(part.begin(), part.end());
  std::vector<Index> count(parts, 0);
  for (int p : out) ++count[p];
  for (int p = 0; p < parts; ++p) {
    if (count[p] > 0) continue;
    const int big = static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
    Index g = ng - 1;
    while (out[g] != big) --g;
    out[g] = p;
    --count[big];
    ++count[p];
  }
  return out;
}

std::vector<int> partition_elements(const Mesh& mesh, int parts, int seed) {
  const Index ne = mesh.num_elements();
  SHATTER_REQUIRE(parts >= 1 && parts <= ne, "partition_elements: cannot cut "
                                                 << ne << " elements into " << parts << " parts");
  if (parts == 1) return std::vector<int>(ne, 0);

  // Corner nodes only: a TET10 face shares 3 corners exactly when a TET4 face does.
  std::vector<idx_t> eptr(static_cast<size_t>(ne) + 1), eind(static_cast<size_t>(ne) * 4);
  for (Index e = 0; e < ne; ++e) {
    eptr[e] = 4 * e;
    for (int a = 0; a < 4; ++a) eind[4 * static_cast<size_t>(e) + a] = mesh.element(e)[a];
  }
  eptr[ne] = 4 * ne;
  idx_t n_elem = ne, n_node = mesh.num_nodes(), ncommon = 3, numflag = 0;
  idx_t *xadj = nullptr, *adjncy = nullptr;
  int status = METIS_MeshToDual(&n_elem, &n_node, eptr.data(), eind.data(), &ncommon, &numflag,
                                &xadj, &adjncy);
  SHATTER_REQUIRE(status == METIS_OK,
                  "partition_elements: METIS_MeshToDual failed with status " << status);

  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = seed;
  options[METIS_OPTION_NUMBERING] = 0;
  idx_t ncon = 1, nparts = parts, edgecut = 0;
  std::vector<idx_t> part(ne);
  status = METIS_PartGraphKway(&n_elem, &ncon, xadj, adjncy, nullptr, nullptr, nullptr, &nparts,
                               nullptr, nullptr, options, &edgecut, part.data());
  METIS_Free(xadj);
  METIS_Free(adjncy);
  SHATTER_REQUIRE(status == METIS_OK,
                  "partition_elements: METIS_PartGraphKway failed with status " << status);
  return std::vector<int>(part.begin(), part.end());
}

LocalMesh extract_subdomain(const Mesh& global, std::span<const int> elem_part, int rank) {
  const Index ne = global.num_elements(), nn = global.num_nodes();
  const int k = global.nodes_per_element();
  SHATTER_REQUIRE(
      static_cast<Index>(elem_part.size()) == ne,
      "extract_subdomain: " << elem_part.size() << " parts given for " << ne << " elements");
  SHATTER_REQUIRE(static_cast<Index>(global.node_elem_offsets.size()) == nn + 1,
                  "extract_subdomain: the global mesh has no node -> element CSR");
  const NodeRanks touch = touching_ranks(global, elem_part);

  // Touched nodes, then held elements (their stars) and held nodes.
  std::vector<char> touched(nn, 0), held_elem(ne, 0), held_node(nn, 0);
  for (Index e = 0; e < ne; ++e)
    if (elem_part[e] == rank)
      for (int a = 0; a < k; ++a) touched[global.element(e)[a]] = 1;
  for (Index n = 0; n < nn; ++n)
    if (touched[n])
      for (Index p = global.node_elem_offsets[n]; p < global.node_elem_offsets[n + 1]; ++p)
        held_elem[global.node_elem[p]] = 1;
  std::vector<Index> elems, nodes;
  for (Index e = 0; e < ne; ++e)
    if (held_elem[e]) {
      elems.push_back(e);
      for (int a = 0; a < k; ++a) held_node[global.element(e)[a]] = 1;
    }
  for (Index n = 0; n < nn; ++n)
    if (held_node[n]) nodes.push_back(n);
  elems = order_by_gid(elems, global.elem_gid, "element");
  nodes = order_by_gid(nodes, global.node_gid, "node");

  LocalMesh local;
  local.rank = rank;
  Mesh& m = local.mesh;
  m.order = global.order;
  m.revision = global.revision;
  std::vector<Index> to_local(nn, -1);
  for (Index i = 0; i < static_cast<Index>(nodes.size()); ++i) {
    const Index n = nodes[i];
    to_local[n] = i;
    m.reference.push_back(global.reference[n]);
    m.node_gid.push_back(global.node_gid[n]);
    m.node_body.push_back(global.node_body[n]);
    local.node_owner.push_back(touch.of(n).front());
    local.node_touched.push_back(touched[n]);
  }
  for (Index e : elems) {
    for (int a = 0; a < k; ++a) m.conn.push_back(to_local[global.element(e)[a]]);
    m.elem_gid.push_back(global.elem_gid[e]);
    m.elem_body.push_back(global.elem_body[e]);
    m.elem_material.push_back(global.elem_material[e]);
    local.elem_owner.push_back(elem_part[e]);
  }
  m.build_node_elements();

  // A rank holds element e exactly when it touches one of e's nodes, so the
  // ranks holding node n are the union of touch(m) over the nodes m of its star.
  std::map<int, std::vector<Index>> shared, send, recv, only_send, only_recv;
  std::vector<int> holders;
  for (Index i = 0; i < static_cast<Index>(nodes.size()); ++i) {
    const Index n = nodes[i];
    if (touched[n])
      for (int q : touch.of(n))
        if (q != rank) shared[q].push_back(i);
    if (local.node_owner[i] != rank) {
      recv[local.node_owner[i]].push_back(i);
      if (!touched[n]) only_recv[local.node_owner[i]].push_back(i);
      continue;
    }
    holders.clear();
    for (Index p = global.node_elem_offsets[n]; p < global.node_elem_offsets[n + 1]; ++p) {
      const Index* c = global.element(global.node_elem[p]);
      for (int a = 0; a < k; ++a) {
        const auto t = touch.of(c[a]);
        holders.insert(holders.end(), t.begin(), t.end());
      }
    }
    std::sort(holders.begin(), holders.end());
    holders.erase(std::unique(holders.begin(), holders.end()), holders.end());
    const auto touching = touch.of(n);
    for (int q : holders) {
      if (q == rank) continue;
      send[q].push_back(i);
      if (!std::binary_search(touching.begin(), touching.end(), q)) only_send[q].push_back(i);
    }
  }
  local.shared = exchange_from(shared);
  local.ghost_send = exchange_from(send);
  local.ghost_recv = exchange_from(recv);
  local.ghost_only_send = exchange_from(only_send);
  local.ghost_only_recv = exchange_from(only_recv);
  return local;
}

}  // namespace shatter
