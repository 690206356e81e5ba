#pragma once
// Triangle control meshes of shell mid-surfaces, meshed through the Gmsh API.
#include <string>

#include "mesh/shell_mesh.hpp"

namespace shatter {

/// A mid-surface to mesh. Lengths in m; `where` names the scene key for errors.
struct ShellShapeSpec {
  std::string shape;             ///< sphere (its surface) | disk | rectangle | cylinder (its side)
  double radius = 0;             ///< sphere, disk, cylinder
  double length = 0;             ///< cylinder
  double width = 0, height = 0;  ///< rectangle edge lengths along x and y
  Vec3 center = Vec3::Zero();    ///< centre; disk and rectangle lie in the plane z = center.z
  Vec3 axis = Vec3(0, 0, 1);     ///< cylinder axis
  double element_size = 0;       ///< target edge length
};

/// Mesh a mid-surface with 3-node triangles and build its control mesh
/// (build_shell_mesh). InputError for an unknown shape.
ShellMesh mesh_shell_shape(const ShellShapeSpec& spec, const std::string& where);

}  // namespace shatter
