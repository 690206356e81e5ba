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
///                patch is the mirror image of a lattice point across the
///                boundary (or, at a corner of the boundary, across both of
///                its edges): 12 control vertices in Stam's order, some of
///                them ghost vertices (GhostReflection);
///  unsupported_boundary: any other triangle with a corner on the boundary
///                (the fans do not fit the lattice, as on unstructured
///                boundaries, or an extraordinary vertex next to it); no patch.
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
///   ghost g (0 <= g < num_ghosts()): a lattice point of a boundary patch
///     outside the surface (Cirak et al. (2000) use such ghost vertices at
///     boundaries), built as ghost_reflection[g] (below) and evaluated as
///     x_g = ghost_shift[g] + sum_k ghost_weight[k] x[ghost_vertex[k]], k in
///     [ghost_offsets[g], ghost_offsets[g+1]) (CSR over vertices, ascending).
///     Its force (or lumped mass) goes to those vertices with those weights.
///     ghost_reference[g]: its reference position X_g, m; ghost_even[g]: 1 when
///     its reflection is even (set by clamp_shell_edges).

/// How ghost vertex g is made (docs/shells.md "Ghost vertices"): the mirror
/// image of patch entry `mirror` (a vertex, or n + an earlier ghost) across
/// the boundary edge (edge[0], edge[1]), through `foot`, a point on the
/// boundary given as patch entries and weights summing to 1.
///   odd (default):  x_g = 2 x_foot - x_mirror, a linear extrapolation of the
///     control net across the boundary; with the boundary vertices held,
///     w_g = -w_mirror: zero moment at the edge (simply supported);
///   even (the edge clamped): x_g = x_mirror + (X_g - X_mirror): the ghost
///     moves with its mirror image, zero slope across the edge.
/// At a corner of the boundary a ghost is the reflection of a ghost across
/// the other edge (foot and mirror ghosts themselves): both reflections
/// composed, so w is even about the corner of a simply supported plate.
struct GhostReflection {
  std::array<Index, 2> edge;
  std::vector<std::pair<Index, double>> foot;
  Index mirror = 0;
};

struct ShellMesh {
  std::vector<Vec3> reference;
  std::vector<std::array<Index, 3>> triangles;
  std::vector<Index> valence;
  std::vector<std::uint8_t> on_boundary;
  std::vector<ShellPatchKind> patch_kind;
  std::vector<Index> patch_offsets;
  std::vector<Index> patch;
  std::vector<GhostReflection> ghost_reflection;
  std::vector<Vec3> ghost_reference;
  std::vector<std::uint8_t> ghost_even;
  std::vector<Index> ghost_offsets{0}, ghost_vertex;
  std::vector<double> ghost_weight;
  std::vector<Vec3> ghost_shift;

  Index num_vertices() const { return static_cast<Index>(reference.size()); }
  Index num_triangles() const { return static_cast<Index>(triangles.size()); }
  Index num_ghosts() const { return static_cast<Index>(ghost_reference.size()); }
  const Index* patch_of(Index t) const { return patch.data() + patch_offsets[t]; }
  Index patch_size(Index t) const { return patch_offsets[t + 1] - patch_offsets[t]; }

  /// Position of patch entry `id` (a vertex, or ghost id - n) from the vertex positions x.
  Vec3 entry_position(std::span<const Vec3> x, Index id) const {
    if (id < num_vertices()) return x[id];
    const Index g = id - num_vertices();
    Vec3 p = ghost_shift[g];
    for (Index k = ghost_offsets[g]; k < ghost_offsets[g + 1]; ++k) p += ghost_weight[k] * x[ghost_vertex[k]];
    return p;
  }

  /// Call add(vertex, weight) for the vertices patch entry `id` stands for:
  /// its force (or lumped mass) v goes to each vertex as weight x v.
  template <class Add>
  void scatter_entry(Index id, Add&& add) const {
    if (id < num_vertices()) return add(id, 1.0);
    const Index g = id - num_vertices();
    for (Index k = ghost_offsets[g]; k < ghost_offsets[g + 1]; ++k) add(ghost_vertex[k], ghost_weight[k]);
  }
};

/// Build the control mesh from vertex positions and triangles (any
/// orientation): the triangles are oriented consistently (by the first
/// triangle, and outward when the surface is closed), then valences,
/// boundary vertices and patches are found (boundary patches whose ghosts
/// disagree with a neighbour's across an edge are dropped to
/// unsupported_boundary: docs/shells.md "Ghost vertices"). InputError naming `where` for a
/// corner index out of range, a triangle with a repeated corner, an edge of
/// more than two triangles, a vertex whose triangles do not form one fan, a
/// non-orientable surface or an unused vertex.
ShellMesh build_shell_mesh(std::vector<Vec3> points, std::vector<std::array<Index, 3>> triangles,
                           const std::string& where);

/// Clamp the boundary edges whose two vertices have clamped[v] != 0: the
/// ghosts reflected across them become even (GhostReflection), all others
/// odd; the ghosts' weights are recomputed. With those vertices held, the
/// edges are clamped (docs/shells.md). Even ghosts keep the sum of forces
/// but not of moments, as a clamp does not.
void clamp_shell_edges(ShellMesh& m, const std::vector<std::uint8_t>& clamped);

}  // namespace shatter
