#include "runtime/contact_patch.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>

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

ContactPatch::ContactPatch(const Decomposition& dec, const ContactSurface& surface, const VertexTriangles& around,
                           const Model& model, Index num_nodes)
    : dec_(dec), surface_(surface), around_(around), model_(model), num_nodes_(num_nodes) {
  // The edges are sorted by their first node, so each vertex's are a range.
  edge_offsets_.assign(surface.vertices.size() + 1, 0);
  for (const auto& e : surface.edges) ++edge_offsets_[around.position[e[0]] + 1];
  std::partial_sum(edge_offsets_.begin(), edge_offsets_.end(), edge_offsets_.begin());
  for (const Index n : surface.vertices) {
    const std::span<const int> ranks = dec.node_ranks(n);
    if (!std::binary_search(ranks.begin(), ranks.end(), dec.rank())) continue;
    for (const int r : ranks)
      if (r != dec.rank()) touching_.push_back(r);
    if (dec.node_owner(n) == dec.rank()) volume_vertices_.vertices.push_back(n);
  }
  sort_unique(touching_);
}

ContactPatch::~ContactPatch() = default;

Index ContactPatch::node(Index whole) const {
  const Index n = model_.local_node(whole);
  SHATTER_ASSERT(n >= 0);
  return n;
}

Index ContactPatch::edge(Index a, Index b) const {
  const Index at = around_.position[a];
  const auto first = surface_.edges.begin() + edge_offsets_[at], last = surface_.edges.begin() + edge_offsets_[at + 1];
  const auto it = std::find(first, last, std::array<Index, 2>{a, b});
  SHATTER_ASSERT(it != last);
  return static_cast<Index>(it - surface_.edges.begin());
}

Index ContactPatch::surface_primitive(Index q) const {
  const auto nt = static_cast<Index>(owned_triangles_.size());
  return q < nt ? owned_triangles_[q] : surface_.num_triangles() + patch_edges_[q - nt];
}

void ContactPatch::own(std::span<const Index> primitives) {
  const auto nt = static_cast<Index>(surface_.triangles.size());
  const auto total = nt + static_cast<Index>(surface_.edges.size());
  owned_once_ = true;
  owned_triangles_.clear();
  owned_edges_.clear();
  owned_mark_.assign(total, 0);
  owned_ = {};
  for (size_t k = 0; k < primitives.size(); ++k) {
    const Index q = primitives[k];
    SHATTER_REQUIRE(q >= 0 && q < total && (k == 0 || primitives[k - 1] < q),
                    "ContactPatch: primitive " << q << " of " << total << " out of range or out of order");
    owned_mark_[q] = 1;
    if (q < nt) {
      owned_triangles_.push_back(q);
      owned_.triangles.push_back(surface_.triangles[q]);
      owned_.body.push_back(surface_.body[q]);
    } else {
      owned_edges_.push_back(q - nt);
      owned_.edges.push_back(surface_.edges[q - nt]);
    }
  }
  add_nodes<3>(owned_.triangles, owned_.vertices);
  add_nodes<2>(owned_.edges, owned_.vertices);
  sort_unique(owned_.vertices);
  for (auto& p : plans_) p.reset();
  plans_[static_cast<int>(PatchPlan::Owned)] = plan(owned_.vertices, false);
}

void ContactPatch::add_node(Index n, std::vector<Index>& nodes) {
  if (!node_mark_[n]) node_mark_[n] = 1, nodes.push_back(n);
}

void ContactPatch::sort_marked(std::vector<Index>& nodes) {
  for (const Index n : nodes) node_mark_[n] = 0;
  std::sort(nodes.begin(), nodes.end());
}

