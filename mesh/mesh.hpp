#pragma once
// Volume mesh storage: struct of arrays, indexed by local ids, with global
// ids beside them (DESIGN.md "Data layout").
#include <cstdint>
#include <string>
#include <vector>

#include "kernels/tet10.hpp"
#include "kernels/types.hpp"

namespace shatter {

/// A tetrahedral mesh of one or more bodies, all of one order.
///
/// Layouts (n = nodes, e = elements, k = nodes_per_element()):
///   reference[n]      reference coordinates X, m
///   node_gid[n]       global node id
///   node_body[n]      body index of the node
///   conn[e*k + a]     local node id of element node a (Gmsh node order)
///   elem_gid[e], elem_body[e], elem_material[e]
///   node_elem_offsets[n+1], node_elem[...]: CSR node -> elements (ascending)
struct Mesh {
  int order = 1;  ///< 1 = TET4, 2 = TET10
  /// Bumped by every change of topology (node splitting); outputs rewrite
  /// their mesh when it changes.
  std::uint64_t revision = 0;
  std::vector<Vec3> reference;
  std::vector<GlobalId> node_gid;
  std::vector<int> node_body;
  std::vector<Index> conn;
  std::vector<GlobalId> elem_gid;
  std::vector<int> elem_body;
  std::vector<int> elem_material;
  std::vector<Index> node_elem_offsets;
  std::vector<Index> node_elem;

  int nodes_per_element() const { return order == 1 ? 4 : 10; }
  Index num_nodes() const { return static_cast<Index>(reference.size()); }
  Index num_elements() const { return static_cast<Index>(elem_gid.size()); }
  const Index* element(Index e) const { return conn.data() + static_cast<size_t>(e) * nodes_per_element(); }

  /// Rebuild the node -> element CSR from conn.
  void build_node_elements();
};

/// Append mesh `b` to `a` (same order); node and element ids of `b` are
/// shifted, and its global ids (Gmsh tags) offset past the largest of `a`.
/// Validate each body's mesh before appending, so errors name the file's tags.
void append_mesh(Mesh& a, const Mesh& b);

/// The largest magnitude of a node coordinate, m (the Sun's radius is 7e8 m):
/// beyond it, or not finite, validate_mesh refuses the node, since the volume
/// test would overflow (1e200) or see NaN and call the element "of zero volume".
inline constexpr double kMaxCoordinate = 1e9;

/// Check a mesh for nodes of its elements with coordinates not finite or
/// beyond kMaxCoordinate, inverted or zero-volume elements, TET10s folded by their
/// curved edges (a scaled Jacobian <= 0 at a quadrature point,
/// tet10_min_scaled_jacobian) and unused nodes; throws InputError naming
/// `where` (file/key) and the first offending element or node.
void validate_mesh(const Mesh& mesh, const std::string& where);

/// The smallest scaled Jacobian of TET10 element e (tet10_min_scaled_jacobian).
Tet10ScaledJacobian element_min_scaled_jacobian(const Mesh& mesh, Index e);

/// The smallest scaled Jacobian over a TET10 mesh and the global id of its
/// element; value 1 and element -1 for a TET4 mesh (straight-sided).
struct MeshScaledJacobian {
  double value = 1;
  GlobalId element = -1;
};
MeshScaledJacobian min_scaled_jacobian(const Mesh& mesh);

/// Signed reference volume of element e (for TET10: integral of det(dX/dxi)).
double element_reference_volume(const Mesh& mesh, Index e);

}  // namespace shatter
