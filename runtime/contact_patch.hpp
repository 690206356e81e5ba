#pragma once
// A rank's share of the contact surface on several MPI ranks (docs/parallel.md
// "Contact across ranks"): the triangles and edges it owns (a partition of the
// surface primitives, ContactPartition), the ghost primitives whose boxes reach
// into the box of its own, and three plans that bring the states of nodes
// from their volume owners, point to point: the owned primitives' (their
// boxes start a search), the whole patch's (the search) and, every step
// between searches, the nodes of this rank's candidate pairs and the
// triangles around them only. The search and DCR run on the
// patch only; no surface state goes to every rank.
//
// The surface's topology (triangles, edges, the vertex -> triangle lists) is
// still held on every rank: memory that grows with the surface, no traffic.
// Between ranks, nodes are named by their whole-model ids and edges by their
// two nodes' (docs/parallel.md "Patches with their own topology", step 1),
// never by positions in the replicated surface.
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <vector>

#include "contact/candidates.hpp"
#include "contact/dcr.hpp"
#include "contact/surface.hpp"

namespace shatter {

class Decomposition;
class Halo;
struct Model;

/// Swept boxes of a surface's primitives from x_old to x_new (swept_boxes), each grown by
/// 1.01 margin on every side: the boxes of a search whose candidates serve while every node
/// stays within margin (ContactStage, "Candidate reuse"); then, with `reach` (per node: a
/// shell node's half-thickness, else 0), by the reach of the primitive's first node (a
/// shell's primitives are thick: docs/shells.md "Contact").
SweptBoxes inflated_boxes(const ContactSurface& surface, std::span<const Vec3> x_old, std::span<const Vec3> x_new,
                          double margin, std::span<const double> reach = {});

/// Which nodes' states ContactPatch::exchange brings: the owned primitives' (own()), the
/// patch's (reach()) or the candidates' (activate()).
enum class PatchPlan { Owned, Patch, Active };

class ContactPatch {
 public:
  /// surface, around: the contact surface and its vertex -> triangle lists, held by the
  /// caller for the patch's lifetime (a new surface needs a new patch); model: names the
  /// nodes (whole ids); num_nodes: the length of the nodal arrays.
  ContactPatch(const Decomposition& dec, const ContactSurface& surface, const VertexTriangles& around,
               const Model& model, Index num_nodes);
  ~ContactPatch();
  ContactPatch(const ContactPatch&) = delete;
  ContactPatch& operator=(const ContactPatch&) = delete;

  /// A new ownership: the primitives this rank owns, ascending (triangle t as t, edge e as
  /// the number of triangles + e); no rank learns the others'. Plans the states of the owned
  /// primitives' nodes (PatchPlan::Owned; collective).
  void own(std::span<const Index> primitives);
  bool owned_any() const { return owned_once_; }
  /// Whether this rank owns primitive q (numbered as in own()).
  bool owns(Index q) const { return owned_mark_[q] != 0; }
  /// The triangles and edges owned here (surface indices, ascending) and their nodes.
  std::span<const Index> owned_triangles() const { return owned_triangles_; }
  std::span<const Index> owned_edges() const { return owned_edges_; }
  const ContactSurface& owned() const { return owned_; }

  /// The ghosts for a search over x_old -> x_new with reuse margin `margin` (the owned
  /// primitives' states must be here): every rank's reach box (the union of its owned
  /// primitives' inflated boxes) is gathered; the owner of each edge sends it to the ranks
  /// whose reach its inflated box overlaps, and the volume owner of each vertex likewise.
  /// The patch becomes the owned triangles, the owned and ghost edges and the vertices that
  /// reach here; their nodes are PatchPlan::Patch. Collective.
  /// `node_reach`: per node, its reach (inflated_boxes), empty without shells.
  void reach(std::span<const Vec3> x_old, std::span<const Vec3> x_new, double margin,
             std::span<const double> node_reach = {});
  /// PatchPlan::Active, until the next search: the nodes of `pairs` (this rank's candidates)
  /// and of the triangles around them, whose normals orient the pairs. Collective.
  void activate(std::span<const ContactPair> pairs);
  /// The surface the search runs on here (surface order, node ids of the mesh).
  const ContactSurface& patch() const { return patch_; }
  /// Per edge of patch(): 1 if owned here (find_owned_candidates keeps their pairs).
  std::span<const std::uint8_t> patch_edges_owned() const { return patch_edge_owned_; }
  /// The patch's inflated boxes for the search (inflated_boxes of patch(), with the owned
  /// primitives' from reach(); their states must be unchanged since, the rest here).
  SweptBoxes patch_boxes(std::span<const Vec3> x_old, std::span<const Vec3> x_new, double margin,
                         std::span<const double> node_reach = {}) const;
  /// The primitive (numbered as in own()) of a primitive of patch() (as in OwnedPairs).
  Index surface_primitive(Index patch_primitive) const;
  /// The triangles whose normals the active pairs read, ascending.
  std::span<const Index> normal_triangles() const { return normal_triangles_; }
  /// The surface vertices whose volume owner this rank is, ascending.
  std::span<const Index> home_vertices() const { return volume_vertices_.vertices; }

