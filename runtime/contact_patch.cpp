#include "runtime/contact_patch.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>

#include "contact/radix_sort.hpp"
#include "kernels/drift.hpp"
#include "kernels/error.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/halo.hpp"
#include "runtime/model.hpp"
#include "runtime/sort_unique.hpp"

namespace shatter {

namespace {

/// Appends the nodes of the listed primitives to `nodes` (with repeats).
template <size_t K>
void add_nodes(std::span<const std::array<Index, K>> primitives, std::vector<Index>& nodes) {
  for (const auto& p : primitives) nodes.insert(nodes.end(), p.begin(), p.end());
}

/// Edge {a, b} (whole ids) as one number whose order is that of (a, b).
std::uint64_t edge_key(Index a, Index b) {
  return static_cast<std::uint64_t>(a) << 32 | static_cast<std::uint32_t>(b);
}

/// `items` in the ascending order of key(item) (a std::uint64_t; equal keys keep their
/// order): a radix sort (the comparison sorts of reach() and activate() were a third of their
/// time on the 76 cubes).
template <class T, class Key>
void sort_by_key(std::vector<T>& items, Key key) {
  std::vector<RadixRecord> records(items.size());
  for (size_t i = 0; i < items.size(); ++i) records[i] = {key(items[i]), 0, static_cast<Index>(i)};
  radix_sort(records);
  std::vector<T> sorted;
  sorted.reserve(items.size());
  for (const RadixRecord& r : records) sorted.push_back(std::move(items[r.id]));
  items = std::move(sorted);
}

Box empty_box() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  return {Vec3::Constant(inf), Vec3::Constant(-inf)};
}

}  // namespace

SweptBoxes inflated_boxes(const ContactSurface& surface, std::span<const Vec3> x_old, std::span<const Vec3> x_new,
                          double margin, std::span<const double> reach) {
  SweptBoxes boxes = swept_boxes(surface, x_old, x_new);
  for (auto* list : {&boxes.triangles, &boxes.edges, &boxes.vertices})
    for (Box& b : *list) {
      b.lo.array() -= 1.01 * margin;
      b.hi.array() += 1.01 * margin;
    }
  if (reach.empty()) return boxes;
  auto grow = [&](Box& b, Index node) {
    b.lo.array() -= reach[node];
    b.hi.array() += reach[node];
  };
  for (size_t t = 0; t < boxes.triangles.size(); ++t) grow(boxes.triangles[t], surface.triangles[t][0]);
  for (size_t e = 0; e < boxes.edges.size(); ++e) grow(boxes.edges[e], surface.edges[e][0]);
  for (size_t v = 0; v < boxes.vertices.size(); ++v) grow(boxes.vertices[v], surface.vertices[v]);
  return boxes;
}

ContactPatch::ContactPatch(const Decomposition& dec, const SurfaceVertices& vertices, std::vector<NamedTriangle> home,
                           const Model& model, Index num_nodes, std::span<const double> node_reach)
    : dec_(dec), vertices_(vertices), model_(model), num_nodes_(num_nodes), part_reach_(node_reach),
      home_(std::move(home)) {
  for (size_t t = 0; t < home_.size(); ++t)
    for (const Index n : home_[t].nodes) home_at_.emplace_back(n, static_cast<Index>(t));
  std::sort(home_at_.begin(), home_at_.end());
  for (size_t k = 0; k < vertices.whole.size(); ++k) {
    // The part's rows the time loop keeps: those of its elements' nodes, and every node of a
    // rigid body (RigidBodies places them all on every rank, after DCR too).
    const Index n = vertices.node[k];
    SHATTER_ASSERT(n >= 0);
    const std::span<const int> ranks = dec.node_ranks(n);
    const bool touches = std::binary_search(ranks.begin(), ranks.end(), dec.rank());
    const bool rigid = model.scene.bodies[vertices.body[k]].has_rigid_state();
    const Index twin = vertices.twin.empty() ? vertices.whole[k] : vertices.twin[k];
    if (touches || rigid) kept_.push_back(know(vertices.whole[k], vertices.owner[k], vertices.body[k], twin));
    if (!touches) continue;
    for (const int r : ranks)
      if (r != dec.rank()) touching_.push_back(r);
    if (vertices.owner[k] == dec.rank()) volume_vertices_.vertices.push_back(n), volume_twin_.push_back(twin);
  }
  sort_unique(touching_);
  renumber(kept_);
}

