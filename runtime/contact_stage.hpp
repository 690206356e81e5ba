#pragma once
// Step 2 of the time loop (DESIGN.md): contact search over the step's motion
// and the DCR response, for scenes with a contact block. Owns the contact
// surface; fracture rebuilds it with the crack faces it opens.
//
// Candidate reuse (a Verlet list): the search runs on swept boxes inflated by
// a margin (1.01 delta; delta = contact.search_margin, default 0.1, times the
// median surface edge) and its candidates serve the following steps for as
// long as every surface node stays within delta (max norm) of where it was at
// that search, at the start and at the end of the step. A primitive's swept
// box over such a step then lies inside its inflated box of the search (the
// 1 % covers the relative growth kBoxInflation of a larger box), so filtering
// the list with the step's own box test (pair_boxes_overlap) gives exactly
// the pairs a fresh search would: DCR sees the same list, in the same order,
// whatever the reuse schedule (restarts stay bitwise).
//
// On several MPI ranks (docs/parallel.md "Contact across ranks") the surface
// primitives are partitioned by RCB (ContactPartition) and each rank holds a
// patch of the surface (ContactPatch): its own primitives, the ghosts whose
// boxes reach them, and the states of their nodes, which the volume owners
// send point to point each step. A pair belongs to the rank of its face
// (vertex-face) or first edge (edge-edge); each rank searches, detects and
// resolves its patch's pairs only, and the states of nodes that pairs on
// several ranks share pass between those ranks (PatchRanks): every node a pair
// moved ends with the one-rank bits on every rank that reads it.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "contact/candidates.hpp"
#include "contact/dcr.hpp"
#include "contact/surface.hpp"
#include "runtime/contact_patch.hpp"
#include "runtime/model.hpp"
#include "runtime/named_surface.hpp"

namespace shatter {

/// Where the contact stage spends its time and how much work it finds, summed
/// over the steps (summary.json, docs/scenes.md).
struct ContactProfile {
  double verlet_seconds = 0;    ///< checking that the candidates of the last search still serve
  double search_seconds = 0;    ///< the searches themselves
  double sweep_seconds = 0;     ///< DCR: box test and detection, coloring and resolution rounds
  long steps = 0, searches = 0;
  long candidates = 0;   ///< candidates of the search in force, summed over steps
  long owned_pairs = 0;  ///< this rank's candidates that passed the box test, summed over steps
  long detections = 0;   ///< pair detections run here, summed over steps
  long sweeps = 0;       ///< detection rounds, summed over steps
  // On several ranks:
  long exchange_bytes = 0;      ///< bytes this rank sent: state_bytes + found_bytes
  long state_bytes = 0;         ///< its nodes' states to the patches that hold them
  long found_bytes = 0;         ///< DCR's: its found pairs' links and the states passed on (PatchRanks)
  long states_posted = 0;       ///< node states passed to the rank of the node's next pair
  double exchange_seconds = 0;  ///< in those gathers (not in the times above)
  long repartitions = 0;        ///< RCB partitions computed
  long known_vertices_max = 0;  ///< the most surface vertices its patch knew at a search (ContactPatch::known_vertices)
  // Thread CPU time of the work itself (meaningful when ranks share cores):
  double search_cpu_seconds = 0;  ///< the searches' boxes, bucket search and filter
  double sweep_cpu_seconds = 0;   ///< DCR, less the gathers
};

/// A pair DCR left penetrating at the sweep cap, named for the diagnosis: its kind, its
/// nodes' ids (node_gid), bodies and positions x(n+1).
struct UnresolvedPair {
  ContactPair::Kind kind = ContactPair::VertexFace;
  std::array<GlobalId, 4> gid{};
  std::array<int, 4> body{};
  std::array<Vec3, 4> x{};
};

/// ContactProfile over the ranks (ContactStage::balance, summary.json).
struct ContactBalance {
  long pairs_min = 0, pairs_max = 0, pairs_sum = 0;  ///< ContactProfile::owned_pairs
  long candidates_sum = 0;
  long states_posted_sum = 0;  ///< ContactProfile::states_posted
  long state_bytes_max = 0, found_bytes_max = 0;
  double search_cpu_max = 0, sweep_cpu_max = 0;
  long whole_surface_bytes_max = 0;  ///< ContactStage::whole_surface_bytes
  long known_vertices_max = 0;       ///< ContactProfile::known_vertices_max
  long triangles = 0;                ///< the whole contact surface's triangles now
};

class Decomposition;
class ContactPartition;
class PatchRanks;

class ContactStage {
 public:
  /// dec: the ranks sharing the work (null or one rank: all pairs resolved here).
  ContactStage(const Model& model, const ContactSpec& spec, const Decomposition* dec = nullptr);
  ~ContactStage();

