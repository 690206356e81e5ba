#include "runtime/named_surface.hpp"

#include <algorithm>
#include <tuple>

#include "runtime/decomposition.hpp"
#include "runtime/model.hpp"

namespace shatter {

namespace {

/// A boundary triangle of the part's mesh, named, with its nodes in the part.
struct PartTriangle {
  NamedTriangle named;
  std::array<Index, 3> local;  ///< its nodes in the part
};

/// Every boundary triangle of the part's mesh, the bonded faces left out, in name order (local
/// elements ascend in whole id). Faces the part misclassifies (of outer ghosts, whose
/// neighbours it lacks) hold no node of an owned element. Their nodes' owners are right for
/// the triangles of the elements sharing a node with an owned one (the first ghost layer's
/// ranks are the start-up rank's, or whole stars with two layers), which are all that leave
/// here (-1: a node no rank touches).
std::vector<PartTriangle> part_boundary(const Model& model, const Decomposition& dec, const Bonded& bonded) {
  const Mesh& mesh = model.mesh;
  const auto owner = [&](Index n) { return dec.distributed() && dec.node_ranks(n).empty() ? -1 : dec.node_owner(n); };
  const auto twin = [&](Index n) { return bonded.twin.empty() ? model.whole_node(n) : bonded.twin[n]; };
  std::vector<PartTriangle> out;
  for (const auto& [e, f] : boundary_faces(mesh, bonded.faces)) {
    const Index* n = mesh.element(e);
    const auto subs = face_triangles(mesh.order, f);
    for (size_t s = 0; s < subs.size(); ++s) {
      const Index a = n[subs[s][0]], b = n[subs[s][1]], c = n[subs[s][2]];
      out.push_back({{{model.whole_element(e), f, static_cast<Index>(s)},
                      {model.whole_node(a), model.whole_node(b), model.whole_node(c)},
                      {owner(a), owner(b), owner(c)},
                      {twin(a), twin(b), twin(c)},
                      mesh.elem_body[e]},
                     {a, b, c}});
    }
  }
  return out;
}

}  // namespace

void append_words(const NamedTriangle& t, std::vector<Index>& out) {
  out.insert(out.end(), t.name.begin(), t.name.end());
  out.insert(out.end(), t.nodes.begin(), t.nodes.end());
  out.insert(out.end(), t.owner.begin(), t.owner.end());
  out.insert(out.end(), t.twin.begin(), t.twin.end());
  out.push_back(t.body);
}

void append_words(const NamedEdge& e, std::vector<Index>& out) {
  out.insert(out.end(), {e.nodes[0], e.nodes[1], e.owner[0], e.owner[1], e.twin[0], e.twin[1], e.body});
}

NamedTriangle read_triangle(const Index* w) {
  return {{w[0], w[1], w[2]}, {w[3], w[4], w[5]}, {w[6], w[7], w[8]}, {w[9], w[10], w[11]}, static_cast<int>(w[12])};
}

NamedEdge read_edge(const Index* w) {
  return {{w[0], w[1]}, {w[2], w[3]}, {w[4], w[5]}, static_cast<int>(w[6])};
}

NamedSurface owned_surface(const Model& model, const Decomposition& dec, const Bonded& bonded) {
  // The part's triangles, owned or not: those of ghost elements name the edges' smallest
  // triangles too; the misclassified ones share no edge with an owned triangle.
  struct Seen {
    NamedEdge edge;  ///< nodes ascending
    std::array<Index, 3> name;
    bool owned;
  };
  NamedSurface out;
  std::vector<Seen> seen;
  for (const auto& [t, local] : part_boundary(model, dec, bonded)) {
    const bool owned = dec.owns_element(model.local_element(t.name[0]));
    if (owned) out.triangles.push_back(t);
    for (int c = 0; c < 3; ++c) {
      const int a = c, b = (c + 1) % 3, lo = t.nodes[a] < t.nodes[b] ? a : b, hi = a + b - lo;
      seen.push_back(
          {{{t.nodes[lo], t.nodes[hi]}, {t.owner[lo], t.owner[hi]}, {t.twin[lo], t.twin[hi]}, t.body}, t.name, owned});
    }
  }
  std::sort(seen.begin(), seen.end(), [](const Seen& p, const Seen& q) {
    return std::tie(p.edge.nodes, p.name) < std::tie(q.edge.nodes, q.name);
  });
  for (size_t i = 0; i < seen.size(); ++i)
    if ((i == 0 || seen[i].edge.nodes != seen[i - 1].edge.nodes) && seen[i].owned) out.edges.push_back(seen[i].edge);
  return out;
}

std::vector<NamedTriangle> home_triangles(const Model& model, const Decomposition& dec, const Bonded& bonded) {
  // A node whose volume owner this rank is is touched here, so its star is held and the
  // faces through it are classified as in the whole mesh.
  const auto home = [&](Index n) {
    return !dec.distributed() || (!dec.node_ranks(n).empty() && dec.node_owner(n) == dec.rank());
  };
  std::vector<NamedTriangle> out;
  for (const auto& [t, local] : part_boundary(model, dec, bonded))
    if (home(local[0]) || home(local[1]) || home(local[2])) out.push_back(t);
  return out;
}

std::vector<Index> touched_surface_nodes(const Model& model, const Decomposition& dec, const Bonded& bonded) {
  // A touched node's star is held, so the faces through it are classified as in the whole mesh.
  std::vector<Index> out;
  for (const auto& [t, local] : part_boundary(model, dec, bonded))
    for (const Index n : local)
      if (!dec.distributed() || dec.touches(n, dec.rank())) out.push_back(n);
  std::sort(out.begin(), out.end(), [&](Index a, Index b) { return model.whole_node(a) < model.whole_node(b); });
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace shatter
