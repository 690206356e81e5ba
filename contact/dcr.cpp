#include "contact/dcr.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>

#include "kernels/error.hpp"

namespace shatter {

Index contact_pair_nodes(const ContactPairs& pairs, std::vector<Index>& offsets, std::vector<Index>& slots,
                         std::vector<Index>& node_slot) {
  offsets.resize(pairs.size() + 1);
  slots.resize(4 * pairs.size());
  for (size_t i = 0; i <= pairs.size(); ++i) offsets[i] = static_cast<Index>(4 * i);
  Index n_slots = 0;
  for (size_t i = 0; i < pairs.size(); ++i)
    for (int k = 0; k < 4; ++k) {
      const Index n = pairs[i].nodes[k];
      SHATTER_REQUIRE(static_cast<size_t>(n) < node_slot.size(),
                      "contact_pair_nodes: node " << n << " beyond the scratch of " << node_slot.size());
      if (node_slot[n] < 0) node_slot[n] = n_slots++;
      slots[4 * i + k] = node_slot[n];
    }
  for (const ContactPair& p : pairs)
    for (const Index n : p.nodes) node_slot[n] = -1;
  return n_slots;
}

std::vector<Vec3> contact_pair_normals(const ContactPairs& pairs, const ContactSurface& surface,
                                       const VertexTriangles& around, std::span<const Vec3> x) {
  std::vector<Vec3> normals(2 * pairs.size());
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, pairs.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
          const auto& n = pairs[i].nodes;
          const bool vf = pairs[i].kind == ContactPair::VertexFace;
          normals[2 * i] = surface_normal(surface, around, x, n[0], vf ? -1 : n[1]);
          normals[2 * i + 1] = vf ? Vec3::Zero() : surface_normal(surface, around, x, n[2], n[3]);
        }
      });
  return normals;
}

namespace {

bool distinct_nodes(const ContactPair& p) {
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (p.nodes[i] == p.nodes[j]) return false;
  return true;
}

}  // namespace

