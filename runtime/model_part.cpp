#include "runtime/model_part.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <functional>

#include "kernels/error.hpp"
#include "mesh/topology.hpp"
#include "contact/surface.hpp"
#include "mesh/partition.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/element_forces.hpp"
#include "runtime/key_positions.hpp"
#include "runtime/loads.hpp"

namespace shatter {
namespace {

constexpr int kTag = 7311;
constexpr std::uint64_t kChunk = std::uint64_t{1} << 30;  // MPI counts are int

/// The partition of the whole model every part is cut from.
struct Partition {
  std::vector<int> granule_rank, block_color;
  NodeRanks touch;
  std::vector<Index> bc_index;  ///< per node: its rank among the nodes with a prescribed component
  Index bc_nodes = 0;
  // Contact scenes: of the whole model's surface (Model::Part), its median edge, and the rigid
  // bodies' surface nodes (which every part holds) with their owners.
  double surface_edge = 0;
  std::vector<Index> rigid_surface_nodes;
  std::vector<int> rigid_surface_owners;
};

Partition partition(const Model& whole, int ranks) {
  Partition p;
  const Mesh& mesh = whole.mesh;
  p.granule_rank = partition_granules(mesh, ElementForces::kGranule, ranks);
  p.block_color = block_colors(mesh);
  p.touch = granule_touching_ranks(mesh, p.granule_rank);
  p.bc_index.assign(mesh.num_nodes(), -1);
  for (Index n = 0; n < mesh.num_nodes(); ++n)
    if (whole.bc_mask[n]) p.bc_index[n] = p.bc_nodes++;
  if (!whole.scene.contact) return p;
  const ContactSurface surface = build_contact_surface(mesh);
  p.surface_edge = median_edge_length(surface, mesh.reference);
  for (const Index n : surface.vertices)
    if (whole.scene.bodies[mesh.node_body[n]].has_rigid_state()) {
      p.rigid_surface_nodes.push_back(n);
      p.rigid_surface_owners.push_back(p.touch.of(n)[0]);
    }
  return p;
}

/// The elements each rank holds, ascending: its owned ones and their ghost
/// layer (every element with a node it touches), and with `two_layers` the
/// elements sharing a node with those. A few passes over the mesh.
std::vector<std::vector<Index>> held_elements(const Mesh& wm, const NodeRanks& touch, int ranks, bool two_layers) {
  const Index ne = wm.num_elements(), nn = wm.num_nodes();
  const int k = wm.nodes_per_element();
  // (CSR of ranks per element or node, each list ascending.)
  auto gather = [&](Index count, auto lists_of) {
    NodeRanks out;
    out.offsets.assign(1, 0);
    std::vector<int> rs;
    for (Index i = 0; i < count; ++i) {
      rs.clear();
      lists_of(i, rs);
      std::sort(rs.begin(), rs.end());
      rs.erase(std::unique(rs.begin(), rs.end()), rs.end());
      out.ranks.insert(out.ranks.end(), rs.begin(), rs.end());
      out.offsets.push_back(static_cast<Index>(out.ranks.size()));
    }
    return out;
  };
  // The ranks whose first layer holds each element.
  NodeRanks layer = gather(ne, [&](Index e, std::vector<int>& rs) {
    for (int a = 0; a < k; ++a)
      for (int q : touch.of(wm.element(e)[a])) rs.push_back(q);
  });
  if (two_layers) {
    // Those holding an element of each node's star, then each element's.
    const NodeRanks star = gather(nn, [&](Index n, std::vector<int>& rs) {
      for (Index e : node_star(wm, n))
        for (int q : layer.of(e)) rs.push_back(q);
    });
    layer = gather(ne, [&](Index e, std::vector<int>& rs) {
      for (int a = 0; a < k; ++a)
        for (int q : star.of(wm.element(e)[a])) rs.push_back(q);
    });
  }
  std::vector<std::vector<Index>> held(ranks);
  for (Index e = 0; e < ne; ++e)
    for (int q : layer.of(e)) held[q].push_back(e);
  return held;
}

/// Rank r's part of `whole` (without scene and materials), from the
/// elements it holds. `local`: scratch of one entry per whole node, -1 on
/// entry and on return.
Model cut(const Model& whole, const Partition& p, std::vector<Index> elements, std::vector<Index>& local) {
  const Mesh& wm = whole.mesh;
  const bool two_layers = whole.scene.fracture_enabled();
  const int k = wm.nodes_per_element();
  Model m;
  Model::Part& part = m.part;
  part.element_index = std::move(elements);
  for (Index e : part.element_index)
    for (int a = 0; a < k; ++a) part.node_index.push_back(wm.element(e)[a]);
  part.node_index.insert(part.node_index.end(), p.rigid_surface_nodes.begin(), p.rigid_surface_nodes.end());
  std::sort(part.node_index.begin(), part.node_index.end());
  part.node_index.erase(std::unique(part.node_index.begin(), part.node_index.end()), part.node_index.end());
  for (size_t i = 0; i < part.node_index.size(); ++i) local[part.node_index[i]] = static_cast<Index>(i);

  Mesh& mesh = m.mesh;
  mesh.order = wm.order;
  mesh.revision = wm.revision;
  for (Index n : part.node_index) {
    append_node_row(m, whole, n);
    if (whole.bc_mask[n]) part.bc_index.push_back(p.bc_index[n]);
    if (two_layers) continue;
    part.node_rank_offsets.push_back(static_cast<Index>(part.node_ranks.size()));
    for (int q : p.touch.of(n)) part.node_ranks.push_back(q);
  }
  if (!two_layers) part.node_rank_offsets.push_back(static_cast<Index>(part.node_ranks.size()));
  Index last_block = -1;
  for (Index e : part.element_index) {
    for (int a = 0; a < k; ++a) {
      mesh.conn.push_back(local[wm.element(e)[a]]);
      m.element_node_mass.push_back(whole.element_node_mass[static_cast<size_t>(e) * k + a]);
    }
    mesh.elem_gid.push_back(wm.elem_gid[e]);
    mesh.elem_body.push_back(wm.elem_body[e]);
    mesh.elem_material.push_back(wm.elem_material[e]);
    m.element_volume.push_back(whole.element_volume[e]);
    if (wm.order == 1) m.tet4_Dm_inv.push_back(whole.tet4_Dm_inv[e]);
    else m.tet10_ref.push_back(whole.tet10_ref[e]);
    if (e / ElementForces::kBlock != last_block) {
      last_block = e / ElementForces::kBlock;
      part.block_color.push_back(p.block_color[last_block]);
    }
  }
  mesh.build_node_elements();
  m.load_faces = held_load_faces(whole.load_faces, part.element_index);
  part.rigid_surface_node = p.rigid_surface_nodes;
  part.rigid_surface_owner = p.rigid_surface_owners;
  part.surface_edge = p.surface_edge;
  m.body_mass = whole.body_mass;
  m.body_volume = whole.body_volume;
  for (Index n : part.node_index) local[n] = -1;
  part.granule_rank = p.granule_rank;
  part.whole_elements = wm.num_elements();
  part.whole_nodes = wm.num_nodes();
  part.whole_bc_nodes = p.bc_nodes;
  part.fingerprint = model_fingerprint(whole);
  return m;
}

void send_bytes(const void* data, std::uint64_t bytes, int dest, MPI_Comm comm) {
  for (std::uint64_t at = 0; at < bytes; at += kChunk)
    MPI_Send(static_cast<const char*>(data) + at, static_cast<int>(std::min(kChunk, bytes - at)), MPI_BYTE, dest,
             kTag, comm);
}

void receive_bytes(void* data, std::uint64_t bytes, MPI_Comm comm) {
  for (std::uint64_t at = 0; at < bytes; at += kChunk)
    MPI_Recv(static_cast<char*>(data) + at, static_cast<int>(std::min(kChunk, bytes - at)), MPI_BYTE, 0, kTag,
             comm, MPI_STATUS_IGNORE);
}

}  // namespace

void cut_parts(const Model& whole, int ranks, const std::function<void(int, Model&&)>& each) {
  const Partition p = partition(whole, ranks);
  std::vector<std::vector<Index>> held = held_elements(whole.mesh, p.touch, ranks, whole.scene.fracture_enabled());
  std::vector<Index> local(whole.mesh.num_nodes(), -1);
  // Rank 0's part last: the start-up rank keeps its own part only once the others are gone.
  for (int k = 1; k <= ranks; ++k) each(k % ranks, cut(whole, p, std::move(held[k % ranks]), local));
}

void put_part(const Model& m, const std::function<void(const void*, std::uint64_t)>& put) {
  const std::uint64_t head[7] = {static_cast<std::uint64_t>(m.mesh.order), m.mesh.revision,
                                 static_cast<std::uint64_t>(m.part.whole_elements),
                                 static_cast<std::uint64_t>(m.part.whole_nodes),
                                 static_cast<std::uint64_t>(m.part.whole_bc_nodes), m.part.fingerprint,
                                 std::bit_cast<std::uint64_t>(m.part.surface_edge)};
  put(head, sizeof head);
  for_each_array(m, [&](const auto& v) {
    const std::uint64_t n = v.size();
    put(&n, sizeof n);
    put(v.data(), n * sizeof(v[0]));
  });
}

bool get_part(Model& m, std::uint64_t limit, const std::function<void(void*, std::uint64_t)>& get) {
  std::uint64_t head[7];
  if (limit < sizeof head) return false;
  get(head, sizeof head);
  limit -= sizeof head;
  m.mesh.order = static_cast<int>(head[0]);
  m.mesh.revision = head[1];
  m.part.whole_elements = static_cast<Index>(head[2]);
  m.part.whole_nodes = static_cast<Index>(head[3]);
  m.part.whole_bc_nodes = static_cast<Index>(head[4]);
  m.part.fingerprint = head[5];
  m.part.surface_edge = std::bit_cast<double>(head[6]);
  bool fits = true;
  for_each_array(m, [&](auto& v) {
    std::uint64_t n = 0;
    if (!fits || limit < sizeof n) return void(fits = false);
    get(&n, sizeof n);
    limit -= sizeof n;
    if (n > limit / sizeof(v[0])) return void(fits = false);
    v.resize(n);
    get(v.data(), n * sizeof(v[0]));
    limit -= n * sizeof(v[0]);
  });
  return fits;
}

Index number_split_nodes(Model& m, Index first, std::uint64_t revision, const Decomposition& dec) {
  Mesh& mesh = m.mesh;
  Model::Part& part = m.part;
  const Index nn = mesh.num_nodes();
  SHATTER_REQUIRE(m.bc_mask.size() == static_cast<size_t>(nn), "number_split_nodes: the model's node arrays are not grown");
  auto owner = [&](Index n) {
    int r = dec.size();
    for (Index e : node_star(mesh, n)) r = std::min(r, dec.element_rank(e));
    return r;
  };
  // Names, doubled, plus one for a copy with a prescribed component.
  auto key = [&](Index n) { return 2 * mesh.node_gid[n] + (m.bc_mask[n] ? 1 : 0); };
  // Every rank names the copies it holds; each is numbered by its owner's name.
  std::vector<GlobalId> mine, names, mine_held, names_held;  // (held: the prescribed ones)
  for (Index n = first; n < nn; ++n) {
    const bool owned = owner(n) == dec.rank();
    names.push_back(key(n));
    if (owned) mine.push_back(key(n));
    if (!m.bc_mask[n]) continue;
    names_held.push_back(key(n));
    if (owned) mine_held.push_back(key(n));
  }
  const KeyPositions all = key_positions(mine, names, dec), held = key_positions(mine_held, names_held, dec);
  size_t h = 0;
  for (Index n = first; n < nn; ++n) {
    const Index k = all.position[n - first];
    part.node_index.push_back(k >= 0 ? part.whole_nodes + k : -1);
    if (!m.bc_mask[n]) continue;
    const Index b = held.position[h++];
    part.bc_index.push_back(k >= 0 ? part.whole_bc_nodes + b : -1);
  }
  part.whole_nodes += all.total;
  part.whole_bc_nodes += held.total;
  // (The outer layer may have split alone: the whole model's revision, as fields.h5 writes it.)
  mesh.revision = revision + (all.total == 0 ? 0 : 1);
  return all.total;
}

void distribute_parts(Model& model, MPI_Comm comm) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  if (rank != 0) {
    get_part(model, ~std::uint64_t{0}, [&](void* data, std::uint64_t bytes) { receive_bytes(data, bytes, comm); });
    return;
  }
  Model mine;
  cut_parts(model, ranks, [&](int r, Model&& part) {
    if (r == 0) return void(mine = std::move(part));
    put_part(part, [&](const void* data, std::uint64_t bytes) { send_bytes(data, bytes, r, comm); });
  });
  // (cut() grows its arrays one push at a time; the received ones are exact.)
  for_each_array(mine, [](auto& v) { v.shrink_to_fit(); });
  mine.scene = std::move(model.scene);
  mine.materials = std::move(model.materials);
  model = std::move(mine);
}

}  // namespace shatter
