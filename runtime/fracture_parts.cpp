// FractureStage's state between the whole model and the ranks' parts
// (docs/parallel.md "Fracture on parts"): a checkpoint gathers the whole
// model's fracture state from the owners; at a restart on parts each part
// reads its own rows of it (read_checkpoint) and takes them in (part_of).
#include <algorithm>
#include <array>
#include <cstdint>
#include <tuple>
#include <type_traits>

#include "kernels/error.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/row_blocks.hpp"

namespace shatter {
namespace {

/// Values travel as doubles (integers below 2^53 exactly): put appends one, take
/// reads one and moves past it.
void put(std::vector<double>& to, const Vec3& v) { to.insert(to.end(), v.data(), v.data() + 3); }
void put(std::vector<double>& to, const std::array<std::int32_t, 3>& a) { to.insert(to.end(), a.begin(), a.end()); }
template <class T>
  requires std::is_arithmetic_v<T>
void put(std::vector<double>& to, T a) {
  to.push_back(static_cast<double>(a));
}
void take(const double*& v, Vec3& x) { x = Vec3(v[0], v[1], v[2]), v += 3; }
void take(const double*& v, std::array<std::int32_t, 3>& a) {
  for (auto& c : a) c = static_cast<std::int32_t>(*v++);
}
template <class T>
  requires std::is_arithmetic_v<T>
void take(const double*& v, T& a) {
  a = static_cast<T>(*v++);
}

/// Per node, every array of node_arrays (FractureState): reference, node_gid,
/// node_body, mass, bc_mask, bc_velocity, bc_condition, initial_velocity.
constexpr int kNodeValues = 3 + 1 + 1 + 1 + 1 + 3 + 3 + 3;
/// Per cohesive element: facet gid and state, side_local and side_nodes
/// (whole ids), area, normal, delta_max.
constexpr int kCohesiveValues = 2 + 2 * kCohesiveSlots + 1 + 3 + kCohesivePoints;

}  // namespace

FractureState FractureStage::gather(const FractureState& mine) const {
  const Model& m = model_;
  const int k = m.mesh.nodes_per_element();
  const auto nodes = static_cast<Index>(mine.reference.size());
  const auto saved = static_cast<Index>(mine.cohesive_facet_gid.size());
  std::vector<Index> rows;
  std::vector<double> values;
  // Each node from its owner (it touches the node, whose star is whole here).
  for (Index n : dec_.touched_nodes()) {
    if (n >= nodes || dec_.node_owner(n) != dec_.rank()) continue;
    rows.push_back(m.whole_node(n));
    std::apply([&](const auto&... a) { (put(values, a[n]), ...); }, node_arrays(mine));
  }
  const std::vector<double> node_rows = to_root(rows, values, kNodeValues, mine.whole_nodes, dec_.comm());
  // Each element's nodes from its owner.
  rows.clear();
  values.clear();
  for (Index e : dec_.owned_element_ids()) {
    rows.push_back(m.whole_element(e));
    for (int a = 0; a < k; ++a) values.push_back(m.whole_node(mine.conn[static_cast<size_t>(e) * k + a]));
  }
  const std::vector<double> conn_rows = to_root(rows, values, k, m.whole_elements(), dec_.comm());
  // Each cohesive element from the owner of its facet's first element.
  rows.clear();
  values.clear();
  for (Index c = 0; c < saved; ++c) {
    const Index f = cohesive_.facet[c];
    if (!dec_.owns_element(topology_.facet_elem[f][0])) continue;
    rows.push_back(mine.cohesive_whole[c]);
    const GlobalId gid = mine.cohesive_facet_gid[c];
    const auto at = std::lower_bound(mine.facet_gid.begin(), mine.facet_gid.end(), gid) - mine.facet_gid.begin();
    values.insert(values.end(), {static_cast<double>(gid), static_cast<double>(mine.facet_state[at])});
    const size_t slots = static_cast<size_t>(c) * kCohesiveSlots;
    for (int j = 0; j < kCohesiveSlots; ++j) put(values, mine.cohesive.side_local[slots + j]);
    for (int j = 0; j < kCohesiveSlots; ++j) {
      const Index n = mine.cohesive.side_nodes[slots + j];
      put(values, n < 0 ? Index{-1} : m.whole_node(n));
    }
    put(values, mine.cohesive.area[c]);
    put(values, mine.cohesive.normal[c]);
    for (int q = 0; q < kCohesivePoints; ++q) put(values, mine.cohesive.delta_max[static_cast<size_t>(c) * kCohesivePoints + q]);
  }
  const std::vector<double> cohesive_rows =
      to_root(rows, values, kCohesiveValues, mine.whole_cohesive, dec_.comm());

  FractureState w;
  if (dec_.rank() != 0) return w;
  w.mesh_revision = mine.mesh_revision;
  w.whole_nodes = mine.whole_nodes;
  w.whole_cohesive = mine.whole_cohesive;
  const double* row = node_rows.data();
  for (Index n = 0; n < mine.whole_nodes; ++n)
    std::apply([&](auto&... a) { (take(row, a.emplace_back()), ...); }, node_arrays(w));
  for (double a : conn_rows) w.conn.push_back(static_cast<Index>(a));
  std::vector<std::pair<GlobalId, FacetState>> facets;
  for (Index c = 0; c < mine.whole_cohesive; ++c) {
    const double* r = cohesive_rows.data() + static_cast<size_t>(c) * kCohesiveValues;
    const auto gid = static_cast<GlobalId>(r[0]);
    facets.emplace_back(gid, static_cast<FacetState>(r[1]));
    r += 2;
    w.cohesive_facet_gid.push_back(gid);
    for (int j = 0; j < kCohesiveSlots; ++j) take(r, w.cohesive.side_local.emplace_back());
    for (int j = 0; j < kCohesiveSlots; ++j) take(r, w.cohesive.side_nodes.emplace_back());
    take(r, w.cohesive.area.emplace_back());
    take(r, w.cohesive.normal.emplace_back());
    for (int q = 0; q < kCohesivePoints; ++q) take(r, w.cohesive.delta_max.emplace_back());
    w.cohesive_whole.push_back(c);
  }
  // Every facet that is not intact has a cohesive element.
  std::sort(facets.begin(), facets.end());
  for (const auto& [gid, state] : facets) {
    w.facet_gid.push_back(gid);
    w.facet_state.push_back(state);
  }
  return w;
}

FractureState FractureStage::part_of(const FractureState& read) {
  const Mesh& mesh = model_.mesh;
  Model::Part& part = model_.part;
  const int k = mesh.nodes_per_element();
  const std::vector<Index>& nodes = read.node_rows;  // whole indices, ascending
  const size_t rn = nodes.size();
  SHATTER_REQUIRE(read.conn.size() == static_cast<size_t>(mesh.num_elements()) * k && read.reference.size() == rn &&
                      read.node_gid.size() == rn && read.node_body.size() == rn && read.mass.size() == rn &&
                      read.bc_mask.size() == rn && read.bc_velocity.size() == rn && read.bc_condition.size() == rn &&
                      read.initial_velocity.size() == rn &&
                      read.bc_rows.size() == static_cast<size_t>(std::count_if(read.bc_mask.begin(), read.bc_mask.end(),
                                                                               [](std::uint8_t m) { return m != 0; })),
                  "fracture state: a part's rows of " << rn << " nodes and " << read.conn.size() / k
                                                      << " elements do not fit its " << mesh.num_elements()
                                                      << " elements");
  auto local = [&](Index w) {
    const auto it = std::lower_bound(nodes.begin(), nodes.end(), w);
    return it != nodes.end() && *it == w ? static_cast<Index>(it - nodes.begin()) : Index{-1};
  };
  FractureState s;
  s.mesh_revision = read.mesh_revision;
  copy_node_arrays(s, read);
  for (Index w : read.conn) s.conn.push_back(local(w));
  part.node_index = nodes;
  part.bc_index = read.bc_rows;
  part.whole_nodes = read.whole_nodes;
  part.whole_bc_nodes = read.whole_bc_nodes;
  // The facets and cohesive elements held here.
  auto held = [&](GlobalId gid) { return !facets(std::span<const GlobalId>(&gid, 1)).empty(); };
  SHATTER_REQUIRE(
      read.facet_state.size() == read.facet_gid.size(),
      "fracture state: " << read.facet_gid.size() << " facet ids and " << read.facet_state.size() << " states");
  for (size_t i = 0; i < read.facet_gid.size(); ++i)
    if (held(read.facet_gid[i])) {
      s.facet_gid.push_back(read.facet_gid[i]);
      s.facet_state.push_back(read.facet_state[i]);
    }
  const CohesiveElements& c = read.cohesive;
  const size_t nc = read.cohesive_facet_gid.size();
  SHATTER_REQUIRE(read.cohesive_whole.size() == nc && c.side_local.size() == nc * kCohesiveSlots &&
                      c.side_nodes.size() == nc * kCohesiveSlots && c.area.size() == nc && c.normal.size() == nc &&
                      c.delta_max.size() == nc * kCohesivePoints,
                  "fracture state: the cohesive element arrays disagree in size");
  for (size_t i = 0; i < nc; ++i) {
    if (!held(read.cohesive_facet_gid[i])) continue;
    s.cohesive_facet_gid.push_back(read.cohesive_facet_gid[i]);
    s.cohesive_whole.push_back(read.cohesive_whole[i]);
    for (int j = 0; j < kCohesiveSlots; ++j) {
      s.cohesive.side_local.push_back(c.side_local[i * kCohesiveSlots + j]);
      const Index w = c.side_nodes[i * kCohesiveSlots + j];
      SHATTER_REQUIRE(w >= -1 && (w < 0 || local(w) >= 0),
                      "fracture state: side node " << w << " is not a node of the facet's elements");
      s.cohesive.side_nodes.push_back(w < 0 ? -1 : local(w));
    }
    s.cohesive.area.push_back(c.area[i]);
    s.cohesive.normal.push_back(c.normal[i]);
    s.cohesive.delta_max.insert(s.cohesive.delta_max.end(), c.delta_max.begin() + i * kCohesivePoints,
                                c.delta_max.begin() + (i + 1) * kCohesivePoints);
  }
  s.whole_nodes = read.whole_nodes;
  s.whole_cohesive = read.whole_cohesive;
  return s;
}

}  // namespace shatter
