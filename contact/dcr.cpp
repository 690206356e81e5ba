#include "contact/dcr.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "contact/candidates.hpp"
#include "kernels/error.hpp"
#include "mesh/coloring.hpp"

namespace shatter {

namespace {

bool distinct_nodes(const ContactPair& p) {
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (p.nodes[i] == p.nodes[j]) return false;
  return true;
}

DcrPairKind dcr_kind(const ContactPair& p) {
  return p.kind == ContactPair::VertexFace ? DcrPairKind::VertexFace : DcrPairKind::EdgeEdge;
}

/// The greedy coloring of the found pairs in their order, over their nodes numbered compactly
/// (first appearance) with slot_of, a per-node scratch of -1 that is left so.
Coloring color_found(std::span<const FoundPair> found, std::vector<Index>& slot_of) {
  std::vector<Index> offsets(found.size() + 1), slots(4 * found.size());
  std::vector<Index> seen;
  Index n_slots = 0;
  for (size_t k = 0; k < found.size(); ++k) {
    offsets[k] = static_cast<Index>(4 * k);
    for (int c = 0; c < 4; ++c) {
      const Index n = found[k].pair.nodes[c];
      if (slot_of[n] < 0) {
        slot_of[n] = n_slots++;
        seen.push_back(n);
      }
      slots[4 * k + c] = slot_of[n];
    }
  }
  offsets[found.size()] = static_cast<Index>(4 * found.size());
  for (const Index n : seen) slot_of[n] = -1;
  return greedy_coloring(offsets, slots, n_slots);
}

}  // namespace

PairNormals pair_normals(const ContactPair& pair, const DcrSurface& surface, const TriangleNormals& tn) {
  PairNormals N = PairNormals::Zero();
  if (!surface.surface) return N;
  const auto& n = pair.nodes;
  const bool vf = pair.kind == ContactPair::VertexFace;
  N.col(0) = surface_normal(*surface.surface, *surface.around, tn, n[0], vf ? -1 : n[1]);
  if (!vf) N.col(1) = surface_normal(*surface.surface, *surface.around, tn, n[2], n[3]);
  return N;
}

DcrResult resolve_contacts(std::span<const ContactPair> mine, std::span<Vec3> x_new,
                           std::span<const Vec3> x_old, std::span<Vec3> v, std::span<const double> inv_mass, double dt,
                           const DcrOptions& options, const DcrSurface& surface, DcrScratch& scratch,
                           const DcrGather& gather, std::span<const std::uint8_t> held_masks) {
  const size_t n_nodes = x_new.size();
  SHATTER_REQUIRE(x_old.size() == n_nodes && v.size() == n_nodes && inv_mass.size() == n_nodes,
                  "resolve_contacts: nodal arrays differ in size (x_new "
                      << n_nodes << ", x_old " << x_old.size() << ", v " << v.size() << ", inv_mass " << inv_mass.size()
                      << ")");
  SHATTER_REQUIRE(dt > 0, "resolve_contacts: step length dt = " << dt << " s");
  SHATTER_REQUIRE(held_masks.empty() || held_masks.size() == n_nodes,
                  "resolve_contacts: " << held_masks.size() << " held masks for " << n_nodes << " nodes");
  SHATTER_REQUIRE(options.max_sweeps >= 1, "resolve_contacts: max_sweeps = " << options.max_sweeps);
  for (size_t i = 0; i < mine.size(); ++i)
    for (const Index n : mine[i].nodes)
      SHATTER_REQUIRE(n >= 0 && static_cast<size_t>(n) < n_nodes, "resolve_contacts: node " << n << " of pair " << i
                                                                                            << " beyond the " << n_nodes
                                                                                            << " nodal values");
  const DcrLaw law{options.restitution, options.friction, options.gap, options.placement};
  if (scratch.moved.size() < n_nodes) scratch.moved.resize(n_nodes, 0);
  if (scratch.slot.size() < n_nodes) scratch.slot.resize(n_nodes, -1);
  // The outward normals orient the pairs at the start of the step.
  TriangleNormals& tn = scratch.normals;
  if (surface.surface && !mine.empty()) triangle_normals(*surface.surface, x_old, surface.triangles, tn);

  DcrResult result;
  ContactPairs resolved;  // every pair resolved, with repeats
  std::vector<double> dissipated, support_work;
  std::vector<std::uint8_t> active;
  // The first round's box test keeps the pairs of mine that may touch; later rounds check
  // only those, and only when a node moved in the previous round.
  std::vector<Index>& kept = scratch.overlapping;
  bool first_round = true;
  while (true) {
    // Detection (read only, in parallel). hit: 0 not checked, 1 checked and clean,
    // 2 penetrating, and in the first round 3 for a pair whose swept boxes do not overlap.
    const long previous = scratch.stamp;
    const long stamp = ++scratch.stamp;
    const size_t n_check = first_round ? mine.size() : kept.size();
    auto checked = [&](size_t k) { return first_round ? static_cast<Index>(k) : kept[k]; };
    std::vector<std::uint8_t> hit(n_check, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n_check, 256), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k != r.end(); ++k) {
        const ContactPair& p = mine[checked(k)];
        if (!first_round &&
            std::none_of(p.nodes.begin(), p.nodes.end(), [&](Index n) { return scratch.moved[n] == previous; }))
          continue;
        PairPoints X_old, X_new;
        for (int c = 0; c < 4; ++c) {
          X_old.col(c) = x_old[p.nodes[c]];
          X_new.col(c) = x_new[p.nodes[c]];
        }
        if (first_round && !pair_boxes_overlap(p.kind, X_old, X_new)) {
          hit[k] = 3;
          continue;
        }
        const auto normals = [&] { return pair_normals(p, surface, tn); };
        hit[k] = distinct_nodes(p) && dcr_detect(dcr_kind(p), X_old, X_new, normals).penetrating ? 2 : 1;
      }
    });
    std::vector<FoundPair> found;
    if (first_round) kept.clear();
    for (size_t k = 0; k < n_check; ++k) {
      const ContactPair& p = mine[checked(k)];
      if (hit[k] == 2) found.push_back({p, pair_normals(p, surface, tn)});
      if (first_round && hit[k] != 3) kept.push_back(checked(k));
      result.detected += hit[k] == 1 || hit[k] == 2;
    }
    if (gather) gather(found);
    first_round = false;
    ++result.sweeps;
    if (found.empty()) break;

    // Resolution: one Gauss-Seidel pass over the found pairs, color by color.
    const Coloring colors = color_found(found, scratch.slot);
    dissipated.assign(found.size(), 0.0);
    support_work.assign(found.size(), 0.0);
    active.assign(found.size(), 0);
    for (int c = 0; c < colors.num_colors(); ++c) {
      const std::span<const Index> group = colors.items_of(c);
      tbb::parallel_for(tbb::blocked_range<size_t>(0, group.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) {
          const Index f = group[k];
          const ContactPair& p = found[f].pair;
          PairPoints X_old, X_new, V, W;
          PairWeights w;
          bool held = false, driven = false;  // a held component; one held at a non-zero velocity
          for (int i = 0; i < 4; ++i) {
            const Index n = p.nodes[i];
            X_old.col(i) = x_old[n];
            X_new.col(i) = x_new[n];
            V.col(i) = v[n];
            w[i] = inv_mass[n];
            const std::uint8_t h = held_masks.empty() ? 0 : held_masks[n];
            for (int c = 0; c < 3; ++c) {
              const bool hc = (h >> c) & 1u;
              W(c, i) = hc ? 0.0 : w[i];
              held = held || hc;
              driven = driven || (hc && V(c, i) != 0.0);
            }
          }
          const PairPoints V_before = V;
          const PairNormals& N = found[f].normals;
          const DcrPairResponse out = held ? dcr_resolve_pair(dcr_kind(p), X_old, X_new, V, N, W, law, 0.5 * dt)
                                           : dcr_resolve_pair(dcr_kind(p), X_old, X_new, V, N, w, law, 0.5 * dt);
          if (driven && out.active) {
            // The free components' kinetic energy change beyond the dissipation came from the supports.
            double gained = 0;
            for (int i = 0; i < 4; ++i)
              for (int c = 0; c < 3; ++c)
                if (W(c, i) > 0) gained += 0.5 / W(c, i) * (V(c, i) * V(c, i) - V_before(c, i) * V_before(c, i));
            support_work[f] = gained + out.impulse.dissipated;
          }
          if (!out.active) continue;
          active[f] = 1;
          dissipated[f] = out.impulse.dissipated;
          for (int i = 0; i < 4; ++i) {
            const Index n = p.nodes[i];
            x_new[n] = X_new.col(i);
            v[n] = V.col(i);
            scratch.moved[n] = stamp;
          }
        }
      });
    }
    for (size_t f = 0; f < found.size(); ++f)
      if (active[f]) {
        resolved.push_back(found[f].pair);
        result.dissipated += dissipated[f];
        result.support_work += support_work[f];
      }
    if (result.sweeps == options.max_sweeps) {
      result.capped = true;
      result.unresolved = found.front().pair;
      break;
    }
  }
  std::sort(resolved.begin(), resolved.end());
  result.contacts = static_cast<Index>(std::unique(resolved.begin(), resolved.end()) - resolved.begin());
  return result;
}

}  // namespace shatter
