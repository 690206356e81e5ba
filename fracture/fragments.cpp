#include "fracture/fragments.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

#include "kernels/tet10.hpp"
#include "kernels/tet4.hpp"

namespace shatter {

namespace {

Index find_root(std::vector<Index>& parent, Index a) {
  while (parent[a] != a) {
    parent[a] = parent[parent[a]];
    a = parent[a];
  }
  return a;
}

double current_volume(const Mesh& mesh, std::span<const Vec3> x, Index e) {
  const Index* c = mesh.element(e);
  if (mesh.order == 1) return tet_signed_volume(x[c[0]], x[c[1]], x[c[2]], x[c[3]]);
  Tet10Nodes xe;
  for (int a = 0; a < 10; ++a) xe.col(a) = x[c[a]];
  return tet10_reference(xe).volume;
}

}  // namespace

Fragments find_fragments(const Mesh& mesh, const Topology& topo, std::span<const Vec3> x,
                         std::span<const Vec3> v, std::span<const double> mass) {
  const Index ne = mesh.num_elements();
  std::vector<Index> parent(ne);
  std::iota(parent.begin(), parent.end(), 0);
  for (Index f = 0; f < topo.num_facets(); ++f) {
    if (topo.facet_state[f] == FacetState::free) continue;
    const Index a = find_root(parent, topo.facet_elem[f][0]);
    const Index b = find_root(parent, topo.facet_elem[f][1]);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  // Canonical numbering: by the smallest element global id of each component.
  std::vector<GlobalId> root_min(ne, std::numeric_limits<GlobalId>::max());
  for (Index e = 0; e < ne; ++e) {
    const Index r = find_root(parent, e);
    root_min[r] = std::min(root_min[r], mesh.elem_gid[e]);
  }
  std::vector<Index> roots;
  for (Index e = 0; e < ne; ++e)
    if (parent[e] == e) roots.push_back(e);
  std::sort(roots.begin(), roots.end(),
            [&](Index a, Index b) { return root_min[a] < root_min[b]; });
  std::vector<Index> root_id(ne, -1);
  for (size_t i = 0; i < roots.size(); ++i) root_id[roots[i]] = static_cast<Index>(i);

  Fragments out;
  out.elem_fragment.resize(ne);
  out.stats.resize(roots.size());
  for (Index e = 0; e < ne; ++e) {
    const Index id = root_id[find_root(parent, e)];
    out.elem_fragment[e] = id;
    out.stats[id].elements += 1;
    out.stats[id].volume += current_volume(mesh, x, e);
  }
  for (Index n = 0; n < mesh.num_nodes(); ++n) {
    if (mesh.node_elem_offsets[n + 1] == mesh.node_elem_offsets[n]) continue;
    FragmentStats& s = out.stats[out.elem_fragment[mesh.node_elem[mesh.node_elem_offsets[n]]]];
    s.mass += mass[n];
    s.centre += mass[n] * x[n];
    s.velocity += mass[n] * v[n];
  }
  for (FragmentStats& s : out.stats)
    if (s.mass > 0) {
      s.centre /= s.mass;
      s.velocity /= s.mass;
    }
  return out;
}

}  // namespace shatter
