#include "runtime/named_surface.hpp"

#include <algorithm>
#include <tuple>

#include "runtime/decomposition.hpp"
#include "runtime/model.hpp"

namespace shatter {

NamedSurface owned_surface(const Model& model, const Decomposition& dec, std::span<const MeshFace> skip) {
  const Mesh& mesh = model.mesh;
  // Every boundary triangle the part sees, owned or not: those of ghost elements name the
  // edges' smallest triangles too. Faces the part misclassifies (of outer ghosts, whose
  // neighbours it lacks) hold no node of an owned element, so they share no edge with an
  // owned triangle.
  struct Seen {
    std::array<Index, 2> edge;  ///< whole ids, ascending
    std::array<Index, 3> name;
    bool owned;
  };
  NamedSurface out;
  std::vector<Seen> seen;
  for (const auto& [e, f] : boundary_faces(mesh, skip)) {
    const Index* n = mesh.element(e);
    const bool owned = dec.owns_element(e);
    const auto subs = face_triangles(mesh.order, f);
    for (size_t s = 0; s < subs.size(); ++s) {
      const NamedTriangle t{{model.whole_element(e), f, static_cast<Index>(s)},
                            {model.whole_node(n[subs[s][0]]), model.whole_node(n[subs[s][1]]),
                             model.whole_node(n[subs[s][2]])},
                            mesh.elem_body[e]};
      if (owned) out.triangles.push_back(t);
      for (int c = 0; c < 3; ++c) {
        const Index a = t.nodes[c], b = t.nodes[(c + 1) % 3];
        seen.push_back({{std::min(a, b), std::max(a, b)}, t.name, owned});
      }
    }
  }
  // Local elements ascend in whole id, so the triangles come in name order already.
  std::sort(seen.begin(), seen.end(),
            [](const Seen& p, const Seen& q) { return std::tie(p.edge, p.name) < std::tie(q.edge, q.name); });
  for (size_t i = 0; i < seen.size(); ++i)
    if ((i == 0 || seen[i].edge != seen[i - 1].edge) && seen[i].owned) out.edges.push_back(seen[i].edge);
  return out;
}

}  // namespace shatter
