#pragma once
// Meshes through the Gmsh API: primitive shapes meshed with a target element
// size and order, and .msh files (formats 2.x and 4.1) read by Gmsh itself after our own scan
// of their element types.
#include <string>
#include <vector>

#include "mesh/mesh.hpp"
#include "mesh/msh_scan.hpp"

namespace shatter {

/// A primitive shape to mesh. Lengths in m. `where` names the scene key for errors.
struct ShapeSpec {
  std::string shape;               ///< box | cylinder | sphere | tube
  Vec3 size = Vec3::Zero();        ///< box edge lengths
  double radius = 0;               ///< cylinder, sphere
  double inner_radius = 0;         ///< tube; sphere: > 0 makes it hollow (sphere minus sphere)
  double outer_radius = 0;         ///< tube
  double length = 0;               ///< cylinder, tube
  Vec3 center = Vec3::Zero();      ///< centre of the shape
  Vec3 axis = Vec3(0, 0, 1);       ///< cylinder/tube axis
  double element_size = 0;         ///< target edge length
  /// box only: a box (centre, edge lengths) cut out of it, e.g. a saw-cut
  /// notch reaching a face; notch_size zero = none
  Vec3 notch_center = Vec3::Zero();
  Vec3 notch_size = Vec3::Zero();
  int order = 1;                   ///< 1 = TET4, 2 = TET10
};

/// Mesh a primitive shape; all nodes and elements get `body` and `material`.
Mesh mesh_shape(const ShapeSpec& spec, int body, int material, const std::string& where);

/// Read the tetrahedra of a Gmsh file (all of them, or those of the physical
/// volume named `physical` when it is not empty), as TET4 or TET10. The file
/// is scanned first (scan_msh_elements) and refused, before Gmsh reads it,
/// when it holds tetrahedra of more than one order.
Mesh read_msh(const std::string& path, const std::string& physical, int body, int material,
              const std::string& where);

}  // namespace shatter
