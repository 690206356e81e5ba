#pragma once
// Triangle control mesh of a shell's mid-surface and the Loop patch of each
// triangle (Cirak, Ortiz & Schroeder, IJNME 47 (2000) 2039-2072):
// the control vertices whose shape functions are non-zero on the triangle,
// i.e. the triangle's corners and their 1-rings.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

/// What the patch of a triangle is.
///  regular:      three interior corners of valence 6; 12 control vertices in
///                kernels/loop_basis.hpp order (Stam's 1..12 as 0..11);
///  extraordinary: three interior corners, exactly one of valence N != 6;
///                N + 6 control vertices in the order of ShellMesh::patch
///                (kernels/loop_extraordinary.hpp evaluates it);
///  several_extraordinary: more than one corner of valence != 6 (one Loop
///                subdivision of the control mesh separates them); no patch;
///  boundary:     a corner on the boundary, the fans of the corners fit the
///                regular lattice and every missing lattice point of the
///                patch is next to a boundary edge: 12 control vertices in
///                Stam's order, some of them ghost vertices (ghost_rule);
///  unsupported_boundary: any other triangle with a corner on the boundary
///                (e.g. at a corner of the boundary, or an extraordinary
///                vertex next to it); no patch.
enum class ShellPatchKind : std::uint8_t {
  regular,
  extraordinary,
  several_extraordinary,
  boundary,
  unsupported_boundary
};

/// A triangle control mesh, consistently oriented.
///
/// Layouts (n = vertices, t = triangles):
///   reference[n]        reference position of the control vertex, m
///   triangles[t]        corner vertices, counter-clockwise about the normal;
///                       on a closed surface the normal points outward
///   valence[n]          number of edges at the vertex
///   on_boundary[n]      1 when the vertex is on a boundary edge
///   patch_kind[t]
///   patch_offsets[t+1], patch[...]: CSR triangle -> patch control vertices.
///     regular: Stam's order (kernels/loop_basis.hpp), corners 4, 7, 8 =
///       triangles[t][0], [1], [2].
///     extraordinary, the corner of valence N first: triangles[t] is rotated
///       so that it is corner 0, then
///       0: that corner p; 1..N: its ring counter-clockwise from the next
///       corner (1 = triangles[t][1], 2 = triangles[t][2], N = the vertex
///       across the edge p-[1]); N+1..N+5: Stam's vertices 6, 10, 11, 12, 9
///       (beyond corner [1], across the edge [1]-[2], beyond corner [2]).
///     boundary: as regular; an entry n + g (n = num_vertices()) is ghost g.
///   ghost_rule[g] = {b1, b2, a}: ghost vertex g sits at x_b1 + x_b2 - x_a
///     (ghost vertices as Cirak et al. (2000) use them at boundaries): the
///     reflection of a through the midpoint of a boundary edge (b1, b2), or
///     through a boundary vertex b1 = b2, whichever makes a the mirror image
///     of the ghost across the boundary in the reference configuration; its
///     force goes to b1 and b2 and, negated, to a, which keeps the sum of
///     forces and of their moments. With the boundary vertices held, the
///     edge is simply supported; free otherwise (docs/shells.md).
///   ghost_mode[g]: odd (the rule above) or even: the ghost moves with a,
///     x_g = x_a + (X_b1 + X_b2 - 2 X_a) with X the reference positions, its
///     force going to a alone. Even ghosts with the boundary vertices held
///     make a clamped edge (zero slope across it); they keep the sum of
///     forces but not of moments, as a clamp does not.
enum class GhostMode : std::uint8_t { odd, even };

struct ShellMesh {
  std::vector<Vec3> reference;
  std::vector<std::array<Index, 3>> triangles;
  std::vector<Index> valence;
  std::vector<std::uint8_t> on_boundary;
  std::vector<ShellPatchKind> patch_kind;
  std::vector<Index> patch_offsets;
  std::vector<Index> patch;
  std::vector<std::array<Index, 3>> ghost_rule;
  std::vector<GhostMode> ghost_mode;

  Index num_vertices() const { return static_cast<Index>(reference.size()); }
  Index num_triangles() const { return static_cast<Index>(triangles.size()); }
  const Index* patch_of(Index t) const { return patch.data() + patch_offsets[t]; }
  Index patch_size(Index t) const { return patch_offsets[t + 1] - patch_offsets[t]; }

  /// Position of patch entry `id` (a vertex, or ghost id - n) from the vertex positions x.
  Vec3 entry_position(std::span<const Vec3> x, Index id) const {
    if (id < num_vertices()) return x[id];
    const Index g = id - num_vertices();
    const auto& [b1, b2, a] = ghost_rule[g];
    if (ghost_mode[g] == GhostMode::even) return x[a] + (reference[b1] + reference[b2] - 2.0 * reference[a]);
    return x[b1] + x[b2] - x[a];
  }

  /// Call add(vertex, weight) for the vertices patch entry `id` stands for:
  /// its force (or lumped mass) v goes to each vertex as weight x v.
  template <class Add>
  void scatter_entry(Index id, Add&& add) const {
    if (id < num_vertices()) return add(id, 1.0);
    const Index g = id - num_vertices();
    const auto& [b1, b2, a] = ghost_rule[g];
    if (ghost_mode[g] == GhostMode::even) return add(a, 1.0);
    add(b1, 1.0);
    add(b2, 1.0);
    add(a, -1.0);
  }
};

/// Build the control mesh from vertex positions and triangles (any
/// orientation): the triangles are oriented consistently (by the first
/// triangle, and outward when the surface is closed), then valences,
/// boundary vertices and patches are found. InputError naming `where` for a
/// corner index out of range, a triangle with a repeated corner, an edge of
/// more than two triangles, a vertex whose triangles do not form one fan, a
/// non-orientable surface or an unused vertex.
ShellMesh build_shell_mesh(std::vector<Vec3> points, std::vector<std::array<Index, 3>> triangles,
                           const std::string& where);

}  // namespace shatter