  /// Find the pairs penetrating during the motion x_old -> x_new and resolve
  /// them: x_new is projected back, v (the mid-step velocity) gets the DCR
  /// impulses. inv_mass: inverse lumped masses, 0 for nodes DCR must not move;
  /// held (empty: none): per node, bit k = component k held (resolve_contacts).
  /// On several ranks the arrays' owned entries are the state; the patch's other
  /// nodes are filled from their owners (at a search x_old, x_new and v; between
  /// searches v, and x_new = x_old + dt * v as the time loop's drift makes it, bit for
  /// bit, but for a rigid body's nodes, whose x_new comes too; x_old must then be what
  /// this rank held as x_new at the end of the last step, as the time loop's x(n) is),
  /// and every node a pair moved gets its final state on every rank that touches it or
  /// holds it in its patch.
  /// The result's contacts, dissipated, support_work and work are then this rank's part;
  /// when capped, unresolved is the first pair over all ranks, in whole-model node ids.
  /// rigid (null: none): the free rigid bodies (resolve_contacts); the result's rigid sums
  /// are this rank's part. When capped, unresolved() names the pair on every rank.
  DcrResult apply(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v,
                  std::span<const double> inv_mass, double dt, std::span<const std::uint8_t> held = {},
                  const DcrRigidBodies* rigid = nullptr);

  /// Rebuild the surface after fracture split nodes or freed facets: crack faces
  /// whose sides no longer share nodes join it, but those in `skip` ((element,
  /// local face), ascending: the bonded cohesive facets), and older triangles get
  /// the new node ids. The nodes of each pair in `twins` (those a bonded facet
  /// joins) count as one node: no pair is made of primitives that share one, as
  /// none is of primitives sharing a node.
  void rebuild(const Mesh& mesh, std::span<const std::pair<Index, int>> skip = {},
               std::span<const std::array<Index, 2>> twins = {});

  /// The contact surface: in the mesh's node ids on one rank; on several holding the whole
  /// model, in surface vertex ids (vertex k is the surface's k-th node, surface_nodes()[k]
  /// here); on a part, empty (each rank's patch holds its share).
  const ContactSurface& surface() const { return surface_; }
  /// The surface's nodes, ascending (mesh node ids; on a part, those it holds).
  std::span<const Index> surface_nodes() const { return dec_ ? vertices_.node : surface_.vertices; }
  /// The candidates of the search in force (on several ranks, this rank's).
  const ContactPairs& candidates() const { return pairs_; }
  /// This rank's pairs that DCR checked in the last apply(), in whole-model node ids: on one
  /// rank, equal to the pairs of a fresh search whose swept boxes overlap.
  ContactPairs active_pairs() const;
  /// The first pair left penetrating by the last apply() that reached the sweep cap (the
  /// same on every rank), else none.
  const std::optional<UnresolvedPair>& unresolved() const { return unresolved_; }
  /// Seconds spent in the search (the reuse check included) and in DCR (the step's box test,
  /// detection, coloring, resolution) so far; number of searches run.
  double search_seconds() const { return profile_.verlet_seconds + profile_.search_seconds; }
  double dcr_seconds() const { return profile_.sweep_seconds; }
  long searches() const { return profile_.searches; }
  const ContactProfile& profile() const { return profile_; }
  /// profile() over the ranks (collective).
  ContactBalance balance() const;
  /// The bytes of the contact arrays this rank holds that are sized by the whole contact
  /// surface (its topology, per-vertex tables and scratch; the part's own per-vertex tables
  /// are model bytes): on a part, the term that still grows with the whole model.
  long whole_surface_bytes() const;
  /// The reuse margin delta, m: contact.search_margin (default a tenth) times the
  /// median surface edge length.
  double margin() const { return margin_; }

