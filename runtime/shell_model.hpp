#pragma once
// The shell bodies of a model (docs/shells.md "The runtime"): each one's
// triangle control mesh, whose vertices are nodes of the model (after the
// solids' nodes, body after body), and its elements, one Loop patch per
// triangle (Cirak, Ortiz & Schroeder, IJNME 47 (2000) 2039-2072), grouped by
// the valence N of the patch's irregular corner (N = 6: regular patches and
// boundary patches completed by ghosts), with K = N + 6 control entries.
#include <array>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "kernels/error.hpp"
#include "kernels/neo_hookean.hpp"
#include "kernels/shell_kl.hpp"
#include "mesh/shell_mesh.hpp"
#include "runtime/scene.hpp"

namespace shatter {

/// Quadrature points per shell element (ShellQuadrature<3>: degree 2, the
/// rule the kernels' accuracy figures were measured with).
inline constexpr int kShellPoints = 3;
/// Shell control vertices per granule (docs/parallel.md "Shells on ranks"):
/// the unit of their ownership between MPI ranks and of their terms in
/// global sums, kShellGranule vertices of all shell bodies consecutive along
/// a Morton curve of their reference positions (runtime/decomposition.cpp).
inline constexpr Index kShellGranule = 32;
/// The valences of an extraordinary corner the runtime has element sets for.
inline constexpr int kShellMinValence = 3, kShellMaxValence = 12;

/// The Loop basis of a patch whose irregular corner has valence N, at the
/// kShellPoints quadrature points (regular for N = 6); tabulated once.
template <int N>
const std::array<SubdivisionBasis<N + 6>, kShellPoints>& shell_basis() {
  static const auto basis = [] {
    if constexpr (N == 6) return loop_regular_basis_at_quadrature<kShellPoints>();
    else return loop_extraordinary_basis_at_quadrature<N, kShellPoints>();
  }();
  return basis;
}

/// f(std::integral_constant<int, N>{}) for a valence N in [kShellMinValence, kShellMaxValence].
template <class F>
decltype(auto) with_valence(int n, F&& f) {
  switch (n) {
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 5: return f(std::integral_constant<int, 5>{});
    case 6: return f(std::integral_constant<int, 6>{});
    case 7: return f(std::integral_constant<int, 7>{});
    case 8: return f(std::integral_constant<int, 8>{});
    case 9: return f(std::integral_constant<int, 9>{});
    case 10: return f(std::integral_constant<int, 10>{});
    case 11: return f(std::integral_constant<int, 11>{});
    case 12: return f(std::integral_constant<int, 12>{});
  }
  SHATTER_REQUIRE(false, "with_valence: valence " << n << " outside [" << kShellMinValence << ", "
                                                  << kShellMaxValence << "]");
  return f(std::integral_constant<int, 6>{});
}

/// The patches of one shell body whose irregular corner has valence `valence`.
/// Force slots: entry a of patch p is slot first_slot + p * (valence + 6) + a.
struct ShellPatchSet {
  int valence = 6;
  std::vector<Index> triangle;  ///< per patch: its triangle in the body's control mesh
  std::vector<ShellReference<kShellPoints>> reference;  ///< per patch: reference constants
  Index first_slot = 0;
  int size() const { return valence + 6; }
};

/// One shell body. Layouts (v = control vertices):
///   vertex v is the model's node first_node + v;
///   sets: by ascending valence, only those with patches;
///   vertex_slot_offsets[v+1], vertex_slot[...], vertex_slot_weight[...]:
///     CSR per vertex: the force slots that add to its force, ascending, and
///     their weights (ShellMesh::scatter_entry: 1, or -1 for a ghost's mirror vertex).
struct ShellBody {
  int body = 0;          ///< index into Scene::bodies
  int material = 0;      ///< index into Model::materials
  double thickness = 0;  ///< m
  Index first_node = 0;
  ShellMesh mesh;
  std::vector<ShellPatchSet> sets;
  Index slots = 0;  ///< force slots of all sets
  std::vector<Index> vertex_slot_offsets, vertex_slot;
  std::vector<double> vertex_slot_weight;
  double area = 0;  ///< of the reference limit surface, m^2 (sum of the quadrature weights)
  /// The limit surface at the vertices (shell_limit_stencils): CSR per vertex
  /// v, the vertices u and weights W with limit point sum_u W x_u + a constant
  /// (even ghosts' offsets), so that the limit displacement and velocity are
  /// sum_u W u_u and sum_u W v_u; limit_reference[v]: the reference limit point, m.
  std::vector<Index> limit_offsets, limit_vertex;
  std::vector<double> limit_weight;
  std::vector<Vec3> limit_reference;
};

/// The shell body `body` of `scene`: its mid-surface meshed by Gmsh at twice
/// its element_size and refined by one Loop subdivision step (which leaves at
/// most one extraordinary corner per triangle: docs/shells.md), its patches
/// and their reference constants for `material`. InputError naming `where`
/// (file: bodies[i].mesh) when a triangle has no patch (the boundary corners
/// and unstructured boundaries that docs/shells.md lists as missing) or a
/// corner's valence is outside [kShellMinValence, kShellMaxValence].
ShellBody build_shell_body(const Scene& scene, int body, const std::string& where);

/// Fills the limit stencils of `shell` (ShellBody::limit_offsets ...): a
/// vertex that is a regular corner of a patch (a corner of valence 6, or a
/// non-extraordinary corner of an extraordinary patch) gets the patch's basis
/// at that corner, of its first triangle with one; an extraordinary vertex
/// in the interior Loop's limit mask (1 - N chi) x + chi sum of its ring,
/// chi = 1 / (N + 3 / (8 beta)) (Loop 1987; Hoppe et al., SIGGRAPH 1994).
void shell_limit_stencils(ShellBody& shell);

/// The limit point of control vertex v from patch entries: the basis of the
/// patch of triangle t at its corner c (0, 1, 2: triangles[t][c]), as
/// (patch entry, weight) pairs; empty when that corner is the extraordinary
/// one of the patch.
std::vector<std::pair<Index, double>> shell_corner_stencil(const ShellBody& shell, Index t, int c);

/// The model nodes each shell patch reads and adds forces to (its entries'
/// vertices, ghosts' included), every patch of every body in force-slot
/// order (body after body, set after set), `width` ids each, ascending,
/// padded with -1.
struct ShellPatchNodes {
  int width = 0;
  std::vector<Index> nodes;
  Index patches() const { return width == 0 ? 0 : static_cast<Index>(nodes.size()) / width; }
  std::span<const Index> of(Index p) const { return {nodes.data() + static_cast<std::size_t>(p) * width, static_cast<std::size_t>(width)}; }
};
ShellPatchNodes shell_patch_nodes(const std::vector<ShellBody>& shells);

/// Control vertices of all shell bodies (they are the model's nodes from
/// shells.front().first_node on, body after body).
Index shell_vertices(const std::vector<ShellBody>& shells);

/// About how many control triangles build_shell_body makes of a mid-surface:
/// its area over that of an equilateral triangle of edge element_size.
double estimated_shell_triangles(const ShellShapeSpec& shape);

/// The mid-surface as a ShapeSpec of its centre and reach, for check_shape_extent.
ShapeSpec shell_extent(const ShellShapeSpec& shape);

/// The lumped mass of each control vertex, rho t x the integral of its shape
/// function over the reference limit surface (ghosts' scattered), kg.
std::vector<double> shell_vertex_mass(const ShellBody& shell, const NeoHookean& material);

}  // namespace shatter
