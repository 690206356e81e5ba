#include "runtime/shell_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "mesh/shell_gmsh.hpp"
#include "mesh/shell_subdivision.hpp"

namespace shatter {

namespace {

/// The reference constants of every patch of `set`.
template <int N>
void add_references(ShellBody& s, ShellPatchSet& set) {
  constexpr int K = N + 6;
  const auto& basis = shell_basis<N>();
  for (const Index t : set.triangle) {
    Eigen::Matrix<double, 3, K> X;
    for (int a = 0; a < K; ++a) X.col(a) = s.mesh.entry_position(s.mesh.reference, s.mesh.patch_of(t)[a]);
    set.reference.push_back(shell_reference<K, kShellPoints>(X, basis, s.thickness));
    for (const auto& r : set.reference.back()) s.area += r.area_weight;
  }
}

/// The CSR of force slots per vertex (ShellBody::vertex_slot_offsets).
void number_slots(ShellBody& s) {
  const Index nv = s.mesh.num_vertices();
  std::vector<std::vector<std::pair<Index, double>>> to(nv);
  for (ShellPatchSet& set : s.sets) {
    set.first_slot = s.slots;
    for (std::size_t p = 0; p < set.triangle.size(); ++p, s.slots += set.size())
      for (int a = 0; a < set.size(); ++a)
        s.mesh.scatter_entry(s.mesh.patch_of(set.triangle[p])[a],
                             [&](Index v, double w) { to[v].emplace_back(s.slots + a, w); });
  }
  s.vertex_slot_offsets.assign(nv + 1, 0);
  for (Index v = 0; v < nv; ++v) {
    s.vertex_slot_offsets[v + 1] = s.vertex_slot_offsets[v] + static_cast<Index>(to[v].size());
    for (const auto& [slot, w] : to[v]) s.vertex_slot.push_back(slot), s.vertex_slot_weight.push_back(w);
  }
}

}  // namespace

ShellBody build_shell_body(const Scene& scene, int body, const std::string& where) {
  const BodySpec& spec = scene.bodies[body];
  ShellBody s;
  s.body = body;
  s.material = spec.material;
  s.thickness = spec.shell->thickness;
  ShellShapeSpec coarse = spec.shell->shape;
  coarse.element_size *= 2;
  s.mesh = loop_subdivide(mesh_shell_shape(coarse, where), where);
  // Clamped boundary conditions: their boxes' control vertices (as
  // runtime/regions.cpp selects them) clamp the boundary edges between them.
  std::vector<std::uint8_t> clamped(s.mesh.num_vertices(), 0);
  bool any_clamped = false;
  for (const BoundaryConditionSpec& bc : scene.boundary_conditions)
    if (bc.body == body && bc.clamped)
      for (Index v = 0; v < s.mesh.num_vertices(); ++v)
        if (bc.region.box_holds(s.mesh.reference[v])) clamped[v] = 1, any_clamped = true;
  if (any_clamped) clamp_shell_edges(s.mesh, clamped);

  std::vector<std::vector<Index>> by_valence(kShellMaxValence + 1);
  Index missing = 0;
  for (Index t = 0; t < s.mesh.num_triangles(); ++t) {
    const ShellPatchKind kind = s.mesh.patch_kind[t];
    if (kind == ShellPatchKind::several_extraordinary || kind == ShellPatchKind::unsupported_boundary) {
      ++missing;
      continue;
    }
    const Index n = s.mesh.patch_size(t) - 6;
    if (n < kShellMinValence || n > kShellMaxValence) {
      std::ostringstream os;
      os << where << ": a vertex of the shell's control mesh has " << n << " edges; expected between "
         << kShellMinValence << " and " << kShellMaxValence << " (a finer or smoother mesh)";
      throw InputError(os.str());
    }
    by_valence[n].push_back(t);
  }
  if (missing > 0) {
    std::ostringstream os;
    os << where << ": " << missing << " of " << s.mesh.num_triangles()
       << " triangles of the shell's control mesh have no Loop patch (at its boundary: a boundary vertex's "
          "triangles do not fit the regular lattice, or the ghost vertices of the patches on either side of an edge "
          "disagree; docs/shells.md \"Ghost vertices\"); expected every triangle with its patch (another element_size "
          "may do)";
    throw InputError(os.str());
  }
  for (int n = kShellMinValence; n <= kShellMaxValence; ++n) {
    if (by_valence[n].empty()) continue;
    ShellPatchSet& set = s.sets.emplace_back();
    set.valence = n;
    set.triangle = std::move(by_valence[n]);
    with_valence(n, [&](auto N) { add_references<N()>(s, set); });
  }
  number_slots(s);
  shell_limit_stencils(s);
  return s;
}

ShellPatchNodes shell_patch_nodes(const std::vector<ShellBody>& shells) {
  std::vector<std::vector<Index>> lists;
  ShellPatchNodes out;
  for (const ShellBody& s : shells)
    for (const ShellPatchSet& set : s.sets)
      for (const Index t : set.triangle) {
        std::vector<Index>& l = lists.emplace_back();
        for (int a = 0; a < set.size(); ++a)
          s.mesh.scatter_entry(s.mesh.patch_of(t)[a], [&](Index v, double) { l.push_back(s.first_node + v); });
        std::sort(l.begin(), l.end());
        l.erase(std::unique(l.begin(), l.end()), l.end());
        out.width = std::max(out.width, static_cast<int>(l.size()));
      }
  out.nodes.assign(lists.size() * out.width, -1);
  for (std::size_t p = 0; p < lists.size(); ++p) std::copy(lists[p].begin(), lists[p].end(), out.nodes.begin() + p * out.width);
  return out;
}

Index shell_vertices(const std::vector<ShellBody>& shells) {
  Index n = 0;
  for (const ShellBody& s : shells) n += s.mesh.num_vertices();
  return n;
}

std::vector<std::pair<Index, double>> shell_corner_stencil(const ShellBody& s, Index t, int c) {
  constexpr double corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  const Index n = s.mesh.patch_size(t) - 6;
  std::vector<std::pair<Index, double>> out;
  if (n != 6 && c == 0) return out;  // the extraordinary corner: no regular sub-triangle holds it
  const Index* entries = s.mesh.patch_of(t);
  with_valence(static_cast<int>(n), [&](auto N) {
    Eigen::Matrix<double, N() + 6, 1> basis;
    if constexpr (N() == 6) basis = loop_regular_basis(corner[c][0], corner[c][1]).N;
    else basis = loop_extraordinary_basis<N()>(corner[c][0], corner[c][1]).N;
    for (int a = 0; a < N() + 6; ++a)
      if (basis[a] != 0) out.emplace_back(entries[a], basis[a]);
  });
  return out;
}

void shell_limit_stencils(ShellBody& s) {
  const Index nv = s.mesh.num_vertices();
  // Per vertex: a triangle and corner it is a regular corner of, or an extraordinary patch it is the corner of.
  std::vector<std::pair<Index, int>> regular(nv, {-1, -1});
  std::vector<Index> extraordinary(nv, -1);
  for (Index t = 0; t < s.mesh.num_triangles(); ++t)
    for (int c = 0; c < 3; ++c) {
      const Index v = s.mesh.triangles[t][c];
      if (s.mesh.patch_size(t) != 12 && c == 0) {
        if (extraordinary[v] < 0) extraordinary[v] = t;
      } else if (regular[v].first < 0) {
        regular[v] = {t, c};
      }
    }
  s.limit_offsets.assign(1, 0);
  s.limit_vertex.clear();
  s.limit_weight.clear();
  s.limit_reference.assign(nv, Vec3::Zero());
  std::vector<double> weight(nv, 0.0);
  std::vector<char> seen(nv, 0);
  std::vector<Index> touched;
  for (Index v = 0; v < nv; ++v) {
    std::vector<std::pair<Index, double>> stencil;
    if (regular[v].first >= 0) {
      stencil = shell_corner_stencil(s, regular[v].first, regular[v].second);
    } else {
      const Index t = extraordinary[v];
      const Index n = s.mesh.patch_size(t) - 6;
      const double c = 3.0 / 8 + 0.25 * std::cos(2 * std::numbers::pi / n);
      const double beta = (5.0 / 8 - c * c) / n, chi = 1.0 / (n + 3.0 / (8 * beta));
      stencil.emplace_back(s.mesh.patch_of(t)[0], 1 - n * chi);
      for (Index k = 1; k <= n; ++k) stencil.emplace_back(s.mesh.patch_of(t)[k], chi);
    }
    for (const auto& [entry, w] : stencil) {
      s.limit_reference[v] += w * s.mesh.entry_position(s.mesh.reference, entry);
      s.mesh.scatter_entry(entry, [&](Index u, double g) {
        if (!seen[u]) seen[u] = 1, touched.push_back(u);
        weight[u] += g * w;
      });
    }
    std::sort(touched.begin(), touched.end());
    for (const Index u : touched) {
      if (weight[u] != 0) s.limit_vertex.push_back(u), s.limit_weight.push_back(weight[u]);
      weight[u] = 0, seen[u] = 0;
    }
    touched.clear();
    s.limit_offsets.push_back(static_cast<Index>(s.limit_vertex.size()));
  }
}

double estimated_shell_triangles(const ShellShapeSpec& s) {
  const double pi = std::numbers::pi;
  const double area = s.shape == "sphere"      ? 4 * pi * s.radius * s.radius
                      : s.shape == "disk"      ? pi * s.radius * s.radius
                      : s.shape == "rectangle" ? s.width * s.height
                                               : 2 * pi * s.radius * s.length;
  return area / (std::sqrt(3.0) / 4 * s.element_size * s.element_size);
}

ShapeSpec shell_extent(const ShellShapeSpec& s) {
  ShapeSpec e;
  e.shape = s.shape;
  e.center = s.center;
  e.radius = s.shape == "rectangle" ? 0.5 * std::hypot(s.width, s.height) : s.radius;
  e.length = s.length;
  return e;
}

std::vector<double> shell_vertex_mass(const ShellBody& s, const NeoHookean& material) {
  std::vector<double> mass(s.mesh.num_vertices(), 0.0);
  for (const ShellPatchSet& set : s.sets)
    with_valence(set.valence, [&](auto N) {
      constexpr int K = N() + 6;
      for (std::size_t p = 0; p < set.triangle.size(); ++p) {
        const auto m = shell_lumped_mass<K, kShellPoints>(shell_basis<N()>(), set.reference[p], s.thickness,
                                                          material.density);
        for (int a = 0; a < K; ++a)
          s.mesh.scatter_entry(s.mesh.patch_of(set.triangle[p])[a], [&](Index v, double w) { mass[v] += w * m[a]; });
      }
    });
  return mass;
}

}  // namespace shatter
