#pragma once
// One step of Loop subdivision of a shell's control mesh (Loop, "Smooth
// subdivision surfaces based on triangles", MS thesis, Utah, 1987): every
// triangle becomes four, and the new control mesh has the same limit
// surface in the interior. Used once before a run, it leaves at most one
// extraordinary corner per triangle (what the element of Cirak, Ortiz &
// Schroeder 2000 assumes), so that every interior triangle has a patch.
#include <string>

#include "mesh/shell_mesh.hpp"

namespace shatter {

/// A boundary vertex where the boundary turns by more than this (rad) is a corner.
inline constexpr double kCornerTurn = 1.0;

/// The control mesh after one Loop step. Vertex i keeps index i and moves by
/// the vertex rule, (1 - N beta) x + beta sum of its N neighbours,
/// beta = (5/8 - (3/8 + cos(2 pi / N) / 4)^2) / N; edge points follow,
/// numbered in order of first appearance in the triangles, at
/// 3/8 (a + b) + 1/8 (c + d) (c, d the vertices opposite the edge).
/// Boundary vertices and edges take the crease rules, 3/4 x + 1/8 of the
/// two boundary neighbours and the midpoint (the boundary curve becomes a
/// cubic B-spline of the boundary polygon), except at a corner of the
/// boundary, which turns by more than kCornerTurn there and stays put (Hoppe
/// et al., SIGGRAPH 1994): a rectangle keeps its corners. Triangle (a, b, c) becomes
/// 4t..4t+3 = (a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca), before
/// build_shell_mesh rotates the triangles with an extraordinary corner.
ShellMesh loop_subdivide(const ShellMesh& m, const std::string& where);

}  // namespace shatter
