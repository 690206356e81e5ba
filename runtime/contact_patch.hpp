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
// The patch numbers its nodes itself and holds their states in arrays of its
// own (docs/parallel.md "Patches with their own topology", step 3): the search
// and DCR read the part's arrays only for the surface nodes of the part's
// elements. It knows only the vertices it has met (its primitives', ghosts' and
// rings', and the part's kept surface nodes), each with its whole id, volume
// owner and body, which come with the named primitives: no array of the patch is
// sized by the whole surface (step 2, the end). Between ranks, nodes are named by
// their whole-model ids and edges by their two nodes' (step 1).
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <unordered_map>
#include <vector>

#include "contact/candidates.hpp"
#include "contact/dcr.hpp"
#include "contact/surface.hpp"
#include "runtime/named_surface.hpp"

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

/// What a rank knows of the contact surface's vertices it holds (ContactStage holds it): per
/// vertex, ascending in whole id. On a part, the surface nodes it touches and the rigid
/// bodies' (which every part holds); on a whole model, every vertex.
struct SurfaceVertices {
  std::span<const Index> whole;  ///< its node's whole-model id
  std::vector<Index> node;       ///< its node in the part
  std::span<const int> owner;    ///< its volume owner
  std::span<const int> body;     ///< its node's body
  std::span<const Index> twin;   ///< its twin class (Bonded::twin); empty: every vertex its own
};

/// Which nodes' states ContactPatch::exchange brings: the owned primitives' (own()), the
/// patch's (reach()) or the candidates' (activate()).
enum class PatchPlan { Owned, Patch, Active };

class ContactPatch {
 public:
  /// vertices: the contact surface's vertices the part holds (a new surface needs a new
  /// patch); home: the surface's triangles around the vertices whose volume owner this rank is
  /// (home_triangles), in name order. model: the part (its nodes' whole ids, its bodies);
  /// num_nodes: the length of the part's nodal arrays; node_reach: per part node, its reach
  /// (inflated_boxes; empty without shells), held by the caller.
  ContactPatch(const Decomposition& dec, const SurfaceVertices& vertices, std::vector<NamedTriangle> home,
               const Model& model, Index num_nodes, std::span<const double> node_reach = {});
  ~ContactPatch();
  ContactPatch(const ContactPatch&) = delete;
  ContactPatch& operator=(const ContactPatch&) = delete;

  /// A new ownership: the triangles and edges this rank owns, named (triangles in name
  /// order, edges ascending); no rank learns the others'. Plans the states of the owned
  /// primitives' nodes (PatchPlan::Owned; collective).
  void own(const NamedSurface& primitives);
  bool owned_any() const { return owned_once_; }
  /// The owned triangles and edges, in own()'s order, in patch node ids. Owned primitive k is
  /// triangle k, or edge k - the number of triangles.
  const ContactSurface& owned() const { return owned_; }

  /// The ghosts for a search over x_old -> x_new (the part's arrays: its home vertices'
  /// states; the owned primitives' must be in the patch's) with reuse margin `margin`: every
  /// rank's reach box (the union of its owned primitives' inflated boxes) is gathered; the
  /// owner of each edge sends it to the ranks whose reach its inflated box overlaps, and the
  /// volume owner of each vertex likewise. The patch becomes the owned triangles, the owned
  /// and ghost edges and the vertices that reach here; their nodes are PatchPlan::Patch.
  /// Collective.
  void reach(std::span<const Vec3> x_old, std::span<const Vec3> x_new, double margin);
  /// PatchPlan::Active, until the next search: the nodes of `pairs` (this rank's candidates,
  /// patch node ids) and of the triangles whose normals orient the pairs (pair_normals: those
  /// around a vertex-face pair's vertex, those through an edge-edge pair's edges).
  /// Collective.
  void activate(std::span<const ContactPair> pairs);
  /// The surface the search runs on here (surface order, patch node ids).
  const ContactSurface& patch() const { return patch_; }
  /// Per edge of patch(): 1 if owned here (find_owned_candidates keeps their pairs).
  std::span<const std::uint8_t> patch_edges_owned() const { return patch_edge_owned_; }
  /// The patch's inflated boxes for the search (inflated_boxes of patch(), with the owned
  /// primitives' from reach(); their states must be unchanged since, the rest here).
  SweptBoxes patch_boxes(double margin) const;
  /// The owned primitive (numbered as in owned()) of a primitive of patch() (as in
  /// OwnedPairs), -1 for a ghost edge.
  Index owned_primitive(Index patch_primitive) const;
  /// The triangles whose normals the active pairs read (activate()), in name order (the
  /// one-rank surface's), and their vertices (no edges), with their vertex -> triangle lists
  /// (patch node ids): a vertex's list holds every triangle around it where a pair reads its
  /// normal at the vertex, and those through the edge where a pair reads it at an edge.
  const ContactSurface& normals() const { return normals_; }
  const VertexTriangles& normals_around() const { return normals_around_; }
  /// The surface vertices whose volume owner this rank is, ascending (part node ids).
  std::span<const Index> home_vertices() const { return volume_vertices_.vertices; }

