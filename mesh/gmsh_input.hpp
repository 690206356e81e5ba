#pragma once
// Primitive shapes meshed through the Gmsh API with a target element size
// and order. Mesh files: mesh/mesh_file.hpp.
#include <string>
#include <vector>

#include "mesh/mesh.hpp"
#include "mesh/mesh_file.hpp"

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

}  // namespace shatter
