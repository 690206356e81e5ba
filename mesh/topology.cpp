#include "mesh/topology.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "kernels/error.hpp"

namespace shatter {

namespace {

int face_node_count(const Mesh& mesh) {
  return mesh.order == 1 ? 3 : 6;
}

int local_index(const Mesh& mesh, Index e, Index n) {
  const Index* c = mesh.element(e);
  for (int a = 0; a < mesh.nodes_per_element(); ++a)
    if (c[a] == n) return a;
  return -1;
}

bool face_contains(const Mesh& mesh, Index e, int face, Index n) {
  const Index* c = mesh.element(e);
  for (int j = 0; j < face_node_count(mesh); ++j)
    if (c[kTetFaces[face][j]] == n) return true;
  return false;
}

}  // namespace

std::array<Index, 6> face_nodes(const Mesh& mesh, Index e, int face) {
  std::array<Index, 6> out;
  out.fill(-1);
  const Index* c = mesh.element(e);
  for (int j = 0; j < face_node_count(mesh); ++j) out[j] = c[kTetFaces[face][j]];
  return out;
}

Topology build_topology(const Mesh& mesh, GlobalId split_gid_base) {
  const Index ne = mesh.num_elements();
  // One record per element face, keyed by its sorted corners; equal keys are
  // the two sides of one facet.
  struct FaceRecord {
    std::array<Index, 3> key;
    Index elem;
    int face;
  };
  std::vector<FaceRecord> records;
  records.reserve(static_cast<size_t>(ne) * 4);
  for (Index e = 0; e < ne; ++e)
    for (int i = 0; i < 4; ++i) {
      const std::array<Index, 6> fn = face_nodes(mesh, e, i);
      std::array<Index, 3> key = {fn[0], fn[1], fn[2]};
      std::sort(key.begin(), key.end());
      records.push_back({key, e, i});
    }
  std::sort(records.begin(), records.end(), [](const FaceRecord& a, const FaceRecord& b) {
    return a.key != b.key ? a.key < b.key : a.elem < b.elem;
  });

  // The facets, as pairs of equal keys: element 0 (smaller global id) first.
  struct FacetRecord {
    std::array<Index, 2> elems;
    std::array<std::int8_t, 2> faces;
  };
  std::vector<FacetRecord> facets;
  for (size_t r = 0; r < records.size();) {
    size_t end = r + 1;
    while (end < records.size() && records[end].key == records[r].key) ++end;
    SHATTER_REQUIRE(end - r <= 2, "build_topology: face of element "
                                      << mesh.elem_gid[records[r].elem] << " is shared by "
                                      << end - r << " elements (non-manifold mesh)");
    FacetRecord facet = {{records[r].elem, -1}, {static_cast<std::int8_t>(records[r].face), -1}};
    if (end - r == 2) {
      facet.elems[1] = records[r + 1].elem;
      facet.faces[1] = static_cast<std::int8_t>(records[r + 1].face);
      if (mesh.elem_gid[facet.elems[1]] < mesh.elem_gid[facet.elems[0]]) {
        std::swap(facet.elems[0], facet.elems[1]);
        std::swap(facet.faces[0], facet.faces[1]);
      }
    }
    facets.push_back(facet);
    r = end;
  }
  // Numbered in the order of their element 0, then its local face: the facet
  // check (fracture/facet_criterion.cpp) walks the facets in order and so
  // reads the conn rows, stresses and norms of the elements 0 in order (in
  // the order of sorted corners it missed the cache on every conn row). Local
  // facet ids mean nothing across ranks (facet_gid does), so the order is free.
  std::vector<Index> facet_at(static_cast<size_t>(ne) * 4, -1);  // slot 4 e + face of element 0
  for (size_t i = 0; i < facets.size(); ++i)
    facet_at[static_cast<size_t>(facets[i].elems[0]) * 4 + facets[i].faces[0]] = static_cast<Index>(i);
  Topology topo;
  topo.elem_facet.assign(static_cast<size_t>(ne) * 4, -1);
  for (const Index i : facet_at) {
    if (i < 0) continue;
    const FacetRecord& facet = facets[i];
    const Index f = topo.num_facets();
    topo.facet_elem.push_back(facet.elems);
    topo.facet_face.push_back(facet.faces);
    topo.facet_state.push_back(facet.elems[1] >= 0 ? FacetState::intact : FacetState::free);
    topo.facet_gid.push_back(4 * mesh.elem_gid[facet.elems[0]] + facet.faces[0]);
    for (int j = 0; j < 2; ++j)
      if (facet.elems[j] >= 0) topo.elem_facet[static_cast<size_t>(facet.elems[j]) * 4 + facet.faces[j]] = f;
  }
  if (split_gid_base < 0)
    split_gid_base =
        mesh.node_gid.empty() ? 0 : *std::max_element(mesh.node_gid.begin(), mesh.node_gid.end());
  topo.split_gid_base = split_gid_base;
  return topo;
}

std::vector<std::array<Index, 2>> split_nodes(Mesh& mesh, const Topology& topo,
                                              std::span<const Index> facets) {
  const int k = mesh.nodes_per_element();
  // Stars changed during this call; the CSR is rebuilt once at the end.
  std::unordered_map<Index, std::vector<Index>> stars;
  auto star_of = [&](Index n) -> std::vector<Index>& {
    auto it = stars.find(n);
    if (it == stars.end()) {
      const std::span<const Index> s = node_star(mesh, n);
      it = stars.emplace(n, std::vector<Index>(s.begin(), s.end())).first;
    }
    return it->second;
  };

  std::vector<std::array<Index, 2>> created;
  std::vector<int> label;
  std::vector<Index> queue;
  for (const Index f : facets) {
    const std::array<Index, 6> nodes =
        face_nodes(mesh, topo.facet_elem[f][0], topo.facet_face[f][0]);
    for (int j = 0; j < face_node_count(mesh); ++j) {
      const Index n = nodes[j];
      const std::vector<Index> star = star_of(n);
      const Index m = static_cast<Index>(star.size());
      // Components of the star through intact facets that contain n.
      auto position = [&](Index e) {
        return static_cast<Index>(std::lower_bound(star.begin(), star.end(), e) - star.begin());
      };
      label.assign(m, -1);
      int num_components = 0;
      for (Index s0 = 0; s0 < m; ++s0) {
        if (label[s0] >= 0) continue;
        label[s0] = num_components;
        queue.assign(1, s0);
        while (!queue.empty()) {
          const Index s = queue.back();
          queue.pop_back();
          const Index e = star[s];
          for (int i = 0; i < 4; ++i) {
            const Index g = topo.elem_facet[static_cast<size_t>(e) * 4 + i];
            if (topo.facet_state[g] != FacetState::intact || !face_contains(mesh, e, i, n))
              continue;
            const Index other =
                topo.facet_elem[g][0] == e ? topo.facet_elem[g][1] : topo.facet_elem[g][0];
            const Index t = position(other);
            SHATTER_ASSERT(t < m && star[t] == other);
            if (label[t] < 0) {
              label[t] = num_components;
              queue.push_back(t);
            }
          }
        }
        ++num_components;
      }
      if (num_components == 1) continue;

      // Components are numbered by their first (smallest local id) element;
      // order them by smallest global element id instead, which is rank-independent.
      std::vector<std::vector<Index>> comps(num_components);
      std::vector<GlobalId> comp_min(num_components, std::numeric_limits<GlobalId>::max());
      std::vector<Index> comp_min_elem(num_components, -1);
      for (Index s = 0; s < m; ++s) {
        comps[label[s]].push_back(star[s]);
        if (mesh.elem_gid[star[s]] < comp_min[label[s]]) {
          comp_min[label[s]] = mesh.elem_gid[star[s]];
          comp_min_elem[label[s]] = star[s];
        }
      }
      std::vector<int> order(num_components);
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(),
                [&](int a, int b) { return comp_min[a] < comp_min[b]; });

      stars[n] = comps[order[0]];
      for (int c = 1; c < num_components; ++c) {
        const int comp = order[c];
        const Index copy = mesh.num_nodes();
        const Vec3 X = mesh.reference[n];
        mesh.reference.push_back(X);
        mesh.node_body.push_back(mesh.node_body[n]);
        mesh.node_gid.push_back(topo.split_gid_base + 10 * comp_min[comp] +
                                local_index(mesh, comp_min_elem[comp], n) + 1);
        for (const Index e : comps[comp])
          mesh.conn[static_cast<size_t>(e) * k + local_index(mesh, e, n)] = copy;
        stars[copy] = comps[comp];
        created.push_back({copy, n});
      }
    }
  }
  if (!created.empty()) {
    // The new nodes in the order of their names, as every rank holding some
    // of them orders them (whatever else it splits).
    const Index first = created.front()[0], count = mesh.num_nodes() - first;
    std::vector<Index> order(count), new_id(count);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](Index a, Index b) { return mesh.node_gid[first + a] < mesh.node_gid[first + b]; });
    for (Index i = 0; i < count; ++i) new_id[order[i]] = first + i;
    auto permute = [&](auto& v) {
      const auto old = v;
      for (Index i = 0; i < count; ++i) v[first + i] = old[first + order[i]];
    };
    permute(mesh.reference);
    permute(mesh.node_body);
    permute(mesh.node_gid);
    auto renamed = [&](Index n) { return n >= first ? new_id[n - first] : n; };
    for (Index& n : mesh.conn) n = renamed(n);
    for (auto& [copy, parent] : created) copy = renamed(copy), parent = renamed(parent);
    mesh.build_node_elements();
    ++mesh.revision;
  }
  return created;
}

std::vector<std::array<Index, 2>> surface_faces(const Mesh& mesh, const Topology& topo) {
  std::vector<std::array<Index, 2>> out;
  for (Index e = 0; e < mesh.num_elements(); ++e)
    for (int i = 0; i < 4; ++i)
      if (topo.facet_state[topo.elem_facet[static_cast<size_t>(e) * 4 + i]] != FacetState::intact)
        out.push_back({e, i});
  return out;
}

}  // namespace shatter