  // The patch's nodes (docs/parallel.md "Patches with their own topology", step 3): the
  // nodes of its primitives and of the triangles around them, and the surface nodes whose
  // part rows the time loop keeps (those of the part's elements, and a rigid body's, which
  // every rank places), numbered in ascending whole id. Their states live in arrays of the
  // patch's own; the part's arrays are read and written for the kept nodes only.
  Index num_nodes() const { return static_cast<Index>(nodes_.size()); }
  /// Patch node k's node in the part (-1 if not held there).
  Index part_node(Index k) const { return known_[nodes_[k]].node; }
  /// The patch node whose whole id is `whole` (it must be one), and patch node k's whole id.
  Index node(Index whole) const;
  Index whole(Index k) const { return known_[nodes_[k]].whole; }
  /// The rank that owns patch node k (its volume owner), its body and its twin class (the
  /// whole id of the smallest node bonded facets join to it, its own if none).
  int owner(Index k) const { return known_[nodes_[k]].owner; }
  int body(Index k) const { return known_[nodes_[k]].body; }
  Index twin(Index k) const { return known_[nodes_[k]].twin; }
  /// The patch's states: x(n), x(n+1) and v(n+1/2) per patch node.
  std::span<Vec3> x_old() { return x_old_; }
  std::span<Vec3> x_new() { return x_new_; }
  std::span<Vec3> v() { return v_; }
  /// The number of vertices it knows (what its per-vertex arrays are sized by).
  Index known_vertices() const { return static_cast<Index>(known_.size()); }
  /// Per patch node: its reach (empty without shells).
  std::span<const double> node_reach() const { return reach_; }
  /// Per patch node: its inverse mass and held components (as a number: bit k = component
  /// k), from the part's arrays for the kept nodes (load()), else from the volume owner with
  /// the patch's plan (exchange()).
  std::span<const double> inv_mass() const { return inv_mass_; }
  std::span<const std::uint8_t> held() const { return held_; }
  /// A step's start: the part's states, inverse masses and held components (empty: none)
  /// of the kept nodes into the patch's; every other patch node's x(n) is its x(n+1) of the
  /// last step (the time loop's x(n)), which its exchange or DCR's settle brought. The
  /// arrays must stay until the step's exchanges are done. The states are the central
  /// difference's: x_new = x_old + dt * v (bit for bit, as the time loop's drift makes it)
  /// for every node but a rigid body's.
  void load(std::span<const Vec3> x_old, std::span<const Vec3> x_new, std::span<const Vec3> v,
            std::span<const double> inv_mass, std::span<const std::uint8_t> held, double dt);
  /// A step's end: the patch's states of the kept nodes back into the part's arrays.
  void store(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v) const;

  /// The volume owners' x_old, x_new and v of the plan's nodes (the part's arrays) into the
  /// patch's, and with the patch's plan their inverse masses and held components (load()'s
  /// arrays); returns the bytes this rank sent. The active plan brings less: its first
  /// exchange, right after the search (whose patch plan brought the pairs' nodes), the
  /// x_old and x_new of the nodes of the triangles around the pairs only (they orient the
  /// pairs at x_old); the later ones v only, x_new being x_old (load()) + dt * v, but for a
  /// rigid body's nodes. Point to point; collective in the plan's ranks. No-op before the
  /// plan is made.
  long exchange(std::span<const Vec3> x_old, std::span<const Vec3> x_new, std::span<const Vec3> v, PatchPlan plan);

  /// The ranks this one exchanges with in DCR (patch_ranks.hpp), ascending: those it sends
  /// states to or receives states from in the last plan (the active one after a search), and
  /// those touching a surface node with it. Empty before the first search.
  std::span<const int> neighbors() const { return neighbors_; }
  /// For a patch node whose volume owner this rank is: the other ranks that read its state
  /// (their patches hold it), ascending.
  std::span<const int> readers(Index k) const;

 private:
  /// A plan's lists: the home nodes sent to each rank (part node ids), the nodes received
  /// from each (known ids); per entry of each list, whether the node's velocity is read (1)
  /// or its positions only (0: the active plan's nodes of the triangles around the pairs).
  struct PlanLists {
    std::map<int, std::vector<Index>> send, receive;
    std::map<int, std::vector<std::uint8_t>> send_velocity, receive_velocity;
  };
  /// Plans the exchange of `nodes` (known ids) from their owners, with per node whether its
  /// velocity is read (empty: every node's); with `readers`, makes it the source of
  /// neighbors() and readers() (collective).
  PlanLists plan(const std::vector<Index>& nodes, bool readers, std::span<const std::uint8_t> velocity = {});
  /// The Halos of plan p's lists (lists_), received into the patch's numbering: plans_[p], and
  /// for the active plan fresh_ too.
  void make_halos(PatchPlan p);
  /// neighbors() and readers() from a plan's lists.
  void find_readers(const PlanLists& lists);
  /// The patch's nodes become `nodes` (known ids ascending in whole id; the kept ones among them):
  /// states kept for the nodes that stay, the primitives' ids and the plans renumbered.
  void renumber(std::vector<Index> nodes);
  /// Appends known vertex n to `nodes` unless marked, and marks it.
  void add_node(Index n, std::vector<Index>& nodes);
  /// Sorts known vertices by whole id.
  void sort_by_whole(std::vector<Index>& nodes) const;
  /// The known id of the vertex `whole`, which becomes known with its owner, body and twin
  /// class if new.
  Index know(Index whole, int owner, int body, Index twin);
  /// The part node of the surface vertex `whole` if the part holds it in vertices_, else -1.
  Index held(Index whole) const;
  /// The known id of the vertex `whole` (it must be known).
  Index known(Index whole) const;
  /// Forgets every vertex but the patch's nodes, and the rings (fetched again when needed).
  void forget();
  /// The rings (the triangles around them) of the listed known vertices that have none yet,
  /// from their volume owners (collective).
  void fetch_rings(std::span<const Index> vertices);
  /// The index in ring_ of triangle t, added if new.
  Index ring_triangle(const NamedTriangle& t);
  /// The ring of known vertex v (fetched).
  std::span<const Index> ring_of(Index v) const;