ContactPatch::~ContactPatch() = default;

Index ContactPatch::know(Index whole, int owner, int body, Index twin) {
  const auto [it, fresh] = known_at_.try_emplace(whole, static_cast<Index>(known_.size()));
  if (fresh) known_.push_back({whole, held(whole), owner, body, twin});
  return it->second;
}

Index ContactPatch::held(Index whole) const {
  const std::span<const Index> ids = vertices_.whole;
  const auto it = std::lower_bound(ids.begin(), ids.end(), whole);
  return it != ids.end() && *it == whole ? vertices_.node[it - ids.begin()] : -1;
}

Index ContactPatch::known(Index whole) const {
  const auto it = known_at_.find(whole);
  SHATTER_ASSERT(it != known_at_.end());
  return it->second;
}

Index ContactPatch::node(Index whole) const {
  const Index k = known_[known(whole)].position;
  SHATTER_ASSERT(k >= 0);
  return k;
}

void ContactPatch::sort_by_whole(std::vector<Index>& nodes) const {
  // (whole ids are unique among the known nodes)
  sort_by_key(nodes, [&](Index n) { return static_cast<std::uint64_t>(known_[n].whole); });
}

Index ContactPatch::owned_primitive(Index q) const {
  const Index nt = owned_.num_triangles();
  if (q < nt) return q;
  const Index e = patch_edge_owned_at_[q - nt];
  return e < 0 ? -1 : nt + e;
}

namespace {

/// Every node id of `surface` becomes map[id].
void relabel(ContactSurface& surface, std::span<const Index> map) {
  for (auto& t : surface.triangles)
    for (Index& n : t) n = map[n];
  for (auto& e : surface.edges)
    for (Index& n : e) n = map[n];
  for (Index& n : surface.vertices) n = map[n];
}

}  // namespace

void ContactPatch::renumber(std::vector<Index> nodes) {
  // The patch numbering ascends with the whole model's ids, so the surfaces' orders (edges
  // a < b, vertices ascending) are those of the whole ids.
  std::vector<Vec3> x_old(nodes.size()), x_new(nodes.size()), v(nodes.size());
  std::vector<double> inv_mass(nodes.size(), 0.0);
  std::vector<std::uint8_t> held(held_.empty() ? 0 : nodes.size(), 0);
  for (size_t k = 0; k < nodes.size(); ++k)
    if (const Index was = known_[nodes[k]].position; was >= 0) {
      x_old[k] = x_old_[was], x_new[k] = x_new_[was], v[k] = v_[was], inv_mass[k] = inv_mass_[was];
      if (!held.empty()) held[k] = held_[was];
    }
  for (const Index n : nodes_) known_[n].position = -1;
  for (size_t k = 0; k < nodes.size(); ++k) known_[nodes[k]].position = static_cast<Index>(k);
  std::vector<Index> map(nodes_.size());
  for (size_t k = 0; k < nodes_.size(); ++k) map[k] = known_[nodes_[k]].position;
  relabel(owned_, map);
  nodes_ = std::move(nodes);
  x_old_ = std::move(x_old), x_new_ = std::move(x_new), v_ = std::move(v);
  inv_mass_ = std::move(inv_mass), held_ = std::move(held);
  reach_.clear();
  if (!part_reach_.empty())
    for (const Index n : nodes_) reach_.push_back(part_reach_[known_[n].node]);
  kept_at_.clear();
  for (const Index n : kept_) kept_at_.push_back(known_[n].position);
  // (the patch and active plans are made anew after a new numbering: reach() drops them)
  SHATTER_ASSERT(!plans_[static_cast<int>(PatchPlan::Patch)] && !plans_[static_cast<int>(PatchPlan::Active)]);
  if (plans_[static_cast<int>(PatchPlan::Owned)]) make_halos(PatchPlan::Owned);
}

