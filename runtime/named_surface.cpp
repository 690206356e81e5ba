#include "runtime/named_surface.hpp"

#include <algorithm>
#include <tuple>

#include "runtime/decomposition.hpp"
#include "runtime/model.hpp"

namespace shatter {

namespace {

/// Every boundary triangle of the part's mesh, named, in name order (local elements ascend in
/// whole id). Faces the part misclassifies (of outer ghosts, whose
/// neighbours it lacks) hold no node of an owned element.
std::vector<NamedTriangle> part_boundary(const Model& model) {
  const Mesh& mesh = model.mesh;
  std::vector<NamedTriangle> out;
  for (const auto& [e, f] : boundary_faces(mesh)) {
    const Index* n = mesh.element(e);
    const auto subs = face_triangles(mesh.order, f);
    for (size_t s = 0; s < subs.size(); ++s)
      out.push_back({{model.whole_element(e), f, static_cast<Index>(s)},
                     {model.whole_node(n[subs[s][0]]), model.whole_node(n[subs[s][1]]), model.whole_node(n[subs[s][2]])},
                     mesh.elem_body[e]});
  }
  return out;
}

}  // namespace

void append_words(const NamedTriangle& t, std::vector<Index>& out) {
  out.insert(out.end(), t.name.begin(), t.name.end());
  out.insert(out.end(), t.nodes.begin(), t.nodes.end());
  out.push_back(t.body);
}

NamedTriangle read_words(const Index* w) {
  return {{w[0], w[1], w[2]}, {w[3], w[4], w[5]}, static_cast<int>(w[6])};
}

NamedSurface owned_surface(const Model& model, const Decomposition& dec) {
  // The part's triangles, owned or not: those of ghost elements name the edges' smallest
  // triangles too; the misclassified ones share no edge with an owned triangle.
  struct Seen {
    std::array<Index, 2> edge;  ///< whole ids, ascending
    std::array<Index, 3> name;
    bool owned;
  };
  NamedSurface out;
  std::vector<Seen> seen;
  for (const NamedTriangle& t : part_boundary(model)) {
    const bool owned = dec.owns_element(model.local_element(t.name[0]));
    if (owned) out.triangles.push_back(t);
    for (int c = 0; c < 3; ++c) {
      const Index a = t.nodes[c], b = t.nodes[(c + 1) % 3];
      seen.push_back({{std::min(a, b), std::max(a, b)}, t.name, owned});
    }
  }
  std::sort(seen.begin(), seen.end(),
            [](const Seen& p, const Seen& q) { return std::tie(p.edge, p.name) < std::tie(q.edge, q.name); });
  for (size_t i = 0; i < seen.size(); ++i)
    if ((i == 0 || seen[i].edge != seen[i - 1].edge) && seen[i].owned) out.edges.push_back(seen[i].edge);
  return out;
}

std::vector<NamedTriangle> home_triangles(const Model& model, const Decomposition& dec) {
  // A node whose volume owner this rank is is touched here, so its star is held and the
  // faces through it are classified as in the whole mesh.
  const auto home = [&](Index whole) {
    const Index n = model.local_node(whole);
    return n >= 0 && (!dec.distributed() || (!dec.node_ranks(n).empty() && dec.node_owner(n) == dec.rank()));
  };
  std::vector<NamedTriangle> out;
  for (const NamedTriangle& t : part_boundary(model))
    if (home(t.nodes[0]) || home(t.nodes[1]) || home(t.nodes[2])) out.push_back(t);
  return out;
}

}  // namespace shatter
