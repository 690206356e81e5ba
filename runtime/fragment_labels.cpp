#include "runtime/fragment_labels.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>

#include "runtime/halo.hpp"
#include "runtime/key_positions.hpp"
#include "runtime/sort_unique.hpp"

namespace shatter {

FragmentLabels::FragmentLabels(const Model& model, const Topology& topo, const Decomposition& dec)
    : model_(model), dec_(dec) {
  const Index ne = model.mesh.num_elements();
  is_owned_.assign(ne, 0);
  if (!dec.distributed()) {
    owned_.resize(ne);
    std::iota(owned_.begin(), owned_.end(), 0);
    is_owned_.assign(ne, 1);
    return;
  }
  owned_.assign(dec.owned_element_ids().begin(), dec.owned_element_ids().end());
  for (Index e : owned_) is_owned_[e] = 1;
  // Send an owned element to the owner of every element it shares a facet
  // with; receive those elements from their owners. Both sides list the
  // same elements, ascending (local ids ascend with the whole ids).
  std::map<int, std::vector<Index>> send, recv;
  for (Index e : owned_)
    for (int i = 0; i < 4; ++i) {
      const Index f = topo.elem_facet[4 * static_cast<size_t>(e) + i];
      if (!topo.is_interior(f)) continue;
      const Index other = topo.facet_elem[f][0] == e ? topo.facet_elem[f][1] : topo.facet_elem[f][0];
      if (is_owned_[other]) continue;
      send[dec.element_rank(other)].push_back(e);
      recv[dec.element_rank(other)].push_back(other);
    }
  for (auto* m : {&send, &recv})
    for (auto& [q, list] : *m) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
    }
  halo_ = std::make_unique<Halo>(ne, exchange_from(send), exchange_from(recv), dec.comm(), kFragmentTag);
}

FragmentLabels::~FragmentLabels() = default;

Fragments FragmentLabels::label(const Topology& topo) const {
  const Mesh& mesh = model_.mesh;
  const Index ne = mesh.num_elements();
  // Components of the owned elements through their facets that are not free.
  std::vector<Index> parent(ne);
  std::iota(parent.begin(), parent.end(), 0);
  auto joined = [&](Index e, int i, auto use) {
    const Index f = topo.elem_facet[4 * static_cast<size_t>(e) + i];
    if (!topo.is_interior(f) || topo.facet_state[f] == FacetState::free) return;
    use(topo.facet_elem[f][0] == e ? topo.facet_elem[f][1] : topo.facet_elem[f][0]);
  };
  for (Index e : owned_)
    for (int i = 0; i < 4; ++i)
      joined(e, i, [&](Index other) {
        if (!is_owned_[other]) return;
        const Index a = find_root(parent, e), b = find_root(parent, other);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      });
  // Each component's label: the smallest element global id it reaches, first
  // among its own elements, then through the neighbours' labels until no
  // label falls anywhere (labels as doubles: global ids below 2^53 are exact).
  constexpr double kNone = std::numeric_limits<double>::infinity();
  std::vector<double> label(ne, kNone), root_label(ne, kNone);
  for (Index e : owned_) {
    const Index r = find_root(parent, e);
    root_label[r] = std::min(root_label[r], static_cast<double>(mesh.elem_gid[e]));
  }
  for (Index e : owned_) label[e] = root_label[find_root(parent, e)];
  while (halo_) {
    halo_->update_ghosts(label, 1);
    int fell = 0;
    for (Index e : owned_)
      for (int i = 0; i < 4; ++i)
        joined(e, i, [&](Index other) {
          double& mine = root_label[find_root(parent, e)];
          if (!is_owned_[other] && label[other] < mine) mine = label[other], fell = 1;
        });
    if (!dec_.max(fell)) break;
    for (Index e : owned_) label[e] = root_label[find_root(parent, e)];
  }
  // A fragment's label is the global id of its smallest element, which one
  // rank owns: the fragments are numbered by the positions of those ids
  // among all the ranks' (key_positions, no list of every fragment).
  std::vector<GlobalId> mine, seen;
  for (Index e : owned_)
    if (label[e] == static_cast<double>(mesh.elem_gid[e])) mine.push_back(mesh.elem_gid[e]);
  for (Index e = 0; e < ne; ++e)
    if (label[e] != kNone) seen.push_back(static_cast<GlobalId>(label[e]));
  sort_unique(seen);
  const KeyPositions numbers = key_positions(mine, seen, dec_);
  Fragments out;
  out.fragments = numbers.total;
  out.elem_fragment.assign(ne, -1);
  for (Index e = 0; e < ne; ++e)
    if (label[e] != kNone)
      out.elem_fragment[e] =
          numbers.position[std::lower_bound(seen.begin(), seen.end(), static_cast<GlobalId>(label[e])) - seen.begin()];
  return out;
}

}  // namespace shatter