void ContactPatch::forget() {
  // The patch's nodes keep their places (known id k: patch node k); the rings go.
  std::vector<KnownVertex> known;
  known_at_.clear();
  for (size_t k = 0; k < nodes_.size(); ++k) {
    known.push_back(known_[nodes_[k]]);
    known.back().ring = -1;
    known_at_.emplace(known.back().whole, static_cast<Index>(k));
  }
  std::vector<Index> map(known_.size(), -1);
  for (size_t k = 0; k < nodes_.size(); ++k) map[nodes_[k]] = static_cast<Index>(k);
  for (Index& n : kept_) n = map[n];
  std::iota(nodes_.begin(), nodes_.end(), 0);
  known_ = std::move(known);
  ring_ = {}, ring_keys_.clear(), ring_mark_.clear(), ring_name_.clear();
  ring_offsets_.assign(1, 0), ring_items_.clear();
}

void ContactPatch::own(const NamedSurface& primitives) {
  owned_once_ = true;
  for (int p = 0; p < 3; ++p) plans_[p].reset(), lists_[p] = {};
  fresh_.reset();
  owned_ = {}, patch_ = {}, normals_ = {}, normals_around_ = {};
  renumber(kept_);
  forget();
  ContactSurface owned;
  for (const NamedTriangle& t : primitives.triangles) {
    std::array<Index, 3> k;
    for (int c = 0; c < 3; ++c) k[c] = know(t.nodes[c], t.owner[c], t.body, t.twin[c]);
    owned.triangles.push_back(k);
    owned.body.push_back(t.body);
  }
  owned_edge_keys_.clear();
  for (const NamedEdge& e : primitives.edges) {
    owned.edges.push_back(
        {know(e.nodes[0], e.owner[0], e.body, e.twin[0]), know(e.nodes[1], e.owner[1], e.body, e.twin[1])});
    owned_edge_keys_.push_back(edge_key(e.nodes[0], e.nodes[1]));
  }
  SHATTER_REQUIRE(std::is_sorted(owned_edge_keys_.begin(), owned_edge_keys_.end()) &&
                      std::adjacent_find(owned_edge_keys_.begin(), owned_edge_keys_.end()) == owned_edge_keys_.end(),
                  "ContactPatch: owned edges not ascending");
  add_nodes<3>(owned.triangles, owned.vertices);
  add_nodes<2>(owned.edges, owned.vertices);
  sort_unique(owned.vertices);
  sort_by_whole(owned.vertices);
  std::vector<Index> nodes = kept_;
  nodes.insert(nodes.end(), owned.vertices.begin(), owned.vertices.end());
  sort_unique(nodes);
  sort_by_whole(nodes);
  renumber(std::move(nodes));
  auto& lists = lists_[static_cast<int>(PatchPlan::Owned)];
  lists = plan(owned.vertices, false);
  std::vector<Index> position(known_.size());
  for (size_t k = 0; k < known_.size(); ++k) position[k] = known_[k].position;
  relabel(owned, position);
  owned_ = std::move(owned);
  make_halos(PatchPlan::Owned);
}

void ContactPatch::add_node(Index n, std::vector<Index>& nodes) {
  if (!known_[n].mark) known_[n].mark = true, nodes.push_back(n);
}

