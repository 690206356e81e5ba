// FractureStage's state between the whole model and the ranks' parts
// (docs/parallel.md "Fracture on parts"): a checkpoint's cohesive rows are
// written by their owners (owned_cohesive); at a restart on parts each part
// reads its own rows of it (read_checkpoint) and takes them in (part_of).
#include <algorithm>
#include <cstdint>

#include "kernels/error.hpp"
#include "runtime/fracture_stage.hpp"

namespace shatter {

std::vector<Index> FractureStage::owned_cohesive(const FractureState& mine) const {
  std::vector<Index> owned;
  for (Index c = 0; c < static_cast<Index>(mine.cohesive_facet_gid.size()); ++c)
    if (dec_.owns_element(topology_.facet_elem[cohesive_.facet[c]][0])) owned.push_back(c);
  std::sort(owned.begin(), owned.end(),
            [&](Index a, Index b) { return mine.cohesive_whole[a] < mine.cohesive_whole[b]; });
  return owned;
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
