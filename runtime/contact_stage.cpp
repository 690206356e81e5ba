#include "runtime/contact_stage.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "contact/candidates.hpp"
#include "kernels/error.hpp"
#include "runtime/contact_partition.hpp"
#include "runtime/contact_patch.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/named_surface.hpp"
#include "runtime/parallel.hpp"
#include "runtime/patch_ranks.hpp"
#include "runtime/timed.hpp"

namespace shatter {

ContactStage::ContactStage(const Model& model, const ContactSpec& spec, const Decomposition* dec) : model_(model) {
  if (dec && dec->distributed()) {
    dec_ = dec;
    partition_ = std::make_unique<ContactPartition>(dec->comm());
  }
  options_.restitution = spec.restitution;
  options_.friction = spec.friction;
  options_.max_sweeps = spec.max_sweeps;
  margin_fraction_ = spec.search_margin;
  options_.placement = spec.placement;
  body_pairs_ = spec.pairs;
  self_ = spec.self;
  for (const BodySpec& b : model.scene.bodies) free_rigid_.push_back(b.free_rigid);
  any_free_rigid_ = std::find(free_rigid_.begin(), free_rigid_.end(), char{1}) != free_rigid_.end();
  // Shells: their control nodes' half-thickness; a shell never contacts itself.
  shell_body_.assign(model.scene.bodies.size(), 0);
  for (const ShellBody& shell : model.shells) {
    reach_.resize(model.mesh.num_nodes(), 0.0);
    shell_body_[shell.body] = 1;
    for (Index v = 0; v < shell.mesh.num_vertices(); ++v) reach_[shell.first_node + v] = 0.5 * shell.thickness;
  }
  // A part holds no triangles of the surface but its own elements' (named_surface.hpp): its
  // patch names them and gets the rest from the other ranks. The rigid bodies' surface nodes
  // are held on every part (never split, so their part nodes stay).
  if (model.is_part()) {
    for (const Index whole : model.part.rigid_surface_node) rigid_nodes_.push_back(model.local_node(whole));
    set_surface({}, model.mesh);
  } else {
    rebuild(model.mesh);
  }
}

void ContactStage::rebuild(const Mesh& mesh, std::span<const std::pair<Index, int>> skip,
                           std::span<const std::array<Index, 2>> twins) {
  std::vector<Index> twin_of;
  if (!twins.empty()) {
    // Union-find over the twin pairs, each class represented by its smallest node.
    twin_of.resize(mesh.num_nodes());
    std::iota(twin_of.begin(), twin_of.end(), 0);
    auto root = [&](Index n) {
      while (twin_of[n] != n) n = twin_of[n] = twin_of[twin_of[n]];
      return n;
    };
    for (const auto& [a, b] : twins) {
      const Index ra = root(a), rb = root(b);
      twin_of[std::max(ra, rb)] = std::min(ra, rb);
    }
    for (Index n = 0; n < mesh.num_nodes(); ++n) twin_of[n] = root(n);
  }
  if (model_.is_part()) {
    // A part names the triangles of its own elements, the bonded faces left out, and each node
    // by its twin class's whole id (docs/parallel.md "Cracks in contact on parts").
    bonded_faces_.assign(skip.begin(), skip.end());
    twin_whole_.clear();
    for (const Index n : twin_of) twin_whole_.push_back(model_.whole_node(n));
    set_surface({}, mesh);
    return;
  }
  twin_of_ = std::move(twin_of);
  ContactSurface surface = build_contact_surface(mesh, skip);
  // The shells' control meshes, the mid-surfaces thickened by reach_ (docs/shells.md "Contact");
  // nodes that fracture added (after the shells', of solids) have none.
  if (!reach_.empty()) reach_.resize(mesh.num_nodes(), 0.0);
  std::vector<SurfaceTriangle> sheets;
  for (const ShellBody& shell : model_.shells)
    for (const auto& t : shell.mesh.triangles)
      sheets.push_back({{shell.first_node + t[0], shell.first_node + t[1], shell.first_node + t[2]}, shell.body});
  add_triangles(surface, sheets);
  set_surface(std::move(surface), mesh);
}

bool ContactStage::excluded(const ContactPair& p) const {
  // On several ranks the pair is of patch nodes: their bodies and twin classes come with them.
  const int first = p.kind == ContactPair::VertexFace ? 1 : 2;
  const auto body = [&](Index n) { return dec_ ? patch_->body(n) : node_body_[n]; };
  const auto twin = [&](Index n) { return dec_ ? patch_->twin(n) : twin_of_[n]; };
  if (by_body()) {
    const int a = body(p.nodes[0]), b = body(p.nodes[first]);
    if ((!self_ || shell_body_[a]) && a == b) return true;
    // Free rigid bodies touch deformable ones only (DCR moves one rigid body per pair;
    // the scene refuses two that contact.pairs lets touch): their self-pairs drop.
    if (free_rigid_[a] && free_rigid_[b]) return true;
    if (!body_pairs_.empty() &&
        !std::binary_search(body_pairs_.begin(), body_pairs_.end(), std::array<int, 2>{std::min(a, b), std::max(a, b)}))
      return true;
  }
  if (!dec_ && twin_of_.empty()) return false;
  for (int i = 0; i < first; ++i)
    for (int j = first; j < 4; ++j)
      if (twin(p.nodes[i]) == twin(p.nodes[j])) return true;
  return false;
}

void ContactStage::set_surface(ContactSurface surface, const Mesh& mesh) {
  surface_ = std::move(surface);
  // A part has no rows of most surface nodes: its surface's median edge came with it.
  margin_ = margin_fraction_ *
            (model_.is_part() ? model_.part.surface_edge : median_edge_length(surface_, mesh.reference));
  have_candidates_ = false;
  pairs_.clear();
  scratch_.gaps.clear();
  node_body_.clear();
  if (!dec_) {
    if (by_body()) node_body_ = mesh.node_body;
    vertex_triangles_ = vertex_triangles(surface_);
    return;
  }
  set_vertices(mesh);
  vertex_triangles_ = {};
  ranks_.reset();
  patch_ = std::make_unique<ContactPatch>(*dec_, vertices_, home_triangles(), model_, mesh.num_nodes(), reach_);
  ranks_ = std::make_unique<PatchRanks>(*patch_, *dec_);
  repartition_ = true;
}

void ContactStage::set_vertices(const Mesh& mesh) {
  // The patch starts from the surface vertices held here (docs/parallel.md "Patches with
  // their own topology"); a whole model's topology is in surface vertex ids (vertex k of the
  // surface).
  vertices_ = {};
  whole_tables_ = {};
  if (model_.is_part()) {
    // The surface nodes it touches, from its mesh, and the rigid bodies' (every part holds
    // them), merged in whole-id order.
    const std::vector<Index> touched = touched_surface_nodes(model_, *dec_, bonded());
    const auto whole = [&](Index n) { return model_.whole_node(n); };
    for (size_t i = 0, j = 0; i < touched.size() || j < rigid_nodes_.size();) {
      const bool take_rigid =
          i == touched.size() || (j < rigid_nodes_.size() && whole(rigid_nodes_[j]) <= whole(touched[i]));
      const Index n = take_rigid ? rigid_nodes_[j] : touched[i];
      if (take_rigid && i < touched.size() && touched[i] == n) ++i;
      vertices_.node.push_back(n);
      whole_tables_.whole.push_back(whole(n));
      whole_tables_.owner.push_back(take_rigid ? model_.part.rigid_surface_owner[j] : dec_->node_owner(n));
      whole_tables_.body.push_back(mesh.node_body[n]);
      if (!twin_whole_.empty()) whole_tables_.twin.push_back(twin_whole_[n]);
      take_rigid ? ++j : ++i;
    }
  } else {
    vertices_.node = surface_.vertices;
    const std::vector<Index> at = vertex_triangles(surface_).position;
    for (auto& t : surface_.triangles)
      for (Index& n : t) n = at[n];
    for (auto& e : surface_.edges)
      for (Index& n : e) n = at[n];
    std::iota(surface_.vertices.begin(), surface_.vertices.end(), 0);
    for (const Index n : vertices_.node) {
      whole_tables_.whole.push_back(model_.whole_node(n));
      whole_tables_.owner.push_back(dec_->node_owner(n));
      whole_tables_.body.push_back(mesh.node_body[n]);
    }
    if (!twin_of_.empty())
      for (const Index n : vertices_.node) whole_tables_.twin.push_back(model_.whole_node(twin_of_[n]));
    twin_of_ = std::vector<Index>();  // (not `= {}`, which keeps the capacity): the twins travel with the primitives
  }
  vertices_.whole = whole_tables_.whole;
  vertices_.owner = whole_tables_.owner;
  vertices_.body = whole_tables_.body;
  vertices_.twin = whole_tables_.twin;
}

Bonded ContactStage::bonded() const { return {bonded_faces_, twin_whole_}; }

ContactStage::~ContactStage() = default;

bool ContactStage::candidates_valid(std::span<const Vec3> x_old, std::span<const Vec3> x_new) const {
  if (!have_candidates_) return false;
  // On several ranks each checks the surface vertices whose volume owner it is.
  const std::span<const Index> vertices = dec_ ? patch_->home_vertices() : std::span<const Index>(surface_.vertices);
  const bool valid = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, vertices.size(), 4096), true,
      [&](const tbb::blocked_range<size_t>& r, bool valid) {
        for (size_t k = r.begin(); k < r.end() && valid; ++k) {
          const Index n = vertices[k];
          valid = (x_new[n] - x_search_[n]).cwiseAbs().maxCoeff() <= margin_ &&
                  (x_old[n] - x_search_[n]).cwiseAbs().maxCoeff() <= margin_;
        }
        return valid;
      },
      [](bool a, bool b) { return a && b; });
  return dec_ ? dec_->max(valid ? 0 : 1) == 0 : valid;
}

