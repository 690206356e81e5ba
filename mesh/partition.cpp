#include "mesh/partition.hpp"

#include <metis.h>

#include <algorithm>
#include <map>

#include "kernels/error.hpp"

namespace shatter {

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
  for (Index n = 0; n < nn; ++n) {
    append_star_ranks(mesh, n, [&](Index e) { return elem_part[e]; }, t.ranks);
    t.offsets[n + 1] = static_cast<Index>(t.ranks.size());
  }
  return t;
}

namespace {

/// METIS_PartGraphKway of `ng` granules weighted by `vwgt`, two granules
/// adjacent when a set holds items of both, the edge weighted by the number
/// of such sets; for_each_set(add) calls add(granules) with the sorted,
/// distinct granules of each set. A part METIS leaves empty takes a granule
/// of the largest.
template <class ForEachSet>
std::vector<int> partition_set_graph(Index ng, std::vector<idx_t> vwgt, int parts, int seed, const char* what,
                                     ForEachSet for_each_set) {
  std::vector<std::pair<idx_t, idx_t>> pairs;
  for_each_set([&](const std::vector<idx_t>& star) {
    for (size_t i = 0; i < star.size(); ++i)
      for (size_t j = 0; j < star.size(); ++j)
        if (i != j) pairs.push_back({star[i], star[j]});
  });
  std::sort(pairs.begin(), pairs.end());
  std::vector<idx_t> xadj(ng + 1, 0), adjncy, adjwgt;
  for (size_t p = 0; p < pairs.size();) {
    size_t q = p;
    while (q < pairs.size() && pairs[q] == pairs[p]) ++q;
    ++xadj[pairs[p].first + 1];
    adjncy.push_back(pairs[p].second);
    adjwgt.push_back(static_cast<idx_t>(q - p));
    p = q;
  }
  for (Index g = 0; g < ng; ++g) xadj[g + 1] += xadj[g];
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = seed;
  options[METIS_OPTION_NUMBERING] = 0;
  idx_t nv = ng, ncon = 1, nparts = parts, edgecut = 0;
  std::vector<idx_t> part(ng);
  const int status = METIS_PartGraphKway(&nv, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr,
                                         adjwgt.data(), &nparts, nullptr, nullptr, options, &edgecut, part.data());
  SHATTER_REQUIRE(status == METIS_OK, what << ": METIS_PartGraphKway failed with status " << status);
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

/// Sorted, distinct.
void make_set(std::vector<idx_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

}  // namespace

std::vector<int> partition_granules(const Mesh& mesh, Index granule, int parts, int seed) {
  const Index ne = mesh.num_elements(), ng = (ne + granule - 1) / granule;
  // One part takes every granule, none included (a model of shells alone).
  if (parts == 1) return std::vector<int>(ng, 0);
  SHATTER_REQUIRE(parts >= 1 && parts <= ng, "partition_granules: cannot cut " << ng << " granules into " << parts
                                                                                << " parts");
  std::vector<idx_t> vwgt(ng);
  for (Index g = 0; g < ng; ++g) vwgt[g] = std::min(ne, (g + 1) * granule) - g * granule;
  // Edges: granule pairs sharing a node, weighted by the number of shared nodes.
  return partition_set_graph(ng, std::move(vwgt), parts, seed, "partition_granules", [&](auto add) {
    std::vector<idx_t> star;
    for (Index n = 0; n < mesh.num_nodes(); ++n) {
      star.clear();
      for (Index p = mesh.node_elem_offsets[n]; p < mesh.node_elem_offsets[n + 1]; ++p)
        star.push_back(mesh.node_elem[p] / granule);
      make_set(star);
      add(star);
    }
  });
}

std::vector<int> partition_item_granules(Index items, std::span<const Index> groups, int width, Index granule,
                                         int parts, int seed) {
  const Index ng = (items + granule - 1) / granule;
  if (parts == 1) return std::vector<int>(ng, 0);
  SHATTER_REQUIRE(parts >= 1 && parts <= ng, "partition_item_granules: cannot cut " << ng << " granules into "
                                                                                    << parts << " parts");
  std::vector<idx_t> vwgt(ng);
  for (Index g = 0; g < ng; ++g) vwgt[g] = std::min(items, (g + 1) * granule) - g * granule;
  return partition_set_graph(ng, std::move(vwgt), parts, seed, "partition_item_granules", [&](auto add) {
    std::vector<idx_t> set;
    for (size_t i = 0; i + width <= groups.size(); i += width) {
      set.clear();
      for (int a = 0; a < width; ++a)
        if (groups[i + a] >= 0) set.push_back(groups[i + a] / granule);
      make_set(set);
      add(set);
    }
  });
}

}  // namespace shatter