  const Decomposition& dec_;
  const SurfaceVertices& vertices_;
  const Model& model_;
  Index num_nodes_;
  std::span<const double> part_reach_;
  /// A vertex the patch knows (its known id: its place in known_): those of the patch's
  /// nodes, ghosts and rings, and the kept ones. Forgotten at a new ownership (forget()), so
  /// they stay a patch's worth.
  struct KnownVertex {
    Index whole;          ///< its whole id
    Index node;           ///< its node in the part, -1 if not held
    int owner, body;      ///< its volume owner, its body
    Index twin;           ///< its twin class (twin())
    Index position = -1;  ///< its patch node, -1 if none
    Index ring = -1;      ///< its ring (k: ring_offsets_[k]), -1 before it is fetched
    bool mark = false;    ///< scratch of reach(), false between calls
  };
  std::vector<KnownVertex> known_;
  std::unordered_map<Index, Index> known_at_;  ///< known id of a whole id
  ContactSurface volume_vertices_;  ///< the surface vertices this rank's volume owns (vertices only)
  std::vector<Index> volume_twin_;  ///< per volume vertex: its twin class
  std::vector<Index> kept_;   ///< the known vertices whose part rows the time loop keeps (load()), ascending whole ids
  bool owned_once_ = false;
  std::vector<std::uint64_t> owned_edge_keys_;  ///< owned_.edges as edge_key of whole ids (ascending)
  ContactSurface owned_, patch_;
  SweptBoxes owned_boxes_;                  ///< inflated boxes of owned_ at the last reach()
  std::vector<Index> patch_edge_owned_at_;      ///< per edge of patch_: its owned edge, -1 for a ghost
  std::vector<std::uint8_t> patch_edge_owned_;  ///< per edge of patch_: 1 if owned
  ContactSurface normals_;
  VertexTriangles normals_around_;
  // The rings (docs/parallel.md "Patches with their own topology", step 2): the triangles
  // around the patch's vertices, which orient its pairs, from the vertices' volume owners.
  std::vector<NamedTriangle> home_;           ///< around the vertices whose volume owner this rank is
  std::vector<std::pair<Index, Index>> home_at_;  ///< (whole node, home_ index), ascending
  ContactSurface ring_;                       ///< every triangle fetched, once (triangles and bodies; known ids)
  std::vector<std::int64_t> ring_keys_;  ///< per triangle of ring_: its name_key
  std::vector<std::uint8_t> ring_mark_;  ///< per triangle of ring_: scratch of activate(), 0 between calls
  std::map<std::int64_t, Index> ring_name_;  ///< ring_'s index of a triangle's name_key
  std::vector<Index> ring_offsets_{0}, ring_items_;  ///< the rings fetched, CSR: ring_ indices, name order
  PlanLists lists_[3];              ///< per PatchPlan
  std::unique_ptr<Halo> plans_[3];  ///< per PatchPlan: lists_ in the patch's numbering
  std::unique_ptr<Halo> fresh_;     ///< the active plan's first exchange, until it is made
  std::vector<Index> drifted_;      ///< the active plan's received nodes whose x_new is drifted here
  double dt_ = 0;                   ///< load()'s step
  std::vector<Index> nodes_;        ///< per patch node: its known id, ascending whole ids
  std::vector<Index> kept_at_;      ///< per kept_: its patch node
  std::vector<Vec3> x_old_, x_new_, v_;
  std::vector<double> inv_mass_;
  std::vector<std::uint8_t> held_;         ///< empty: no node held
  std::span<const double> part_inv_mass_;  ///< load()'s
  std::span<const std::uint8_t> part_held_;
  std::vector<Vec3> part_data_;  ///< per part node, filled for the patch plan's sends: inverse mass, held, 0
  std::vector<double> reach_;
  std::vector<int> touching_;   ///< the ranks touching a surface node with this one
  std::vector<int> neighbors_;  ///< touching_ and the plan's ranks
  std::vector<Index> reader_offsets_;  ///< CSR over volume_vertices_.vertices
  std::vector<int> readers_;
};

}  // namespace shatter
