#pragma once
// Facet adjacency of a tetrahedral mesh, kept consistent while cohesive
// elements are inserted and nodes are split (DESIGN.md step 5).
//
// A facet is a triangular face of the volume mesh (for TET10 a 6-node face).
// Facets never change when nodes are split: a facet keeps its two elements
// and their local faces; only its state changes (intact -> cohesive -> free).
// Node stars (elements around a node) are Mesh::node_elem.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/mesh.hpp"

namespace shatter {

/// Local faces of a tetrahedron in Gmsh node order, each oriented outward of
/// a positive-volume element: corners a, b, c, then for TET10 the mid-edge
/// nodes of edges (a,b), (b,c), (c,a). Face i is opposite corner i.
inline constexpr std::array<std::array<int, 6>, 4> kTetFaces = {{
    {1, 2, 3, 5, 8, 9},
    {0, 3, 2, 7, 8, 6},
    {0, 1, 3, 4, 9, 7},
    {0, 2, 1, 6, 5, 4},
}};

/// State of a facet.
///  intact:   the two elements are bonded (shared nodes, no cohesive element);
///  cohesive: a cohesive element bridges the two sides;
///  free:     a boundary face (one element) or a fully debonded crack face.
enum class FacetState : std::uint8_t { intact, cohesive, free };

/// Facets of a mesh. Layouts (f = facets, e = elements):
///   facet_elem[f]  = {element 0, element 1 or -1 on the boundary}; element 0
///                    has the smaller global id
///   facet_face[f]  = local face (kTetFaces row) in each element, -1 if none
///   facet_state[f]
///   facet_gid[f]   = 4 g + face, g the smallest global id of the adjacent
///                    elements and face its local face there: the same on
///                    every rank that holds both elements
///   elem_facet[4 e + i] = facet of local face i of element e
/// Facets are numbered in the order of their element 0 (local id), then its
/// local face: a walk over the facets reads the elements 0 in order (the
/// facet check, fracture/facet_criterion.cpp). Local facet ids mean nothing
/// across ranks; facet_gid does.
struct Topology {
  std::vector<std::array<Index, 2>> facet_elem;
  std::vector<std::array<std::int8_t, 2>> facet_face;
  std::vector<FacetState> facet_state;
  std::vector<GlobalId> facet_gid;
  std::vector<Index> elem_facet;
  // With MPI, a facet between a held element and one that is not held (the
  // outer faces of the ghost layer) looks like a boundary facet here; its id
  // is then not the global one. Only facets with both elements held (every
  // facet of an owned element) are meaningful across ranks.

  /// Names of nodes created by splitting start past this value: it must be at
  /// least the largest global node id of the whole (all-rank) input mesh.
  GlobalId split_gid_base = 0;

  Index num_facets() const { return static_cast<Index>(facet_elem.size()); }
  bool is_interior(Index f) const { return facet_elem[f][1] >= 0; }
};

/// Build the facets of `mesh` (all facets intact except boundary ones, which
/// are free). `split_gid_base` < 0 takes the largest local node global id;
/// with MPI pass the global maximum.
Topology build_topology(const Mesh& mesh, GlobalId split_gid_base = -1);

/// The `k` local node ids (3 for TET4, 6 for TET10) of local face `face` of
/// element e, in kTetFaces order (outward of e).
std::array<Index, 6> face_nodes(const Mesh& mesh, Index e, int face);

/// Elements around node n (ascending local ids).
inline std::span<const Index> node_star(const Mesh& mesh, Index n) {
  return {mesh.node_elem.data() + mesh.node_elem_offsets[n],
          static_cast<size_t>(mesh.node_elem_offsets[n + 1] - mesh.node_elem_offsets[n])};
}

/// Split the nodes around the facets that are no longer intact. For each node
/// of each facet in `facets` (in the given order, which the caller makes
/// canonical), the elements of its star are grouped into components connected
/// through intact facets that contain the node; the component holding the
/// element of smallest global id keeps the node, every other component gets a
/// copy (same reference position and body). A copy of the node at local
/// position a of element g (g the smallest global id of its new star) is
/// named split_gid_base + 10 g + a + 1: such a name is given at most once, and
/// every rank that holds the star derives the same name.
/// Updates conn, reference, node_gid, node_body and the node -> element CSR,
/// and bumps Mesh::revision when a node was created. The new nodes follow the
/// old ones in the order of their names, so that every rank holding some of
/// them numbers them in the same relative order.
/// Returns (new node, parent node) pairs in creation order; a parent may be a
/// node created earlier in the same call.
std::vector<std::array<Index, 2>> split_nodes(Mesh& mesh, const Topology& topo,
                                              std::span<const Index> facets);

/// Faces of the current surface: every face of every element whose facet is
/// not intact (boundary faces and both sides of crack facets), oriented
/// outward of its element, as (element, local face) pairs in element order.
std::vector<std::array<Index, 2>> surface_faces(const Mesh& mesh, const Topology& topo);

}  // namespace shatter