DcrResult resolve_contacts(const ContactPairs& pairs, std::span<Vec3> x_new, std::span<const Vec3> x_old,
                           std::span<Vec3> v, std::span<const double> inv_mass, double dt,
                           const DcrOptions& options, const DcrPairColors& colors, const DcrRemote* remote) {
  const size_t n_nodes = x_new.size();
  SHATTER_REQUIRE(x_old.size() == n_nodes && v.size() == n_nodes && inv_mass.size() == n_nodes,
                  "resolve_contacts: nodal arrays differ in size (x_new " << n_nodes << ", x_old " << x_old.size()
                                                                          << ", v " << v.size() << ", inv_mass "
                                                                          << inv_mass.size() << ")");
  SHATTER_REQUIRE(colors.items.size() == pairs.size() && !colors.offsets.empty() &&
                      colors.offsets.back() == static_cast<Index>(pairs.size()),
                  "resolve_contacts: the coloring covers " << colors.items.size() << " items, not the "
                                                           << pairs.size() << " pairs");
  SHATTER_REQUIRE(
      colors.slots.size() == 4 * pairs.size() && colors.normals.size() == 2 * pairs.size(),
      "resolve_contacts: " << colors.slots.size() << " node slots and " << colors.normals.size()
                           << " normals for " << pairs.size() << " pairs");
  SHATTER_REQUIRE(!remote || remote->owner.size() == pairs.size(),
                  "resolve_contacts: " << remote->owner.size() << " pair owners for " << pairs.size() << " pairs");
  SHATTER_REQUIRE(dt > 0, "resolve_contacts: step length dt = " << dt << " s");
  SHATTER_REQUIRE(options.max_sweeps >= 1, "resolve_contacts: max_sweeps = " << options.max_sweeps);
  const DcrLaw law{options.restitution, options.friction, options.gap, options.placement};

  // Per-pair accumulators, summed in pair order at the end: the totals do not depend on
  // which thread ran which pair.
  std::vector<double> dissipated(pairs.size(), 0.0);
  std::vector<double> dissipated_now(pairs.size(), 0.0);  // in the current sweep
  std::vector<std::uint8_t> ever_active(pairs.size(), 0);
  std::vector<std::uint8_t> active_now(pairs.size(), 0);
  // The last sweep in which each node was moved (0 = never). A pair none of whose nodes
  // moved since its last check would be found clean again, so from the second sweep on
  // only pairs with a node moved in this or the previous sweep are checked: the same
  // result as checking them all, at the cost of the neighbourhood of the active pairs.
  // Indexed by the pairs' compact node slots.
  std::vector<int> moved_in_sweep(colors.num_slots, 0);

  auto resolve = [&](Index i, int sweep) {
    const ContactPair& pair = pairs[i];
    active_now[i] = 0;
    if (!distinct_nodes(pair)) return;
    if (sweep > 1) {
      int last_move = 0;
      for (int k = 0; k < 4; ++k) last_move = std::max(last_move, moved_in_sweep[colors.slots[4 * i + k]]);
      if (last_move < sweep - 1) return;
    }
    PairPoints X_old, X_new, V;
    PairNormals N;
    N << colors.normals[2 * i], colors.normals[2 * i + 1];
    PairWeights w;
    for (int k = 0; k < 4; ++k) {
      const Index n = pair.nodes[k];
      X_old.col(k) = x_old[n];
      X_new.col(k) = x_new[n];
      V.col(k) = v[n];
      w[k] = inv_mass[n];
    }
    const auto kind = pair.kind == ContactPair::VertexFace ? DcrPairKind::VertexFace : DcrPairKind::EdgeEdge;
    const DcrPairResponse r = dcr_resolve_pair(kind, X_old, X_new, V, N, w, law, 0.5 * dt);
    if (!r.active) return;
    active_now[i] = 1;
    ever_active[i] = 1;
    dissipated[i] += r.impulse.dissipated;
    dissipated_now[i] = r.impulse.dissipated;
    for (int k = 0; k < 4; ++k) {
      const Index n = pair.nodes[k];
      x_new[n] = X_new.col(k);
      v[n] = V.col(k);
      moved_in_sweep[colors.slots[4 * i + k]] = sweep;
    }
  };

  // With remote: exchange before color c when flush[c] (DcrRemote).
  const size_t n_colors = colors.offsets.size() - 1;
  std::vector<std::uint8_t> flush(n_colors, 0);
  if (remote) {
    std::vector<int> toucher(colors.num_slots, -1), since(colors.num_slots, -1);  // rank, exchange count
    int exchange = 0;
    for (size_t c = 0; c < n_colors; ++c) {
      const auto group = colors.items.subspan(colors.offsets[c], colors.offsets[c + 1] - colors.offsets[c]);
      for (const Index i : group)
        for (int k = 0; k < 4 && !flush[c]; ++k) {
          const Index s = colors.slots[4 * i + k];
          flush[c] = since[s] == exchange && toucher[s] != remote->owner[i];
        }
      exchange += flush[c];
      for (const Index i : group)
        for (int k = 0; k < 4; ++k) {
          const Index s = colors.slots[4 * i + k];
          toucher[s] = remote->owner[i];
          since[s] = exchange;
        }
    }
  }
  DcrRemote::Moves here, there;
  auto exchange = [&](int sweep) {
    there.pairs.clear();
    there.dissipated.clear();
    remote->exchange(here, there);
    for (size_t k = 0; k < there.pairs.size(); ++k) {
      const Index i = there.pairs[k];
      active_now[i] = 1;
      ever_active[i] = 1;
      dissipated[i] += there.dissipated[k];
      for (int s = 0; s < 4; ++s) moved_in_sweep[colors.slots[4 * i + s]] = sweep;
    }
    here.pairs.clear();
    here.dissipated.clear();
  };
  DcrResult result;
  bool converged = false;
  while (result.sweeps < options.max_sweeps && !converged) {
    const int sweep = ++result.sweeps;
    if (remote)
      for (size_t i = 0; i < pairs.size(); ++i)
        if (remote->owner[i] != remote->rank) active_now[i] = 0;
    for (size_t c = 0; c < n_colors; ++c) {
      const auto group = colors.items.subspan(colors.offsets[c], colors.offsets[c + 1] - colors.offsets[c]);
      if (remote && flush[c] && c > 0) {
        exchange(sweep);
        ++result.exchanges;
      }
      tbb::parallel_for(tbb::blocked_range<size_t>(0, group.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k)
          if (!remote || remote->owner[group[k]] == remote->rank) resolve(group[k], sweep);
      });
      if (remote)
        for (const Index i : group)
          if (active_now[i] && remote->owner[i] == remote->rank) {
            here.pairs.push_back(i);
            here.dissipated.push_back(dissipated_now[i]);
          }
    }
    if (remote && !pairs.empty()) {
      exchange(sweep);
      ++result.exchanges;
    }
    converged = true;
    for (const std::uint8_t a : active_now)
      if (a) converged = false;
  }
  result.capped = !converged;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (result.capped && result.unresolved < 0 && active_now[i]) result.unresolved = static_cast<Index>(i);
    result.contacts += ever_active[i];
    result.dissipated += dissipated[i];
  }
  return result;
}

}  // namespace shatter