void ContactPatch::reach(std::span<const Vec3> x_old, std::span<const Vec3> x_new, double margin) {
  const int ranks = dec_.size(), me = dec_.rank();
  owned_boxes_ = inflated_boxes(owned_, x_old_, x_new_, margin, reach_);
  const SweptBoxes& own = owned_boxes_;
  const SweptBoxes home = inflated_boxes(volume_vertices_, x_old, x_new, margin, part_reach_);
  Box mine = empty_box();
  for (const auto* list : {&own.triangles, &own.edges})
    for (const Box& b : *list) {
      mine.lo = mine.lo.cwiseMin(b.lo);
      mine.hi = mine.hi.cwiseMax(b.hi);
    }
  const double local[6] = {mine.lo.x(), mine.lo.y(), mine.lo.z(), mine.hi.x(), mine.hi.y(), mine.hi.z()};
  const std::vector<double> reach = dec_.allgather(std::span<const double>(local));
  std::vector<Box> boxes(ranks);
  for (int r = 0; r < ranks; ++r)
    boxes[r] = {Vec3(reach[6 * r], reach[6 * r + 1], reach[6 * r + 2]),
                Vec3(reach[6 * r + 3], reach[6 * r + 4], reach[6 * r + 5])};
  // Edges as their words (append_words: whole ids, owners, twins, body), vertices as -(whole
  // id + 1), their body and twin class (their owner is the sender).
  std::vector<std::vector<Index>> to(ranks);
  for (size_t k = 0; k < owned_.edges.size(); ++k)
    for (int r = 0; r < ranks; ++r)
      if (r != me && boxes_overlap(own.edges[k], boxes[r])) {
        const auto& [a, b] = owned_.edges[k];
        append_words(NamedEdge{{whole(a), whole(b)}, {owner(a), owner(b)}, {twin(a), twin(b)}, body(a)}, to[r]);
      }
  for (size_t k = 0; k < volume_vertices_.vertices.size(); ++k)
    for (int r = 0; r < ranks; ++r)
      if (boxes_overlap(home.vertices[k], boxes[r])) {
        const Index n = volume_vertices_.vertices[k];
        to[r].insert(to[r].end(), {-(model_.whole_node(n) + 1), model_.mesh.node_body[n], volume_twin_[k]});
      }
  // The ghost edges sorted by their whole ids, then the patch's edges: the owned ones
  // (ascending) and the ghosts merged, each with its owned edge.
  std::vector<std::pair<std::uint64_t, std::array<Index, 2>>> ghosts;
  std::vector<Index> vertices;
  const std::vector<std::vector<Index>> received = dec_.alltoall(to);
  for (int r = 0; r < ranks; ++r)
    for (size_t at = 0; at < received[r].size();)
      if (const Index* w = &received[r][at]; w[0] < 0) {
        vertices.push_back(know(-w[0] - 1, r, static_cast<int>(w[1]), w[2]));
        at += 3;
      } else {
        const NamedEdge e = read_edge(w);
        ghosts.push_back({edge_key(e.nodes[0], e.nodes[1]), {know(e.nodes[0], e.owner[0], e.body, e.twin[0]),
                                                              know(e.nodes[1], e.owner[1], e.body, e.twin[1])}});
        at += kNamedEdgeWords;
      }
  // (an edge sent by several ranks comes with the same known nodes each time)
  sort_by_key(ghosts, [](const auto& g) { return g.first; });
  ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
  sort_unique(vertices);
  std::vector<std::array<Index, 2>> edges;
  patch_edge_owned_at_.clear();
  patch_edge_owned_.clear();
  const size_t no = owned_edge_keys_.size();
  for (size_t i = 0, j = 0; i < no || j < ghosts.size();) {
    if (j == ghosts.size() || (i < no && owned_edge_keys_[i] < ghosts[j].first)) {
      edges.push_back({nodes_[owned_.edges[i][0]], nodes_[owned_.edges[i][1]]});
      patch_edge_owned_at_.push_back(static_cast<Index>(i++));
    } else {
      edges.push_back(ghosts[j++].second);
      patch_edge_owned_at_.push_back(-1);
    }
    patch_edge_owned_.push_back(patch_edge_owned_at_.back() >= 0 ? 1 : 0);
  }
  // The patch's nodes (made unique by marks: sorting the list with its repeats, each node
  // ~7 times, took a third of reach()'s CPU time on the 76 cubes), then those of the
  // triangles around them, whose normals orient their pairs (activate()).
  std::vector<Index> needed;
  for (const auto& t : owned_.triangles)
    for (const Index n : t) add_node(nodes_[n], needed);
  for (const auto& e : edges)
    for (const Index n : e) add_node(n, needed);
  for (const Index n : vertices) add_node(n, needed);
  std::vector<Index> nodes = needed;
  for (const Index n : kept_) add_node(n, nodes);
  fetch_rings(needed);
  for (size_t k = 0, count = needed.size(); k < count; ++k)
    for (const Index t : ring_of(needed[k]))
      for (const Index n : ring_.triangles[t]) add_node(n, nodes);
  for (const Index n : nodes) known_[n].mark = false;
  sort_by_whole(needed);
  sort_by_whole(nodes);
  for (const PatchPlan p : {PatchPlan::Patch, PatchPlan::Active})
    plans_[static_cast<int>(p)].reset(), lists_[static_cast<int>(p)] = {};
  fresh_.reset();
  normals_ = {}, normals_around_ = {};
  renumber(std::move(nodes));
  patch_ = {};
  patch_.triangles = owned_.triangles;
  patch_.body = owned_.body;
  for (const auto& [a, b] : edges) patch_.edges.push_back({known_[a].position, known_[b].position});
  for (const Index n : vertices) patch_.vertices.push_back(known_[n].position);
  std::sort(patch_.vertices.begin(), patch_.vertices.end());
  lists_[static_cast<int>(PatchPlan::Patch)] = plan(needed, false);
  make_halos(PatchPlan::Patch);
}

