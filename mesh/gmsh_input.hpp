#pragma once
// Primitive shapes meshed through the Gmsh API with a target element size
// and order. Mesh files: mesh/mesh_file.hpp.
#include <string>
#include <vector>

#include "mesh/mesh.hpp"
#include "mesh/mesh_file.hpp"

namespace shatter {

/// A ball of local refinement: element size `element_size` within `radius`
/// of `center`, growing linearly outward to the body's size (mesh_shape).
/// Lengths in m.
struct RefineSpec {
  Vec3 center = Vec3::Zero();
  double radius = 0;
  double element_size = 0;
};

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
  std::vector<RefineSpec> refine;  ///< local refinements, each with element_size <= the body's
};

/// Growth of the element size with distance beyond a refinement ball, in m
/// of size per m of distance: a refinement of h in a body of size H grades
/// over (H - h) / kRefineGrading beyond its radius, so neighbouring elements
/// differ by a factor of about 1 + kRefineGrading.
inline constexpr double kRefineGrading = 0.3;

/// Mesh a primitive shape; all nodes and elements get `body` and `material`.
/// With `refine`, the target size at a point is the smallest of the body's
/// element_size and, for each refinement, h within r of its centre, rising
/// linearly to the body's size at r + (element_size - h) / kRefineGrading
/// (Gmsh Threshold fields on the distance to the centre).
Mesh mesh_shape(const ShapeSpec& spec, int body, int material, const std::string& where);

}  // namespace shatter