  /// The volume owners' x_old, x_new and v of the plan's nodes into the arrays; returns the
  /// bytes this rank sent. After the first exchange of an active plan, its x_old are not
  /// sent: a node active in the last step holds here its final x(n+1) of that step (from
  /// that exchange, or from DCR's settle when a pair moved it), which is this step's x(n).
  /// Point to point; collective in the plan's ranks. No-op before the plan is made.
  long exchange(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v, PatchPlan plan);

  /// The ranks this one exchanges with in DCR (patch_ranks.hpp), ascending: those it sends
  /// states to or receives states from in the last plan (the active one after a search), and
  /// those touching a surface node with it. Empty before the first search.
  std::span<const int> neighbors() const { return neighbors_; }
  /// The node held here whose whole id is `whole` (every surface node is held here).
  Index node(Index whole) const;
  /// For a surface node whose volume owner this rank is: the other ranks that read its
  /// state (their patches hold it, or they touch it), ascending.
  std::span<const int> readers(Index node) const;

 private:
  /// Plans the exchange of `nodes` (ascending mesh ids) from their owners; with `readers`,
  /// makes it the source of neighbors() and readers() (collective).
  std::unique_ptr<Halo> plan(const std::vector<Index>& nodes, bool readers);
  /// neighbors() and readers() from a plan's lists: the home nodes `send` gives to each rank,
  /// and the nodes `receive` takes from each.
  void find_readers(const std::map<int, std::vector<Index>>& send, const std::map<int, std::vector<Index>>& receive);
  Halo* halo(PatchPlan plan) const;
  /// Appends node n to `nodes` unless marked, and marks it.
  void add_node(Index n, std::vector<Index>& nodes);
  /// Clears the marks of `nodes` (from add_node) and sorts them.
  void sort_marked(std::vector<Index>& nodes);
  /// The surface index of the edge {a, b} (a < b, node ids here).
  Index edge(Index a, Index b) const;

  const Decomposition& dec_;
  const ContactSurface& surface_;
  const VertexTriangles& around_;
  const Model& model_;
  Index num_nodes_;
  std::vector<Index> edge_offsets_;  ///< surface_.edges from vertex k's on (CSR by first node)
  ContactSurface volume_vertices_;  ///< the surface vertices this rank's volume owns (vertices only)
  bool owned_once_ = false;
  std::vector<Index> owned_triangles_, owned_edges_;
  std::vector<std::uint8_t> owned_mark_;  ///< per primitive (numbered as in own()), 1 if owned
  ContactSurface owned_, patch_;
  SweptBoxes owned_boxes_;                  ///< inflated boxes of owned_ at the last reach()
  std::vector<Index> patch_edges_;          ///< per edge of patch_: its surface index
  std::vector<std::uint8_t> patch_edge_owned_;  ///< per edge of patch_: 1 if owned
  std::vector<Index> normal_triangles_;
  std::vector<std::uint8_t> triangle_mark_, node_mark_;  ///< scratch of reach() and activate(), 0 between calls
  std::unique_ptr<Halo> plans_[3];  ///< per PatchPlan
  bool active_fresh_ = false;       ///< the active plan has not been exchanged yet
  std::vector<int> touching_;   ///< the ranks touching a surface node with this one
  std::vector<int> neighbors_;  ///< touching_ and the plan's ranks
  std::vector<Index> reader_offsets_;  ///< CSR over volume_vertices_.vertices
  std::vector<int> readers_;
};

}  // namespace shatter