SweptBoxes ContactPatch::patch_boxes(double margin) const {
  // The ghost edges' boxes and the vertices' are new; the owned triangles (all of the
  // patch's) and edges keep those of reach().
  ContactSurface rest;
  for (size_t k = 0; k < patch_.edges.size(); ++k)
    if (!patch_edge_owned_[k]) rest.edges.push_back(patch_.edges[k]);
  rest.vertices = patch_.vertices;
  SweptBoxes boxes = inflated_boxes(rest, x_old_, x_new_, margin, reach_);
  std::vector<Box> ghost_edges = std::move(boxes.edges);
  boxes.triangles = owned_boxes_.triangles;
  boxes.edges.resize(patch_.edges.size());
  for (size_t k = 0, own = 0, ghost = 0; k < patch_.edges.size(); ++k)
    boxes.edges[k] = patch_edge_owned_[k] ? owned_boxes_.edges[own++] : ghost_edges[ghost++];
  return boxes;
}

void ContactPatch::activate(std::span<const ContactPair> pairs) {
  // The pairs' nodes (1), and the triangles whose normals orient the pairs (pair_normals):
  // those around a vertex-face pair's vertex, and those through an edge-edge pair's two
  // edges (from the rings, fetched by reach(): the pairs' nodes are the patch primitives').
  // Their other nodes are 2. Marked by patch node: the patch numbering ascends with the
  // whole ids, so the marked nodes read in order are sorted by whole id.
  std::vector<std::uint8_t> at(nodes_.size(), 0);
  std::vector<Index> triangles;
  ring_mark_.resize(ring_.triangles.size(), 0);
  const auto orient = [&](Index vertex, Index other) {
    for (const Index t : ring_of(nodes_[vertex])) {
      const auto& nodes = ring_.triangles[t];
      const bool through = other < 0 || std::find(nodes.begin(), nodes.end(), nodes_[other]) != nodes.end();
      if (through && !ring_mark_[t]) ring_mark_[t] = 1, triangles.push_back(t);
    }
  };
  for (const ContactPair& p : pairs) {
    for (const Index k : p.nodes) at[k] = 1;
    if (p.kind == ContactPair::VertexFace) {
      orient(p.nodes[0], -1);
    } else {
      orient(p.nodes[0], p.nodes[1]);
      orient(p.nodes[2], p.nodes[3]);
    }
  }
  for (const Index t : triangles) ring_mark_[t] = 0;
  // (name keys are unique and not negative)
  sort_by_key(triangles, [&](Index t) { return static_cast<std::uint64_t>(ring_keys_[t]); });
  for (const Index t : triangles)
    for (const Index n : ring_.triangles[t]) {
      SHATTER_ASSERT(known_[n].position >= 0);
      if (!at[known_[n].position]) at[known_[n].position] = 2;
    }
  std::vector<Index> needed;
  std::vector<std::uint8_t> velocity;
  for (size_t k = 0; k < at.size(); ++k)
    if (at[k]) needed.push_back(nodes_[k]), velocity.push_back(at[k] == 1);
  // reach() holds the rings' nodes in the patch. Only the triangles, their vertices and the
  // vertex -> triangle lists are made (surface_normal's needs).
  normals_ = {};
  std::vector<char> vertex_mark(nodes_.size(), 0);
  for (const Index t : triangles) {
    const auto& [a, b, c] = ring_.triangles[t];
    normals_.triangles.push_back({known_[a].position, known_[b].position, known_[c].position});
    normals_.body.push_back(ring_.body[t]);
    for (const Index n : normals_.triangles.back()) vertex_mark[n] = 1;
  }
  for (size_t k = 0; k < vertex_mark.size(); ++k)
    if (vertex_mark[k]) normals_.vertices.push_back(static_cast<Index>(k));
  normals_around_ = vertex_triangles(normals_);
  lists_[static_cast<int>(PatchPlan::Active)] = plan(needed, true, velocity);
  make_halos(PatchPlan::Active);
}

