// FractureStage's state between the whole model and the ranks' parts
// (docs/parallel.md "Fracture on parts"): a checkpoint gathers the whole
// model's fracture state from the owners; a restart on parts gives each part
// its share of it.
#include <algorithm>

#include "kernels/error.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/row_blocks.hpp"

namespace shatter {
namespace {

/// Per node: reference, bc_velocity, initial_velocity, mass, node_gid,
/// node_body, bc_mask, bc_condition (integers below 2^53 travel exactly as doubles).
constexpr int kNodeValues = 16;
/// Per cohesive element: facet gid and state, side_local and side_nodes
/// (whole ids), area, normal, delta_max.
constexpr int kCohesiveValues = 2 + 2 * kCohesiveSlots + 1 + 3 + kCohesivePoints;

void append(std::vector<double>& to, const Vec3& v) { to.insert(to.end(), v.data(), v.data() + 3); }
Vec3 vec3(const double* v) { return Vec3(v[0], v[1], v[2]); }

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
    append(values, mine.reference[n]);
    append(values, mine.bc_velocity[n]);
    append(values, mine.initial_velocity[n]);
    values.insert(values.end(), {mine.mass[n], static_cast<double>(mine.node_gid[n]),
                                 static_cast<double>(mine.node_body[n]), static_cast<double>(mine.bc_mask[n])});
    for (int c = 0; c < 3; ++c) values.push_back(mine.bc_condition[n][c]);
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
    for (int j = 0; j < kCohesiveSlots; ++j) values.push_back(mine.cohesive.side_local[slots + j]);
    for (int j = 0; j < kCohesiveSlots; ++j) {
      const Index n = mine.cohesive.side_nodes[slots + j];
      values.push_back(n < 0 ? -1.0 : static_cast<double>(m.whole_node(n)));
    }
    values.push_back(mine.cohesive.area[c]);
    append(values, mine.cohesive.normal[c]);
    const double* d = mine.cohesive.delta_max.data() + static_cast<size_t>(c) * kCohesivePoints;
    values.insert(values.end(), d, d + kCohesivePoints);
  }
  const std::vector<double> cohesive_rows =
      to_root(rows, values, kCohesiveValues, mine.whole_cohesive, dec_.comm());

