#include "fracture/fragments.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

#include "kernels/tet10.hpp"
#include "kernels/tet4.hpp"

namespace shatter {

Index find_root(std::vector<Index>& parent, Index a) {
  while (parent[a] != a) {
    parent[a] = parent[parent[a]];
    a = parent[a];
  }
  return a;
}

namespace {

double current_volume(const Mesh& mesh, std::span<const Vec3> x, Index e) {
  const Index* c = mesh.element(e);
  if (mesh.order == 1) return tet_signed_volume(x[c[0]], x[c[1]], x[c[2]], x[c[3]]);
  Tet10Nodes xe;
  for (int a = 0; a < 10; ++a) xe.col(a) = x[c[a]];
  return tet10_reference(xe).volume;
}

}  // namespace

Fragments label_fragments(const Mesh& mesh, const Topology& topo) {
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
  out.fragments = static_cast<Index>(roots.size());
  out.elem_fragment.resize(ne);
  for (Index e = 0; e < ne; ++e) out.elem_fragment[e] = root_id[find_root(parent, e)];
  return out;
}

std::vector<ExactSum> fragment_sums(const Mesh& mesh, const Fragments& frags, std::span<const Index> nodes,
                                    std::span<const Index> elements, std::span<const Vec3> x,
                                    std::span<const Vec3> v, std::span<const double> mass) {
  std::vector<ExactSum> sums(static_cast<size_t>(frags.count()) * kFragmentSums);
  for (const Index e : elements) {
    ExactSum* s = sums.data() + static_cast<size_t>(frags.elem_fragment[e]) * kFragmentSums;
    s[7] += current_volume(mesh, x, e);
    s[8] += 1.0;
  }
  for (const Index n : nodes) {
    if (mesh.node_elem_offsets[n + 1] == mesh.node_elem_offsets[n]) continue;
    ExactSum* s =
        sums.data() + static_cast<size_t>(frags.elem_fragment[mesh.node_elem[mesh.node_elem_offsets[n]]]) * kFragmentSums;
    s[0] += mass[n];
    for (int c = 0; c < 3; ++c) s[1 + c] += mass[n] * x[n][c], s[4 + c] += mass[n] * v[n][c];
  }
  return sums;
}

void set_fragment_stats(Fragments& frags, std::span<const ExactSum> sums) {
  frags.stats.assign(frags.count(), FragmentStats{});
  for (Index k = 0; k < frags.count(); ++k) {
    const ExactSum* s = sums.data() + static_cast<size_t>(k) * kFragmentSums;
    FragmentStats& st = frags.stats[k];
    st.mass = s[0].value();
    st.volume = s[7].value();
    st.elements = static_cast<Index>(s[8].value());
    if (st.mass > 0) {
      st.centre = Vec3(s[1].value(), s[2].value(), s[3].value()) / st.mass;
      st.velocity = Vec3(s[4].value(), s[5].value(), s[6].value()) / st.mass;
    }
  }
}

Fragments find_fragments(const Mesh& mesh, const Topology& topo, std::span<const Vec3> x,
                         std::span<const Vec3> v, std::span<const double> mass) {
  Fragments out = label_fragments(mesh, topo);
  std::vector<Index> nodes(mesh.num_nodes()), elements(mesh.num_elements());
  std::iota(nodes.begin(), nodes.end(), 0);
  std::iota(elements.begin(), elements.end(), 0);
  set_fragment_stats(out, fragment_sums(mesh, out, nodes, elements, x, v, mass));
  return out;
}

}  // namespace shatter