void ContactPatch::reach(std::span<const Vec3> x_old, std::span<const Vec3> x_new, double margin,
                         std::span<const double> node_reach) {
  const int ranks = dec_.size(), me = dec_.rank();
  owned_boxes_ = inflated_boxes(owned_, x_old, x_new, margin, node_reach);
  const SweptBoxes& own = owned_boxes_;
  const SweptBoxes vertex = inflated_boxes(volume_vertices_, x_old, x_new, margin, node_reach);
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
  // Edges as their nodes' whole ids {a, b}, vertices as -(whole id + 1).
  std::vector<std::vector<Index>> to(ranks);
  for (size_t k = 0; k < owned_edges_.size(); ++k)
    for (int r = 0; r < ranks; ++r)
      if (r != me && boxes_overlap(own.edges[k], boxes[r]))
        for (const Index n : owned_.edges[k]) to[r].push_back(model_.whole_node(n));
  for (size_t k = 0; k < volume_vertices_.vertices.size(); ++k)
    for (int r = 0; r < ranks; ++r)
      if (boxes_overlap(vertex.vertices[k], boxes[r]))
        to[r].push_back(-(model_.whole_node(volume_vertices_.vertices[k]) + 1));
  std::vector<Index> edges(owned_edges_), vertices;
  for (const auto& list : dec_.alltoall(to))
    for (size_t at = 0; at < list.size(); ++at)
      if (list[at] < 0) vertices.push_back(node(-list[at] - 1));
      else edges.push_back(edge(node(list[at]), node(list[at + 1]))), ++at;
  sort_unique(edges);
  sort_unique(vertices);
  patch_ = {};
  patch_.triangles = owned_.triangles;
  patch_.body = owned_.body;
  for (const Index e : edges) patch_.edges.push_back(surface_.edges[e]);
  patch_.vertices = std::move(vertices);
  patch_edges_ = std::move(edges);
  patch_edge_owned_.resize(patch_edges_.size());
  for (size_t k = 0; k < patch_edges_.size(); ++k) patch_edge_owned_[k] = owns(surface_.num_triangles() + patch_edges_[k]);
  // The patch's nodes, made unique by marks: sorting the list with its repeats (each node
  // ~7 times) took a third of reach()'s CPU time on the 76 cubes.
  node_mark_.resize(num_nodes_, 0);
  std::vector<Index> needed;
  for (const auto& t : patch_.triangles)
    for (const Index n : t) add_node(n, needed);
  for (const auto& e : patch_.edges)
    for (const Index n : e) add_node(n, needed);
  for (const Index n : patch_.vertices) add_node(n, needed);
  sort_marked(needed);
  plans_[static_cast<int>(PatchPlan::Patch)] = plan(needed, false);
  plans_[static_cast<int>(PatchPlan::Active)].reset();
}

SweptBoxes ContactPatch::patch_boxes(std::span<const Vec3> x_old, std::span<const Vec3> x_new, double margin,
                                     std::span<const double> node_reach) const {
  // The ghost edges' boxes and the vertices' are new; the owned triangles (all of the
  // patch's) and edges keep those of reach().
  ContactSurface rest;
  for (size_t k = 0; k < patch_.edges.size(); ++k)
    if (!patch_edge_owned_[k]) rest.edges.push_back(patch_.edges[k]);
  rest.vertices = patch_.vertices;
  SweptBoxes boxes = inflated_boxes(rest, x_old, x_new, margin, node_reach);
  std::vector<Box> ghost_edges = std::move(boxes.edges);
  boxes.triangles = owned_boxes_.triangles;
  boxes.edges.resize(patch_.edges.size());
  for (size_t k = 0, own = 0, ghost = 0; k < patch_.edges.size(); ++k)
    boxes.edges[k] = patch_edge_owned_[k] ? owned_boxes_.edges[own++] : ghost_edges[ghost++];
  return boxes;
}