  FractureState w;
  if (dec_.rank() != 0) return w;
  w.mesh_revision = mine.mesh_revision;
  w.whole_nodes = mine.whole_nodes;
  w.whole_cohesive = mine.whole_cohesive;
  for (Index n = 0; n < mine.whole_nodes; ++n) {
    const double* v = node_rows.data() + static_cast<size_t>(n) * kNodeValues;
    w.reference.push_back(vec3(v));
    w.bc_velocity.push_back(vec3(v + 3));
    w.initial_velocity.push_back(vec3(v + 6));
    w.mass.push_back(v[9]);
    w.node_gid.push_back(static_cast<GlobalId>(v[10]));
    w.node_body.push_back(static_cast<int>(v[11]));
    w.bc_mask.push_back(static_cast<std::uint8_t>(v[12]));
    w.bc_condition.push_back(
        {static_cast<std::int32_t>(v[13]), static_cast<std::int32_t>(v[14]), static_cast<std::int32_t>(v[15])});
  }
  for (double a : conn_rows) w.conn.push_back(static_cast<Index>(a));
  std::vector<std::pair<GlobalId, FacetState>> facets;
  for (Index c = 0; c < mine.whole_cohesive; ++c) {
    const double* v = cohesive_rows.data() + static_cast<size_t>(c) * kCohesiveValues;
    const auto gid = static_cast<GlobalId>(v[0]);
    facets.emplace_back(gid, static_cast<FacetState>(v[1]));
    w.cohesive_facet_gid.push_back(gid);
    for (int j = 0; j < kCohesiveSlots; ++j) w.cohesive.side_local.push_back(static_cast<std::int8_t>(v[2 + j]));
    for (int j = 0; j < kCohesiveSlots; ++j) w.cohesive.side_nodes.push_back(static_cast<Index>(v[2 + kCohesiveSlots + j]));
    const double* rest = v + 2 + 2 * kCohesiveSlots;
    w.cohesive.area.push_back(rest[0]);
    w.cohesive.normal.push_back(vec3(rest + 1));
    w.cohesive.delta_max.insert(w.cohesive.delta_max.end(), rest + 4, rest + 4 + kCohesivePoints);
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

FractureState FractureStage::part_of(const FractureState& whole) {
  const Mesh& mesh = model_.mesh;
  Model::Part& part = model_.part;
  const int k = mesh.nodes_per_element();
  const size_t wn = whole.reference.size();
  SHATTER_REQUIRE(whole.conn.size() == static_cast<size_t>(model_.whole_elements()) * k && whole.node_gid.size() == wn &&
                      whole.node_body.size() == wn && whole.mass.size() == wn && whole.bc_mask.size() == wn &&
                      whole.bc_velocity.size() == wn && whole.bc_condition.size() == wn &&
                      whole.initial_velocity.size() == wn,
                  "fracture state: node arrays of " << wn << " nodes and " << whole.conn.size() / k
                                                    << " elements do not fit the model ("
                                                    << model_.whole_elements() << " elements)");
  // The part's nodes: those of its elements, ascending by whole index.
  std::vector<Index> nodes;
  for (Index e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < k; ++a) {
      const Index w = whole.conn[static_cast<size_t>(model_.whole_element(e)) * k + a];
      SHATTER_REQUIRE(w >= 0 && static_cast<size_t>(w) < wn, "fracture state: node " << w << " in conn is out of range");
      nodes.push_back(w);
    }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  auto local = [&](Index w) {
    const auto it = std::lower_bound(nodes.begin(), nodes.end(), w);
    return it != nodes.end() && *it == w ? static_cast<Index>(it - nodes.begin()) : Index{-1};
  };
  FractureState s;
  s.mesh_revision = whole.mesh_revision;
  std::vector<Index> bc_rank(wn, -1);
  Index bc_nodes = 0;
  for (size_t w = 0; w < wn; ++w)
    if (whole.bc_mask[w]) bc_rank[w] = bc_nodes++;
  part.bc_index.clear();
  for (Index w : nodes) {
    append_node_row(s, whole, w);
    if (whole.bc_mask[w]) part.bc_index.push_back(bc_rank[w]);
  }
  for (Index e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < k; ++a) s.conn.push_back(local(whole.conn[static_cast<size_t>(model_.whole_element(e)) * k + a]));
  part.node_index = nodes;
  part.whole_nodes = static_cast<Index>(wn);
  part.whole_bc_nodes = bc_nodes;
  // The facets and cohesive elements held here.
  auto held = [&](GlobalId gid) { return !facets(std::span<const GlobalId>(&gid, 1)).empty(); };
  SHATTER_REQUIRE(whole.facet_state.size() == whole.facet_gid.size(),
                  "fracture state: " << whole.facet_gid.size() << " facet ids and " << whole.facet_state.size()
                                     << " states");
  for (size_t i = 0; i < whole.facet_gid.size(); ++i)
    if (held(whole.facet_gid[i])) {
      s.facet_gid.push_back(whole.facet_gid[i]);
      s.facet_state.push_back(whole.facet_state[i]);
    }
  const CohesiveElements& c = whole.cohesive;
  const size_t nc = whole.cohesive_facet_gid.size();
  SHATTER_REQUIRE(c.side_local.size() == nc * kCohesiveSlots && c.side_nodes.size() == nc * kCohesiveSlots &&
                      c.area.size() == nc && c.normal.size() == nc && c.delta_max.size() == nc * kCohesivePoints,
                  "fracture state: the cohesive element arrays disagree in size");
  for (size_t i = 0; i < nc; ++i) {
    if (!held(whole.cohesive_facet_gid[i])) continue;
    s.cohesive_facet_gid.push_back(whole.cohesive_facet_gid[i]);
    s.cohesive_whole.push_back(static_cast<Index>(i));
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
  s.whole_nodes = static_cast<Index>(wn);
  s.whole_cohesive = static_cast<Index>(nc);
  return s;
}

}  // namespace shatter