void ContactStage::drifts(std::span<const Vec3> x_old, std::span<const Vec3> x_new, std::span<const Vec3> x_gap,
                          std::span<const Index> nodes) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const size_t count = nodes.empty() ? x_new.size() : nodes.size();
  scratch_.drift.resize(x_new.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const Index n = nodes.empty() ? static_cast<Index>(k) : nodes[k];
      const double d = std::max((x_new[n] - x_gap[n]).cwiseAbs().maxCoeff(), (x_old[n] - x_gap[n]).cwiseAbs().maxCoeff());
      scratch_.drift[n] = std::isnan(d) ? inf : d;  // a NaN passes no screen
    }
  });
}

void ContactStage::search(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v) {
  if (dec_) {
    search_patch(x_old, x_new, v);
  } else {
    const double cpu0 = thread_cpu_seconds();
    pairs_ = find_candidates(surface_, inflated_boxes(surface_, x_old, x_new, margin_, reach_));
    std::erase_if(pairs_, [&](const ContactPair& p) { return excluded(p); });
    profile_.search_cpu_seconds += thread_cpu_seconds() - cpu0;
  }
  x_search_.assign(x_new.begin(), x_new.end());
  have_candidates_ = true;
  ++profile_.searches;
}

void ContactStage::exchange(std::span<const Vec3> x_old, std::span<const Vec3> x_new, std::span<const Vec3> v,
                            PatchPlan plan) {
  const auto t0 = std::chrono::steady_clock::now();
  const long bytes = patch_->exchange(x_old, x_new, v, plan);
  profile_.exchange_bytes += bytes;
  profile_.state_bytes += bytes;
  profile_.exchange_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Ownership rule: a candidate belongs to the rank of its face (vertex-face) or of
// its first edge (edge-edge). A primitive has two weights, balanced together by a
// multi-criteria RCB: 1 (the search's work, per primitive) and its number of
// candidates + 0.01 (the filter's work, and a bound on DCR's; balanced alone,
// one rank of two held 60 % of the 76 cubes' triangles and searched 1.3x
// longer than the other). Before the first partition a primitive
// belongs to its first owner (first_owned). The primitives are
// re-partitioned at a search (i.e. when the surface moved past the reuse margin)
// if the surface was rebuilt, or if the candidates per rank are out of balance by
// more than 10 % (largest over mean), and then searched again.
void ContactStage::search_patch(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v) {
  if (!patch_->owned_any()) own(first_owned());
  // The owned primitives' states start the search (their boxes, the reach).
  exchange(x_old, x_new, v, PatchPlan::Owned);
  for (bool repartitioned = false;; repartitioned = true) {
    if (repartition_) {
      partition();
      exchange(x_old, x_new, v, PatchPlan::Owned);
      repartition_ = false;
      ++profile_.repartitions;
    }
    patch_->reach(x_old, x_new, margin_);
    exchange(x_old, x_new, v, PatchPlan::Patch);
    const double cpu0 = thread_cpu_seconds();
    // The pairs of this rank's primitives (the patch's triangles are all its own; the pairs of
    // a ghost first edge are another rank's), counted per primitive (the weights).
    const OwnedPairs found =
        find_owned_candidates(patch_->patch(), patch_->patch_boxes(margin_), patch_->patch_edges_owned());
    pairs_.clear();
    std::fill(weight_.begin(), weight_.end(), 0.0f);
    for (size_t k = 0; k < found.pairs.size(); ++k) {
      if (excluded(found.pairs[k])) continue;
      pairs_.push_back(found.pairs[k]);
      weight_[patch_->owned_primitive(found.primitive[k])] += 1.0f;
    }
    profile_.search_cpu_seconds += thread_cpu_seconds() - cpu0;
    const long mine = static_cast<long>(pairs_.size());
    const long most = dec_->max(mine), total = dec_->sum(std::vector<long>{mine})[0];
    if (repartitioned || most * dec_->size() <= 1.1 * static_cast<double>(total)) break;
    repartition_ = true;
  }
  patch_->activate(pairs_);
  exchange(x_old, x_new, v, PatchPlan::Active);
  profile_.known_vertices_max = std::max<long>(profile_.known_vertices_max, patch_->known_vertices());
}

NamedTriangle ContactStage::named_triangle(Index t) const {
  const auto& n = surface_.triangles[t];
  const std::span<const Index> whole = vertices_.whole;
  const std::span<const int> owner = vertices_.owner;
  const auto twin = [&](Index v) { return vertices_.twin.empty() ? whole[v] : vertices_.twin[v]; };
  return {{t, 0, 0},
          {whole[n[0]], whole[n[1]], whole[n[2]]},
          {owner[n[0]], owner[n[1]], owner[n[2]]},
          {twin(n[0]), twin(n[1]), twin(n[2])},
          surface_.body[t]};
}

NamedSurface ContactStage::first_owned() const {
  if (model_.is_part()) return owned_surface(model_, *dec_, bonded());
  // A whole model on ranks (shells): each primitive by the volume owner of its first node.
  const auto twin = [&](Index v) { return vertices_.twin.empty() ? vertices_.whole[v] : vertices_.twin[v]; };
  NamedSurface owned;
  for (Index t = 0; t < surface_.num_triangles(); ++t)
    if (vertices_.owner[surface_.triangles[t][0]] == dec_->rank()) owned.triangles.push_back(named_triangle(t));
  for (const auto& [a, b] : surface_.edges)
    if (vertices_.owner[a] == dec_->rank())
      owned.edges.push_back({{vertices_.whole[a], vertices_.whole[b]},
                             {vertices_.owner[a], vertices_.owner[b]},
                             {twin(a), twin(b)},
                             vertices_.body[a]});
  return owned;
}

std::vector<NamedTriangle> ContactStage::home_triangles() const {
  if (model_.is_part()) return shatter::home_triangles(model_, *dec_, bonded());
  std::vector<NamedTriangle> home;
  const auto mine = [&](Index v) { return vertices_.owner[v] == dec_->rank(); };
  for (Index t = 0; t < surface_.num_triangles(); ++t) {
    const auto& n = surface_.triangles[t];
    if (mine(n[0]) || mine(n[1]) || mine(n[2])) home.push_back(named_triangle(t));
  }
  return home;
}

void ContactStage::partition() {
  // Each primitive as its name (4 words: kind, then a triangle's name or an edge's nodes),
  // its centre at the patch's x(n+1) and its weights.
  const ContactSurface& at = patch_->owned();
  const std::span<const Vec3> x = patch_->x_new();
  const size_t nt = owned_.triangles.size(), ne = owned_.edges.size();
  std::vector<Index> names;
  std::vector<Vec3> points;
  std::vector<float> weights;
  for (size_t k = 0; k < nt; ++k) {
    const auto& n = at.triangles[k];
    names.insert(names.end(), {0, owned_.triangles[k].name[0], owned_.triangles[k].name[1], owned_.triangles[k].name[2]});
    points.push_back((x[n[0]] + x[n[1]] + x[n[2]]) / 3.0);
  }
  for (size_t k = 0; k < ne; ++k) {
    const auto& n = at.edges[k];
    names.insert(names.end(), {1, owned_.edges[k].nodes[0], owned_.edges[k].nodes[1], 0});
    points.push_back(0.5 * (x[n[0]] + x[n[1]]));
  }
  for (const float w : weight_) weights.insert(weights.end(), {1.0f, 0.01f + w});
  // Each primitive's home: the volume owner of most of its nodes (of its first node on a tie).
  std::vector<int> homes;
  for (const NamedTriangle& t : owned_.triangles) {
    const auto& o = t.owner;
    homes.push_back(o[1] == o[2] && o[1] != o[0] ? o[1] : o[0]);
  }
  for (const NamedEdge& e : owned_.edges) homes.push_back(e.owner[0]);
  const std::vector<int> to = partition_->partition(names, points, weights, homes);
  // The primitives that leave go to their new ranks with their data (kind 0 and a triangle's
  // words, or kind 1 and an edge's: append_words).
  const int me = dec_->rank();
  NamedSurface kept;
  std::vector<std::vector<Index>> out(dec_->size());
  for (size_t k = 0; k < nt; ++k) {
    const NamedTriangle& t = owned_.triangles[k];
    if (to[k] == me) {
      kept.triangles.push_back(t);
    } else {
      out[to[k]].push_back(0);
      append_words(t, out[to[k]]);
    }
  }
  for (size_t k = 0; k < ne; ++k) {
    if (to[nt + k] == me) {
      kept.edges.push_back(owned_.edges[k]);
    } else {
      out[to[nt + k]].push_back(1);
      append_words(owned_.edges[k], out[to[nt + k]]);
    }
  }
  for (const auto& list : dec_->alltoall(out))
    for (size_t i = 0; i < list.size();)
      if (list[i] == 0) {
        kept.triangles.push_back(read_triangle(&list[i + 1]));
        i += 1 + kNamedTriangleWords;
      } else {
        kept.edges.push_back(read_edge(&list[i + 1]));
        i += 1 + kNamedEdgeWords;
      }
  std::sort(kept.triangles.begin(), kept.triangles.end(),
            [](const NamedTriangle& a, const NamedTriangle& b) { return a.name < b.name; });
  std::sort(kept.edges.begin(), kept.edges.end(),
            [](const NamedEdge& a, const NamedEdge& b) { return a.nodes < b.nodes; });
  const long before = static_cast<long>(nt + ne), after = static_cast<long>(kept.triangles.size() + kept.edges.size());
  const std::vector<long> sums = dec_->sum(std::vector<long>{before, after});
  SHATTER_REQUIRE(sums[0] == sums[1], "ContactStage: " << sums[0] << " primitives before RCB, " << sums[1] << " after");
  own(std::move(kept));
}

void ContactStage::own(NamedSurface primitives) {
  owned_ = std::move(primitives);
  weight_.assign(owned_.triangles.size() + owned_.edges.size(), 0.0f);
  patch_->own(owned_);
}

std::vector<std::int32_t> ContactStage::patch_rigid_bodies(const DcrRigidBodies& rigid) const {
  // A rigid body's surface nodes are kept (ContactPatch): every part holds their rows. A
  // node the part does not hold is a deformable body's.
  std::vector<std::int32_t> body(patch_->num_nodes(), -1);
  for (Index k = 0; k < patch_->num_nodes(); ++k)
    if (const Index n = patch_->part_node(k); n >= 0) body[k] = rigid.node_body[n];
  return body;
}

ContactBalance ContactStage::balance() const {
  const ContactProfile& p = profile_;
  ContactBalance b{p.owned_pairs,     p.owned_pairs, p.owned_pairs,        p.candidates,
                   p.states_posted,   p.state_bytes, p.found_bytes,        p.search_cpu_seconds,
                   p.sweep_cpu_seconds, whole_surface_bytes(), p.known_vertices_max,
                   surface_.num_triangles()};
  // On parts each triangle is owned by one rank (before the first search since the surface
  // was built, by its first owner); a whole model's count is every rank's.
  const bool by_owners = model_.is_part();
  if (by_owners)
    b.triangles = static_cast<long>(patch_->owned_any() ? owned_.triangles.size() : first_owned().triangles.size());
  if (dec_) {
    long most[6] = {-b.pairs_min,       b.pairs_max,         b.state_bytes_max, b.found_bytes_max,
                    b.whole_surface_bytes_max, b.known_vertices_max},
         sum[4] = {b.pairs_sum, b.candidates_sum, b.states_posted_sum,
                   by_owners ? b.triangles : 0};
    double cpu[2] = {b.search_cpu_max, b.sweep_cpu_max};
    MPI_Allreduce(MPI_IN_PLACE, most, 6, MPI_LONG, MPI_MAX, dec_->comm());
    MPI_Allreduce(MPI_IN_PLACE, sum, 4, MPI_LONG, MPI_SUM, dec_->comm());
    MPI_Allreduce(MPI_IN_PLACE, cpu, 2, MPI_DOUBLE, MPI_MAX, dec_->comm());
    b = {-most[0], most[1], sum[0], sum[1], sum[2], most[2], most[3], cpu[0], cpu[1], most[4], most[5],
         by_owners ? sum[3] : b.triangles};
  }
  return b;
}

long ContactStage::whole_surface_bytes() const {
  auto b = [](const auto& v) { return static_cast<long>(v.capacity() * sizeof(v[0])); };
  return b(surface_.triangles) + b(surface_.body) + b(surface_.edges) + b(surface_.vertices) +
         b(vertex_triangles_.offsets) + b(vertex_triangles_.items) + b(vertex_triangles_.position) +
         (model_.is_part() ? 0
                           : b(whole_tables_.whole) + b(whole_tables_.owner) + b(whole_tables_.body) +
                                 b(whole_tables_.twin) + b(vertices_.node)) +
         b(node_body_) + b(twin_of_);
}

std::optional<ContactPair> ContactStage::first_unresolved(const std::optional<ContactPair>& mine) {
  // Each rank's first pair (kind, whole ids of its nodes, their bodies and positions) to
  // every rank.
  constexpr size_t kWords = 9 + 12;
  std::vector<double> out;
  if (mine) {
    const std::span<const Vec3> at = patch_->x_new();
    out.push_back(mine->kind);
    for (const Index k : mine->nodes) out.push_back(patch_->whole(k));
    for (const Index k : mine->nodes) out.push_back(patch_->body(k));
    for (const Index k : mine->nodes) out.insert(out.end(), at[k].data(), at[k].data() + 3);
  }
  const std::vector<double> all = dec_->allgather(out);
  std::optional<ContactPair> first;
  size_t at_first = 0;
  for (size_t at = 0; at < all.size(); at += kWords) {
    ContactPair p{static_cast<ContactPair::Kind>(all[at]), {}};
    for (int c = 0; c < 4; ++c) p.nodes[c] = static_cast<Index>(all[at + 1 + c]);
    if (!first || p < *first) first = p, at_first = at;
  }
  if (!first) return first;
  // Its name: the bodies are known here, each node's id (node_gid) to its owner.
  UnresolvedPair& u = unresolved_.emplace();
  u.kind = first->kind;
  std::array<long, 4> gid{};
  for (int c = 0; c < 4; ++c) {
    u.body[c] = static_cast<int>(all[at_first + 5 + c]);
    const std::span<const Index> held = vertices_.whole;
    const auto it = std::lower_bound(held.begin(), held.end(), first->nodes[c]);
    const Index n = it != held.end() && *it == first->nodes[c] ? vertices_.node[it - held.begin()] : -1;
    gid[c] = n >= 0 && dec_->owns_node(n) ? model_.mesh.node_gid[n] : -1;
    u.x[c] = Vec3(all[at_first + 9 + 3 * c], all[at_first + 10 + 3 * c], all[at_first + 11 + 3 * c]);
  }
  MPI_Allreduce(MPI_IN_PLACE, gid.data(), 4, MPI_LONG, MPI_MAX, dec_->comm());
  for (int c = 0; c < 4; ++c) u.gid[c] = gid[c];
  return first;
}

ContactPairs ContactStage::active_pairs() const {
  const std::vector<Index>& kept = scratch_.overlapping;
  ContactPairs out(kept.size());
  for (size_t k = 0; k < kept.size(); ++k) out[k] = dec_ ? whole_pair(pairs_[kept[k]]) : pairs_[kept[k]];
  return out;
}

ContactPair ContactStage::whole_pair(ContactPair p) const {
  for (Index& n : p.nodes) n = patch_->whole(n);
  return p;
}

DcrResult ContactStage::apply(std::span<Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v,
                              std::span<const double> inv_mass, double dt, std::span<const std::uint8_t> held,
                              const DcrRigidBodies* rigid) {
  using clock = std::chrono::steady_clock;
  // Each phase's wall time, less the exchanges within it (counted apart).
  auto lap = [this, last = clock::now(), exchanged = profile_.exchange_seconds](double& seconds) mutable {
    const auto now = clock::now();
    seconds += std::chrono::duration<double>(now - last).count() - (profile_.exchange_seconds - exchanged);
    last = now;
    exchanged = profile_.exchange_seconds;
  };
  // The reuse check reads the owned surface vertices; the candidates' states come after it
  // (a search brings them itself).
  if (dec_) patch_->load(x_old, x_new, v, inv_mass, held, dt);
  const bool valid = candidates_valid(x_old, x_new);
  if (dec_ && valid) exchange(x_old, x_new, v, PatchPlan::Active);
  lap(profile_.verlet_seconds);
  if (!valid) search(x_old, x_new, v);
  lap(profile_.search_seconds);
  const double cpu0 = thread_cpu_seconds();
  const long bytes0 = dec_ ? ranks_->bytes() : 0, posted0 = dec_ ? ranks_->posted() : 0;
  const double wait0 = dec_ ? ranks_->seconds() : 0, wait_cpu0 = dec_ ? ranks_->cpu_seconds() : 0;
  DcrResult r;
  double wait_cpu = 0;
  unresolved_.reset();
  if (dec_) {
    // DCR on the patch's nodes.
    std::vector<std::int32_t> rigid_body;
    DcrRigidBodies patch_rigid;
    if (rigid) rigid_body = patch_rigid_bodies(*rigid), patch_rigid = {rigid_body, rigid->bodies};
    const DcrSurface surface{&patch_->normals(), &patch_->normals_around(), {}, patch_->node_reach()};
    if (!valid) {
      scratch_.gaps = pair_gaps(pairs_, patch_->x_new(), surface);
      gap_x_.assign(patch_->x_new().begin(), patch_->x_new().end());
    }
    drifts(patch_->x_old(), patch_->x_new(), gap_x_, {});
    r = resolve_contacts(pairs_, patch_->x_new(), patch_->x_old(), patch_->v(), patch_->inv_mass(), dt, options_,
                         surface, scratch_, ranks_.get(), patch_->held(), rigid ? &patch_rigid : nullptr);
    patch_->store(x_old, x_new, v);
    const long bytes = ranks_->bytes() - bytes0;
    profile_.exchange_bytes += bytes;
    profile_.found_bytes += bytes;
    profile_.states_posted += ranks_->posted() - posted0;
    profile_.exchange_seconds += ranks_->seconds() - wait0;
    wait_cpu = ranks_->cpu_seconds() - wait_cpu0;
    if (r.capped) r.unresolved = first_unresolved(r.unresolved);
  } else {
    const DcrSurface surface{&surface_, &vertex_triangles_, {}, reach_};
    if (!valid) scratch_.gaps = pair_gaps(pairs_, x_new, surface);
    drifts(x_old, x_new, x_search_, surface_.vertices);
    r = resolve_contacts(pairs_, x_new, x_old, v, inv_mass, dt, options_, surface, scratch_, nullptr, held, rigid);
    if (r.unresolved) {
      UnresolvedPair& u = unresolved_.emplace();
      u.kind = r.unresolved->kind;
      for (int c = 0; c < 4; ++c) {
        const Index n = r.unresolved->nodes[c];
        u.gid[c] = model_.mesh.node_gid[n], u.body[c] = model_.mesh.node_body[n], u.x[c] = x_new[n];
      }
    }
  }
  lap(profile_.sweep_seconds);
  profile_.sweep_cpu_seconds += thread_cpu_seconds() - cpu0 - wait_cpu;
  ++profile_.steps;
  profile_.candidates += static_cast<long>(pairs_.size());
  profile_.owned_pairs += static_cast<long>(scratch_.overlapping.size());
  profile_.detections += r.detected;
  profile_.sweeps += r.sweeps;
  return r;
}

}  // namespace shatter