void ContactPatch::activate(std::span<const ContactPair> pairs) {
  // The pairs' nodes, and the triangles around them that orient the pairs with their nodes
  // (marks kept between searches, cleared after use).
  triangle_mark_.resize(surface_.triangles.size(), 0);
  node_mark_.resize(num_nodes_, 0);
  std::vector<Index> needed;
  for (const ContactPair& p : pairs)
    for (const Index n : p.nodes) add_node(n, needed);
  normal_triangles_.clear();
  for (size_t k = 0, nodes = needed.size(); k < nodes; ++k) {
    const Index p = around_.position[needed[k]];
    for (Index i = around_.offsets[p]; i < around_.offsets[p + 1]; ++i) {
      const Index t = around_.items[i];
      if (!triangle_mark_[t]) triangle_mark_[t] = 1, normal_triangles_.push_back(t);
    }
  }
  for (const Index t : normal_triangles_) {
    triangle_mark_[t] = 0;
    for (const Index n : surface_.triangles[t]) add_node(n, needed);
  }
  sort_marked(needed);
  std::sort(normal_triangles_.begin(), normal_triangles_.end());
  plans_[static_cast<int>(PatchPlan::Active)] = plan(needed, true);
  active_fresh_ = true;
}

std::unique_ptr<Halo> ContactPatch::plan(const std::vector<Index>& nodes, bool readers) {
  const int ranks = dec_.size(), me = dec_.rank();
  std::map<int, std::vector<Index>> receive;
  std::vector<std::vector<Index>> requests(ranks);
  for (const Index n : nodes) {
    const int owner = dec_.node_owner(n);
    if (owner == me) continue;
    receive[owner].push_back(n);
    requests[owner].push_back(model_.whole_node(n));
  }
  std::map<int, std::vector<Index>> send;
  const std::vector<std::vector<Index>> asked = dec_.alltoall(requests);
  for (int r = 0; r < ranks; ++r)
    for (const Index whole : asked[r]) send[r].push_back(node(whole));
  if (readers) find_readers(send, receive);
  return std::make_unique<Halo>(num_nodes_, exchange_from(send), exchange_from(receive), dec_.comm(), kPatchTag);
}

void ContactPatch::find_readers(const std::map<int, std::vector<Index>>& send,
                                const std::map<int, std::vector<Index>>& receive) {
  const int me = dec_.rank();
  neighbors_ = touching_;
  for (const auto* plan : {&send, &receive})
    for (const auto& [r, list] : *plan) neighbors_.push_back(r);
  sort_unique(neighbors_);
  // Each home node's readers: the ranks it is sent to, and the other ranks touching it.
  const auto& home = volume_vertices_.vertices;
  std::vector<std::vector<int>> readers(home.size());
  for (const auto& [r, list] : send)
    for (const Index n : list) readers[std::lower_bound(home.begin(), home.end(), n) - home.begin()].push_back(r);
  reader_offsets_.assign(1, 0);
  readers_.clear();
  for (size_t k = 0; k < home.size(); ++k) {
    for (const int r : dec_.node_ranks(home[k]))
      if (r != me) readers[k].push_back(r);
    sort_unique(readers[k]);
    readers_.insert(readers_.end(), readers[k].begin(), readers[k].end());
    reader_offsets_.push_back(static_cast<Index>(readers_.size()));
  }
}

Halo* ContactPatch::halo(PatchPlan plan) const { return plans_[static_cast<int>(plan)].get(); }

long ContactPatch::exchange(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v, PatchPlan plan) {
  Halo* h = halo(plan);
  if (!h) return 0;
  const bool states_only = plan == PatchPlan::Active && !active_fresh_;
  if (plan == PatchPlan::Active) active_fresh_ = false;
  const std::span<Vec3> all[] = {x_old, x_new, v};
  const std::span<const std::span<Vec3>> arrays = states_only ? std::span(all).subspan(1) : std::span(all);
  h->update_ghosts(arrays);
  return static_cast<long>(h->update_bytes(3 * static_cast<int>(arrays.size())));
}

std::span<const int> ContactPatch::readers(Index node) const {
  const auto& home = volume_vertices_.vertices;
  const auto it = std::lower_bound(home.begin(), home.end(), node);
  SHATTER_ASSERT(it != home.end() && *it == node && reader_offsets_.size() == home.size() + 1);
  const auto k = it - home.begin();
  return {readers_.data() + reader_offsets_[k], static_cast<size_t>(reader_offsets_[k + 1] - reader_offsets_[k])};
}

}  // namespace shatter