Index ContactPatch::ring_triangle(const NamedTriangle& t) {
  const std::int64_t key = name_key(t.name);
  const auto [it, fresh] = ring_name_.try_emplace(key, ring_.num_triangles());
  if (fresh) {
    ring_.triangles.push_back({know(t.nodes[0], t.owner[0], t.body, t.twin[0]),
                               know(t.nodes[1], t.owner[1], t.body, t.twin[1]),
                               know(t.nodes[2], t.owner[2], t.body, t.twin[2])});
    ring_.body.push_back(t.body);
    ring_keys_.push_back(key);
  }
  return it->second;
}

std::span<const Index> ContactPatch::ring_of(Index v) const {
  const Index k = known_[v].ring;
  SHATTER_ASSERT(k >= 0);
  return {ring_items_.data() + ring_offsets_[k], static_cast<size_t>(ring_offsets_[k + 1] - ring_offsets_[k])};
}

void ContactPatch::fetch_rings(std::span<const Index> vertices) {
  // Each vertex's volume owner holds every triangle around it (home_triangles). Asked for a
  // list of vertices, it answers with the triangles around them, each once (append_words),
  // in name order.
  const int ranks = dec_.size(), me = dec_.rank();
  std::vector<std::vector<Index>> ask(ranks);
  std::vector<Index> mine;
  for (const Index v : vertices)
    if (known_[v].ring < 0) {
      if (known_[v].owner == me) mine.push_back(v);
      else ask[known_[v].owner].push_back(known_[v].whole);
    }
  for (std::vector<Index>& list : ask) std::sort(list.begin(), list.end());
  const auto around_home = [&](Index whole, std::vector<Index>& out) {
    const auto first = std::lower_bound(home_at_.begin(), home_at_.end(), std::pair<Index, Index>(whole, -1));
    for (auto it = first; it != home_at_.end() && it->first == whole; ++it) out.push_back(it->second);
  };
  const std::vector<std::vector<Index>> asked = dec_.alltoall(ask);
  std::vector<std::vector<Index>> reply(ranks);
  for (int r = 0; r < ranks; ++r) {
    std::vector<Index> triangles;
    for (const Index whole : asked[r]) around_home(whole, triangles);
    sort_unique(triangles);
    for (const Index t : triangles) append_words(home_[t], reply[r]);
  }
  const std::vector<std::vector<Index>> answers = dec_.alltoall(reply);
  // Each ring is appended whole to ring_items_ (one array: the rings are read together at
  // every search).
  const auto append = [&](Index v, const std::vector<Index>& ring) {
    known_[v].ring = static_cast<Index>(ring_offsets_.size() - 1);
    ring_items_.insert(ring_items_.end(), ring.begin(), ring.end());
    ring_offsets_.push_back(static_cast<Index>(ring_items_.size()));
  };
  for (const Index v : mine) {
    std::vector<Index> triangles, ring;
    around_home(known_[v].whole, triangles);
    for (const Index t : triangles) ring.push_back(ring_triangle(home_[t]));
    append(v, ring);
  }
  // An asked vertex's ring: the answered triangles that hold it (its owner sent them all).
  for (int r = 0; r < ranks; ++r) {
    std::vector<std::vector<Index>> rings(ask[r].size());
    const std::vector<Index>& list = answers[r];
    for (size_t i = 0; i + kNamedTriangleWords <= list.size(); i += kNamedTriangleWords) {
      const NamedTriangle t = read_triangle(&list[i]);
      const Index at = ring_triangle(t);
      for (const Index whole : t.nodes)
        if (const auto it = std::lower_bound(ask[r].begin(), ask[r].end(), whole); it != ask[r].end() && *it == whole)
          rings[it - ask[r].begin()].push_back(at);
    }
    for (size_t k = 0; k < ask[r].size(); ++k) append(known(ask[r][k]), rings[k]);
  }
}

ContactPatch::PlanLists ContactPatch::plan(const std::vector<Index>& nodes, bool readers,
                                           std::span<const std::uint8_t> velocity) {
  const int ranks = dec_.size(), me = dec_.rank();
  PlanLists lists;
  // A request names a node by its whole id, or by -(whole id + 1) if only its positions are
  // read.
  std::vector<std::vector<Index>> requests(ranks);
  for (size_t k = 0; k < nodes.size(); ++k) {
    const Index n = nodes[k];
    const int owner = known_[n].owner;
    if (owner == me) continue;
    const bool v = velocity.empty() || velocity[k];
    lists.receive[owner].push_back(n);
    lists.receive_velocity[owner].push_back(v);
    requests[owner].push_back(v ? known_[n].whole : -(known_[n].whole + 1));
  }
  const std::vector<std::vector<Index>> asked = dec_.alltoall(requests);
  for (int r = 0; r < ranks; ++r)
    for (const Index word : asked[r]) {
      const Index n = held(word < 0 ? -word - 1 : word);
      SHATTER_ASSERT(n >= 0);
      lists.send[r].push_back(n);
      lists.send_velocity[r].push_back(word >= 0);
    }
  if (readers) find_readers(lists);
  return lists;
}

