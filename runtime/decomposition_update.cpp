// Decomposition::update_nodes: the node lists and halo plan after an
// insertion, recomputed around the split nodes only (docs/parallel.md
// "Cohesive elements on ranks"). rebuild_nodes computes the same lists over
// the whole part; the test Decomposition.UpdateAfterInsertionEqualsRebuild
// holds the two equal.
#include <algorithm>

#include "mesh/partition.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/halo.hpp"
#include "runtime/sort_unique.hpp"

namespace shatter {
namespace {

/// `list` (ascending) without the entries that `drop` marks, merged with
/// `add` (ascending, every entry marked).
void patch(std::vector<Index>& list, const std::vector<char>& drop, std::span<const Index> add) {
  std::vector<Index> out;
  out.reserve(list.size() + add.size());
  auto a = add.begin();
  for (const Index n : list) {
    if (drop[n]) continue;
    for (; a != add.end() && *a < n; ++a) out.push_back(*a);
    out.push_back(n);
  }
  out.insert(out.end(), a, add.end());
  list = std::move(out);
}

/// The same for lists per rank; a rank left without nodes is dropped, as
/// rebuild_nodes lists only ranks with nodes.
void patch(std::map<int, std::vector<Index>>& lists, const std::vector<char>& drop,
           const std::map<int, std::vector<Index>>& add) {
  static const std::vector<Index> none;
  for (const auto& [q, nodes] : add) lists[q];
  for (auto it = lists.begin(); it != lists.end();) {
    const auto found = add.find(it->first);
    patch(it->second, drop, found == add.end() ? none : found->second);
    it = it->second.empty() ? lists.erase(it) : std::next(it);
  }
}

}  // namespace

void Decomposition::update_nodes(std::span<const Index> changed, std::span<const Index> groups, int group_width,
                                 Index old_groups, const GroupsOfNode& groups_of) {
  if (size_ == 1 || shell_nodes_ > 0 || (model_.is_part() && !model_.holds_two_layers()))
    return rebuild_nodes(groups, group_width);
  const Mesh& mesh = model_.mesh;
  const Index nn = mesh.num_nodes(), old_nn = static_cast<Index>(home_granule_.size());
  const int k = mesh.nodes_per_element();
  auto part_of = [&](Index e) { return granule_rank_[model_.whole_element(e) / ElementForces::kGranule]; };

  // The touching ranks: a changed node's from its star (as rebuild_nodes),
  // the others' copied in runs.
  {
    std::vector<Index> offsets{0};
    std::vector<int> ranks;
    offsets.reserve(static_cast<size_t>(nn) + 1);
    ranks.reserve(node_ranks_.size() + 2 * changed.size());
    Index from = 0;  // the next old node to copy
    auto copy_to = [&](Index end) {
      if (end <= from) return;
      const Index shift = static_cast<Index>(ranks.size()) - node_rank_offsets_[from];
      ranks.insert(ranks.end(), node_ranks_.begin() + node_rank_offsets_[from],
                   node_ranks_.begin() + node_rank_offsets_[end]);
      for (Index n = from; n < end; ++n) offsets.push_back(node_rank_offsets_[n + 1] + shift);
      from = end;
    };
    for (const Index a : changed) {
      copy_to(std::min(a, old_nn));
      if (a < old_nn) from = a + 1;
      append_star_ranks(mesh, a, part_of, ranks);
      offsets.push_back(static_cast<Index>(ranks.size()));
    }
    copy_to(old_nn);
    node_rank_offsets_ = std::move(offsets);
    node_ranks_ = std::move(ranks);
  }

  // Around the changed nodes: the elements of their stars (whose nodes' ranks
  // may have changed), the groups holding them and the new groups, and the
  // candidates, every node of those elements and groups: no other node's
  // lists can change.
  auto group = [&](Index g) { return groups.subspan(static_cast<size_t>(g) * group_width, group_width); };
  const Index ng = static_cast<Index>(groups.size() / group_width);
  std::vector<Index> elements, near_groups, candidates;
  std::vector<char> is_candidate(nn, 0), is_near_element(mesh.num_elements(), 0);
  // (Marked first, sorted once each: the lists repeat every entry many times.)
  auto add_candidate = [&](Index n) {
    if (n >= 0 && !is_candidate[n]) is_candidate[n] = 1, candidates.push_back(n);
  };
  for (const Index a : changed) {
    for (const Index e : node_star(mesh, a))
      if (!is_near_element[e]) is_near_element[e] = 1, elements.push_back(e);
    groups_of(a, near_groups);
  }
  for (Index g = old_groups; g < ng; ++g) near_groups.push_back(g);
  std::sort(elements.begin(), elements.end());
  sort_unique(near_groups);
  std::for_each(changed.begin(), changed.end(), add_candidate);
  for (const Index e : elements) std::for_each(mesh.element(e), mesh.element(e) + k, add_candidate);
  for (const Index g : near_groups) std::for_each(group(g).begin(), group(g).end(), add_candidate);
  std::sort(candidates.begin(), candidates.end());

  // Home granules.
  home_granule_.resize(nn);
  for (const Index a : changed) home_granule_[a] = home_granule_of(a);
  {
    std::vector<std::vector<Index>> add(owned_granules_.size());
    std::vector<Index> owned_add;
    for (const Index n : candidates) {
      const Index g = home_granule_[n];
      if (g < 0 || !owns_granule(g)) continue;
      add[std::lower_bound(owned_granules_.begin(), owned_granules_.end(), g) - owned_granules_.begin()].push_back(n);
      owned_add.push_back(n);
    }
    std::vector<Index> offsets{0}, nodes;
    nodes.reserve(home_nodes_.size() + owned_add.size());
    for (size_t s = 0; s < owned_granules_.size(); ++s) {
      std::vector<Index> list(home_nodes_.begin() + home_offsets_[s], home_nodes_.begin() + home_offsets_[s + 1]);
      patch(list, is_candidate, add[s]);
      nodes.insert(nodes.end(), list.begin(), list.end());
      offsets.push_back(static_cast<Index>(nodes.size()));
    }
    home_offsets_ = std::move(offsets);
    home_nodes_ = std::move(nodes);
    patch(owned_nodes_, is_candidate, owned_add);
  }

  // Local elements: those with a touched node.
  {
    std::vector<Index> local;
    for (const Index e : elements)
      if (std::any_of(mesh.element(e), mesh.element(e) + k, [&](Index n) { return touches(n, rank_); }))
        local.push_back(e);
    patch(local_elements_, is_near_element, local);
  }

  // Each candidate's lists, as rebuild_nodes makes them: held when an element
  // of its star is local or a group holding it has a touched node; sent to
  // every rank holding it (touching a node of an element of its star or of a
  // group holding it) that does not touch it.
  std::vector<Index> touched, held, ghost_only, around;
  std::map<int, std::vector<Index>> send, recv;
  std::vector<Index> mark(size_, -1);
  auto mine = [&](Index g) {
    return std::any_of(group(g).begin(), group(g).end(), [&](Index n) { return n >= 0 && touches(n, rank_); });
  };
  for (const Index n : candidates) {
    around.clear();
    groups_of(n, around);
    const std::span<const Index> star = node_star(mesh, n);
    const bool touched_here = touches(n, rank_);
    const bool held_here =
        std::any_of(star.begin(), star.end(),
                    [&](Index e) { return std::binary_search(local_elements_.begin(), local_elements_.end(), e); }) ||
        std::any_of(around.begin(), around.end(), mine);
    if (touched_here) touched.push_back(n);
    if (held_here) held.push_back(n);
    if (held_here && !touched_here) {
      ghost_only.push_back(n);
      recv[node_owner(n)].push_back(n);
    }
    if (!touched_here || node_owner(n) != rank_) continue;
    auto send_to = [&](Index m) {
      if (m < 0) return;
      for (const int q : node_ranks(m))
        if (mark[q] != n) {
          mark[q] = n;
          if (!touches(n, q)) send[q].push_back(n);
        }
    };
    for (const Index e : star) std::for_each(mesh.element(e), mesh.element(e) + k, send_to);
    for (const Index g : around) std::for_each(group(g).begin(), group(g).end(), send_to);
  }
  patch(touched_nodes_, is_candidate, touched);
  patch(held_nodes_, is_candidate, held);
  patch(ghost_only_nodes_, is_candidate, ghost_only);
  patch(recv_, is_candidate, recv);
  patch(send_, is_candidate, send);
  halo_ = std::make_unique<Halo>(nn, exchange_from(send_), exchange_from(recv_), comm_, kGhostTag);
}

}  // namespace shatter