 private:
  /// The surface (of `mesh`'s nodes; on a part, empty) and what depends on it: the search
  /// margin, the candidates, the RCB order.
  void set_surface(ContactSurface surface, const Mesh& mesh);
  /// On several ranks: vertices_ (on a part, the surface nodes it touches and the rigid
  /// bodies'), with the surface (of mesh node ids on a whole model) turned to surface vertex ids.
  void set_vertices(const Mesh& mesh);
  /// On a part, what fracture changed of its surface (the bonded faces and twins of rebuild()).
  Bonded bonded() const;
  bool candidates_valid(std::span<const Vec3> x_old, std::span<const Vec3> x_new) const;
  /// Whether the pair (mesh nodes on one rank, patch nodes on several) is left out: its
  /// primitives share a node, twins counted as one (rebuild), its bodies are not a pair of
  /// contact.pairs, they are one body and contact.self is false, or both are free rigid bodies.
  bool excluded(const ContactPair& p) const;
  /// Whether excluded() reads the pairs' bodies.
  bool by_body() const { return !body_pairs_.empty() || !self_ || any_free_rigid_ || !reach_.empty(); }
  void search(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v);
  /// DCR's screen (DcrScratch::drift): per node of `nodes` (empty: every one), how far (max
  /// norm) x_old and x_new are from x_gap, where the last search measured the pairs' gaps.
  void drifts(std::span<const Vec3> x_old, std::span<const Vec3> x_new, std::span<const Vec3> x_gap,
              std::span<const Index> nodes);
  /// On several ranks: the patch's search, with a new RCB partition when needed (the rule
  /// in contact_stage.cpp).
  void search_patch(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v);
  /// On several ranks: the first (canonical order) of every rank's `mine` (patch ids), in
  /// whole ids, named in unresolved_ (collective).
  std::optional<ContactPair> first_unresolved(const std::optional<ContactPair>& mine);
  /// Triangle t of a whole model's surface (on several ranks), named by its place: (t, 0, 0).
  NamedTriangle named_triangle(Index t) const;
  /// The primitives owned here before the first partition: on a part, those it names
  /// (owned_surface: a triangle by its element's owner, an edge by its smallest-named
  /// triangle's); on a whole model, each by the volume owner of its first node.
  NamedSurface first_owned() const;
  /// The surface's triangles around the vertices whose volume owner this rank is, named as in
  /// first_owned(): on a part from its mesh (home_triangles), on a whole model from the surface.
  std::vector<NamedTriangle> home_triangles() const;
  /// A new RCB partition of the owned primitives at the patch's x(n+1), weighted by their
  /// candidates; the primitives that leave go to their new ranks with their data (collective).
  void partition();
  /// The primitives owned here become `primitives` (owned_, the patch's, the weights).
  void own(NamedSurface primitives);
  /// The states of a plan's nodes from their owners (ContactPatch::exchange; timed and
  /// counted as exchange).
  void exchange(std::span<const Vec3> x_old, std::span<const Vec3> x_new, std::span<const Vec3> v, PatchPlan plan);
  /// A pair of patch nodes as whole-model nodes.
  ContactPair whole_pair(ContactPair p) const;
  /// Per patch node, its free rigid body (rigid.node_body's), from the part's rows.
  std::vector<std::int32_t> patch_rigid_bodies(const DcrRigidBodies& rigid) const;

  const Model& model_;
  ContactSurface surface_;
  VertexTriangles vertex_triangles_;  ///< of surface_, for the outward normals DCR orients pairs by
  SurfaceVertices vertices_;          ///< several ranks: the surface vertices held here
  /// On several ranks: the tables vertices_ views.
  struct {
    std::vector<Index> whole, twin;
    std::vector<int> owner, body;
  } whole_tables_;
  /// A part: the rigid bodies' surface nodes (part nodes), and what fracture changed of its
  /// surface (bonded()): the bonded faces, and per node its twin class's whole id (empty: none).
  std::vector<Index> rigid_nodes_;
  std::vector<MeshFace> bonded_faces_;
  std::vector<Index> twin_whole_;
  DcrOptions options_;
  double margin_fraction_ = 0.1;  ///< delta / median surface edge
  double margin_ = 0;
  bool have_candidates_ = false;
  ContactPairs pairs_;          ///< this rank's candidates of the last search (inflated boxes)
  std::vector<Index> twin_of_;  ///< one rank: per node, its twins' representative (the smallest node); empty: no twins
  std::vector<std::array<int, 2>> body_pairs_;  ///< contact.pairs (empty: all)
  bool self_ = true;                            ///< contact.self
  std::vector<char> free_rigid_;                ///< per body: bodies[i].rigid: free
  bool any_free_rigid_ = false;
  /// One rank: per node, its body (with contact.pairs or contact.self: false, or shells).
  std::vector<int> node_body_;
  std::vector<char> shell_body_;                ///< per body: a shell (never in contact with itself)
  std::vector<double> reach_;                   ///< per node: a shell node's half-thickness, m, else 0; empty: no shells (grows the search boxes: inflated_boxes)
  std::vector<Vec3> x_search_;  ///< x_new of the last search, per mesh node
  std::vector<Vec3> gap_x_;     ///< on several ranks, the patch's x_new at the last search (pair_gaps)
  DcrScratch scratch_;
  ContactProfile profile_;
  std::optional<UnresolvedPair> unresolved_;
  // Several ranks:
  const Decomposition* dec_ = nullptr;  ///< null on one rank
  std::unique_ptr<ContactPartition> partition_;
  std::unique_ptr<ContactPatch> patch_;  ///< of surface_
  std::unique_ptr<PatchRanks> ranks_;    ///< DCR's exchanges between the patches
  NamedSurface owned_;                   ///< the primitives owned here
  std::vector<float> weight_;            ///< per owned primitive (triangles, then edges): candidates at the last search
  bool repartition_ = true;              ///< partition at the next search
};

}  // namespace shatter