void ContactPatch::make_halos(PatchPlan p) {
  const PlanLists& lists = lists_[static_cast<int>(p)];
  const Index patch_nodes = num_nodes();
  // The lists' nodes in the numberings of the arrays exchanged: a node's own for the owned
  // and patch plans; for the active one, stacked x_old, x_new, v (Halo::update_stacked).
  const auto halo = [&](auto send_entry, auto receive_entry, Index arrays) {
    std::map<int, std::vector<Index>> send, receive;
    for (const auto& [r, list] : lists.send)
      for (size_t k = 0; k < list.size(); ++k) send_entry(send[r], list[k], k, r, num_nodes_);
    for (const auto& [r, list] : lists.receive)
      for (size_t k = 0; k < list.size(); ++k) receive_entry(receive[r], known_[list[k]].position, k, r, patch_nodes);
    // (no message where a rank has no entry for another: the two sides agree on that)
    const auto empty = [](const auto& entry) { return entry.second.empty(); };
    std::erase_if(send, empty), std::erase_if(receive, empty);
    return std::make_unique<Halo>(arrays * num_nodes_, arrays * patch_nodes, exchange_from(send),
                                  exchange_from(receive), dec_.comm(), kPatchTag);
  };
  if (p != PatchPlan::Active) {
    const auto own = [](std::vector<Index>& out, Index n, size_t, int, Index) { out.push_back(n); };
    plans_[static_cast<int>(p)] = halo(own, own, 1);
    return;
  }
  // Right after the search, which brought the primitives' nodes: x_old and x_new of the
  // others (the triangles around the pairs, which orient them at x_old). Between searches:
  // v of every node, whose x_new the receiver drifts from x_old (load()); a rigid body's
  // node also sends x_new (its body places it).
  const auto entries = [&](const std::map<int, std::vector<std::uint8_t>>& velocity, auto rigid, bool fresh) {
    return [&velocity, rigid, fresh](std::vector<Index>& out, Index n, size_t k, int r, Index size) {
      if (fresh && !velocity.at(r)[k]) out.push_back(n), out.push_back(size + n);
      if (fresh) return;
      if (rigid(n)) out.push_back(size + n);
      out.push_back(2 * size + n);
    };
  };
  const auto rigid_body = [this](int body) { return model_.scene.bodies[body].has_rigid_state(); };
  const auto part_rigid = [&](Index n) { return rigid_body(model_.mesh.node_body[n]); };
  const auto patch_rigid = [&](Index k) { return rigid_body(body(k)); };
  plans_[static_cast<int>(p)] = halo(entries(lists.send_velocity, part_rigid, false),
                                     entries(lists.receive_velocity, patch_rigid, false), 3);
  fresh_ = halo(entries(lists.send_velocity, part_rigid, true), entries(lists.receive_velocity, patch_rigid, true), 3);
  drifted_.clear();
  for (const auto& [r, list] : lists.receive)
    for (const Index n : list)
      if (!patch_rigid(known_[n].position)) drifted_.push_back(known_[n].position);
}

void ContactPatch::find_readers(const PlanLists& lists) {
  const int me = dec_.rank();
  neighbors_ = touching_;
  for (const auto* plan : {&lists.send, &lists.receive})
    for (const auto& [r, list] : *plan) neighbors_.push_back(r);
  sort_unique(neighbors_);
  // Each home node's readers: the ranks it is sent to, and the other ranks touching it, as
  // (home node, rank) entries sorted into the CSR.
  const auto& home = volume_vertices_.vertices;
  std::vector<std::pair<Index, int>> entries;
  for (const auto& [r, list] : lists.send)
    for (const Index n : list)
      entries.push_back({static_cast<Index>(std::lower_bound(home.begin(), home.end(), n) - home.begin()), r});
  for (size_t k = 0; k < home.size(); ++k)
    for (const int r : dec_.node_ranks(home[k]))
      if (r != me) entries.push_back({static_cast<Index>(k), r});
  sort_unique(entries);
  reader_offsets_.assign(home.size() + 1, 0);
  readers_.clear();
  for (const auto& [k, r] : entries) ++reader_offsets_[k + 1], readers_.push_back(r);
  for (size_t k = 0; k < home.size(); ++k) reader_offsets_[k + 1] += reader_offsets_[k];
}

