#pragma once
// The contact surface listed where its faces are (docs/parallel.md "Patches with
// their own topology", step 2): each rank names the boundary triangles of its
// owned elements by (whole element, local face, sub-triangle), the one-rank
// surface's order, and lists the edges it owns first: those whose
// smallest-named triangle is one of its own. Over the ranks every triangle and
// every edge of the whole surface is listed once, and the triangles in name order
// are the one-rank surface's.
//
// Why a part decides alone: its first ghost layer holds every element sharing a
// node with an owned one, so the star of every node of an owned element is held.
// A face through such a node has its face neighbour in that star, so the part
// tells boundary faces from inner ones there as the whole mesh does; and every
// boundary triangle through an edge of an owned triangle is a face of an element
// in the star of the edge's nodes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "contact/surface.hpp"
#include "kernels/types.hpp"

namespace shatter {

class Decomposition;
struct Model;

/// A triangle of the contact surface named by where it comes from.
/// Its nodes' volume owners and twin classes travel with it, so a rank that holds no table of
/// the surface's vertices knows whom to ask for their states and which pairs to leave out
/// (ContactPatch, ContactStage::excluded).
struct NamedTriangle {
  std::array<Index, 3> name;   ///< whole element, local face (outward face), sub-triangle (face_triangles)
  std::array<Index, 3> nodes;  ///< whole node ids, counter-clockwise seen from outside
  std::array<int, 3> owner;    ///< per node: its volume owner (Decomposition::node_owner)
  std::array<Index, 3> twin;   ///< per node: its twin class (Bonded::twin; its own whole id if none)
  int body = 0;                ///< the element's body
  friend bool operator==(const NamedTriangle&, const NamedTriangle&) = default;
};

/// An edge of the contact surface: its nodes' whole ids, ascending, with their volume owners
/// and twin classes, and its body.
struct NamedEdge {
  std::array<Index, 2> nodes;
  std::array<int, 2> owner;
  std::array<Index, 2> twin;
  int body = 0;
  friend bool operator==(const NamedEdge&, const NamedEdge&) = default;
};

/// A triangle's name as one number of the same order (faces and sub-triangles are 0-3).
inline std::int64_t name_key(const std::array<Index, 3>& name) {
  return 16 * static_cast<std::int64_t>(name[0]) + 4 * name[1] + name[2];
}

/// A primitive in a message: kNamedTriangleWords numbers (name, nodes, owners, twins, body) or
/// kNamedEdgeWords (nodes, owners, twins, body), appended to `out` by append_words and read
/// back by read_triangle / read_edge from its first.
inline constexpr std::size_t kNamedTriangleWords = 13, kNamedEdgeWords = 7;
void append_words(const NamedTriangle& t, std::vector<Index>& out);
void append_words(const NamedEdge& e, std::vector<Index>& out);
NamedTriangle read_triangle(const Index* words);
NamedEdge read_edge(const Index* words);

/// A rank's share of the contact surface's primitives.
struct NamedSurface {
  std::vector<NamedTriangle> triangles;     ///< the owned elements' boundary triangles, ascending names
  std::vector<NamedEdge> edges;             ///< the edges owned first here, ascending nodes
};

/// What fracture changed of a mesh's surface (ContactStage::rebuild): the faces of the bonded
/// cohesive facets, left out ((element, local face), ascending), and per node of the mesh the
/// whole id of its twin class, the smallest of the nodes that bonded facets join to it
/// (empty: every node its own).
struct Bonded {
  std::span<const MeshFace> faces;
  std::span<const Index> twin;
};

/// This rank's share of the surface of the model's mesh (a part with its first ghost layer,
/// or a whole model), the bonded faces left out.
NamedSurface owned_surface(const Model& model, const Decomposition& dec, const Bonded& bonded = {});

/// The boundary triangles through the nodes whose volume owner this rank is
/// (Decomposition::node_owner), in name order: around each such node, every triangle of the
/// whole surface, those whose normals the surface normal there sums (surface_normal). The
/// owner holds the node's star, so it classifies the faces through the node as the whole
/// mesh does.
std::vector<NamedTriangle> home_triangles(const Model& model, const Decomposition& dec, const Bonded& bonded = {});

/// The surface's nodes this rank touches (Decomposition::node_ranks), as part nodes ascending
/// in whole id: the nodes of its owned elements' boundary triangles, the bonded faces left out.
std::vector<Index> touched_surface_nodes(const Model& model, const Decomposition& dec, const Bonded& bonded = {});

}  // namespace shatter
