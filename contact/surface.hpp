#pragma once
// The contact surface: the triangles, edges and vertices that the contact
// search and DCR work on (DESIGN.md "The physics", step 2). Built once from
// the volume mesh, then extended by the crack faces that fracture opens.
#include <array>
#include <span>
#include <utility>
#include <vector>

#include "kernels/types.hpp"
#include "mesh/mesh.hpp"

namespace shatter {

/// Contact surface, struct of arrays. Node ids are the volume mesh's local
/// node ids, so positions are read from arrays indexed by mesh node.
///
/// Layouts (t = triangles, e = edges, v = vertices):
///   triangles[t] = {n0, n1, n2}   counter-clockwise seen from outside the body:
///                                 (x1 - x0) x (x2 - x0) is the outward normal
///   body[t]                       body id of the triangle (mesh.elem_body of its
///                                 tetrahedron; the caller may overwrite it with a
///                                 fragment id)
///   edges[e] = {a, b}, a < b      every edge of a triangle once, sorted ascending
///                                 lexicographically
///   vertices[v]                   every node of a triangle once, ascending
///
/// TET10: each 6-node boundary face is split into its 4 sub-triangles
/// (corner, mid, mid) x 3 and (mid, mid, mid), so every surface node, mid-edge
/// nodes included, is a contact vertex and the piecewise-flat surface
/// interpolates all surface nodes. The curved quadratic face is thus
/// approximated by 4 flat triangles; the contact constraint acts on nodes.
struct ContactSurface {
  std::vector<std::array<Index, 3>> triangles;
  std::vector<int> body;
  std::vector<std::array<Index, 2>> edges;
  std::vector<Index> vertices;  ///< ascending, distinct

  Index num_triangles() const { return static_cast<Index>(triangles.size()); }
  Index num_edges() const { return static_cast<Index>(edges.size()); }
  Index num_vertices() const { return static_cast<Index>(vertices.size()); }
  friend bool operator==(const ContactSurface&, const ContactSurface&) = default;
};

/// A triangle to add to a surface: nodes counter-clockwise seen from outside,
/// and its body (or fragment) id.
struct SurfaceTriangle {
  std::array<Index, 3> nodes;
  int body;
};

/// A face of a mesh: (element, local face). Local face f is outward face f: mesh elements
/// have positive volume in Gmsh node order, so the outward faces are (0,2,1), (0,1,3),
/// (0,3,2), (1,2,3).
using MeshFace = std::pair<Index, int>;

/// The faces that belong to exactly one tetrahedron, but those in `skip` (ascending),
/// ascending. Cost O(E log E).
std::vector<MeshFace> boundary_faces(const Mesh& mesh, std::span<const MeshFace> skip = {});

/// The local node triples of the triangles of outward face `face`, outward: one for TET4
/// (order 1); for TET10 (order 2) its 4 sub-triangles (corner, mid, mid) x 3, then
/// (mid, mid, mid).
std::span<const std::array<int, 3>> face_triangles(int order, int face);

/// Boundary of a tetrahedral mesh: the triangles of boundary_faces, listed by element, then
/// local face, then sub-triangle (face_triangles).
ContactSurface build_contact_surface(const Mesh& mesh);
/// The same without the boundary faces in `skip`: (element, local face), ascending.
ContactSurface build_contact_surface(const Mesh& mesh, std::span<const MeshFace> skip);

/// Append triangles (e.g. crack faces opened by fracture) and update the
/// vertex and edge lists incrementally: O((t + k) log k + e + v) for k new
/// triangles, no rebuild from the mesh. The result equals
/// make_contact_surface(old triangles followed by the new ones).
void add_triangles(ContactSurface& surface, std::span<const SurfaceTriangle> triangles);

/// A surface made of the given triangles, in the given order.
ContactSurface make_contact_surface(std::span<const SurfaceTriangle> triangles);

/// The triangles around each surface vertex, CSR over the positions in surface.vertices:
/// the triangles of vertices[k] are items[offsets[k] .. offsets[k + 1]), ascending;
/// position[n]: the k of mesh node n (-1 for a node off the surface; up to the largest vertex).
struct VertexTriangles {
  std::vector<Index> offsets, items;
  std::vector<Index> position;
};

/// The vertex -> triangle CSR of a surface, O(t + v + its largest vertex).
VertexTriangles vertex_triangles(const ContactSurface& surface);

/// The median length of the surface's edges at `x` (per node id), 0 without edges: the
/// contact search's length scale (ContactStage::margin).
double median_edge_length(const ContactSurface& surface, std::span<const Vec3> x);

/// Each triangle's (x1 - x0) x (x2 - x0) at x (m^2) and its length, in surface order:
/// computed once per configuration (oneTBB), so that surface_normal only adds them.
struct TriangleNormals {
  std::vector<Vec3> normal;
  std::vector<double> length;
};
TriangleNormals triangle_normals(const ContactSurface& surface, std::span<const Vec3> x);
/// The same for the listed triangles only (empty: all), into tn (sized for every triangle; the
/// others keep what they had), so that a rank computes the normals around its own pairs only.
void triangle_normals(const ContactSurface& surface, std::span<const Vec3> x, std::span<const Index> triangles,
                      TriangleNormals& tn);

/// Outward surface normal at a surface vertex `node` (m^2, not normalised): the sum of
/// (x1 - x0) x (x2 - x0) over the triangles {x0, x1, x2} around it (twice the area-weighted
/// mean of their unit normals), or, with `other` >= 0, over those that also hold `other`:
/// the normal of the edge node-other (its one or two triangles). Where the two sides of a
/// sheet meet they cancel: 0 when |sum| <= 1e-9 sum of |terms|. tn: triangle_normals at the
/// configuration wanted. DCR orients its pairs by them (kernels/dcr.hpp dcr_orientation).
Vec3 surface_normal(const ContactSurface& surface, const VertexTriangles& around, const TriangleNormals& tn,
                    Index node, Index other = -1);

/// The normal (x1 - x0) x (x2 - x0) (m^2, from tn) of the triangle in which the edge runs from
/// `from` to `to`, when the edge has exactly two triangles, one each way (a closed, oriented
/// surface); else 0. With the edge's surface_normal, the sum of both, it gives each triangle's
/// normal, the edge's exact normal cone (kernels/dcr.hpp dcr_in_edge_cone).
Vec3 edge_face_normal(const ContactSurface& surface, const VertexTriangles& around, const TriangleNormals& tn,
                      Index from, Index to);

}  // namespace shatter