void ContactPatch::load(std::span<const Vec3> x_old, std::span<const Vec3> x_new, std::span<const Vec3> v,
                        std::span<const double> inv_mass, std::span<const std::uint8_t> held, double dt) {
  part_inv_mass_ = inv_mass, part_held_ = held, dt_ = dt;
  if (!held.empty()) held_.resize(nodes_.size(), 0);
  x_old_ = x_new_;
  for (size_t i = 0; i < kept_.size(); ++i) {
    const Index n = known_[kept_[i]].node, k = kept_at_[i];
    x_old_[k] = x_old[n], x_new_[k] = x_new[n], v_[k] = v[n], inv_mass_[k] = inv_mass[n];
    if (!held.empty()) held_[k] = held[n];
  }
}

void ContactPatch::store(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v) const {
  for (size_t i = 0; i < kept_.size(); ++i) {
    const Index n = known_[kept_[i]].node, k = kept_at_[i];
    x_old[n] = x_old_[k], x_new[n] = x_new_[k], v[n] = v_[k];
  }
}

long ContactPatch::exchange(std::span<const Vec3> x_old, std::span<const Vec3> x_new, std::span<const Vec3> v,
                            PatchPlan plan) {
  if (plan == PatchPlan::Active) {
    // The fresh plan once, right after the search; then the one between searches.
    std::unique_ptr<Halo> fresh = std::move(fresh_);
    Halo* h = fresh ? fresh.get() : plans_[static_cast<int>(plan)].get();
    if (!h) return 0;
    const std::span<const Vec3> from[] = {x_old, x_new, v};
    const std::span<Vec3> to[] = {x_old_, x_new_, v_};
    h->update_stacked(from, to);
    // The central difference's drift, as the volume owner made it.
    if (!fresh)
      for (const Index k : drifted_) x_new_[k] = drift(x_old_[k], dt_, v_[k]);
    return static_cast<long>(h->update_bytes(3));
  }
  Halo* h = plans_[static_cast<int>(plan)].get();
  if (!h) return 0;
  // The patch's plan brings what DCR reads of the nodes besides their states, as a fourth
  // array (the nodes' masses and conditions do not change between searches).
  std::vector<Vec3> data;
  const bool with_data = plan == PatchPlan::Patch;
  if (with_data) {
    part_data_.resize(num_nodes_);
    for (const auto& [r, list] : lists_[static_cast<int>(PatchPlan::Patch)].send)
      for (const Index n : list) part_data_[n] = Vec3(part_inv_mass_[n], part_held_.empty() ? 0 : part_held_[n], 0);
    data.resize(nodes_.size());
  }
  const std::span<const Vec3> from[] = {x_old, x_new, v, part_data_};
  const std::span<Vec3> to[] = {x_old_, x_new_, v_, data};
  const size_t count = with_data ? 4 : 3;
  h->update(std::span(from).first(count), std::span(to).first(count));
  if (with_data)
    for (const auto& [r, list] : lists_[static_cast<int>(PatchPlan::Patch)].receive)
      for (const Index n : list) {
        const Index k = known_[n].position;
        inv_mass_[k] = data[k].x();
        if (!held_.empty()) held_[k] = static_cast<std::uint8_t>(data[k].y());
      }
  return static_cast<long>(h->update_bytes(static_cast<int>(3 * count)));
}

std::span<const int> ContactPatch::readers(Index k) const {
  const auto& home = volume_vertices_.vertices;
  const Index n = part_node(k);
  const auto it = std::lower_bound(home.begin(), home.end(), n);
  SHATTER_ASSERT(it != home.end() && *it == n && reader_offsets_.size() == home.size() + 1);
  const auto at = it - home.begin();
  return {readers_.data() + reader_offsets_[at], static_cast<size_t>(reader_offsets_[at + 1] - reader_offsets_[at])};
}

}  // namespace shatter
