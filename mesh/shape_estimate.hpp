#pragma once
// What a primitive shape will cost before Gmsh meshes it (issue 21): an
// element_size a million times smaller than the body made Gmsh grow until
// the machine ran out of memory, and a centre of 1e308 crashed it.
#include <string>

#include "mesh/gmsh_input.hpp"

namespace shatter {

/// The default limit on the estimated elements of a run (`--max-elements`).
inline constexpr double kDefaultMaxElements = 5e7;

/// Gmsh's tetrahedra per element_size^3 of volume: 4.5 on a 2.1 M-element
/// unit cube, 9.8 at 9 798 elements (boundary layers weigh more when coarse).
inline constexpr double kTetsPerCube = 5.0;

/// The shape's volume, m^3 (a notch is not taken off: an upper bound).
double shape_volume(const ShapeSpec& shape);

/// About how many elements Gmsh makes of the shape: kTetsPerCube V / h^3,
/// plus for each refinement its ball and graded shell at their sizes.
double estimated_elements(const ShapeSpec& shape);

/// Throws InputError naming `where` (e.g. "scene.yaml: bodies[0].mesh") when
/// the shape reaches beyond kMaxCoordinate from the origin (centre and
/// extent): Gmsh is not given it.
void check_shape_extent(const ShapeSpec& shape, const std::string& where);

}  // namespace shatter
