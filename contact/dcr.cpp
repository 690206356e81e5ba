#include "contact/dcr.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <numeric>

#include "contact/candidates.hpp"
#include "kernels/error.hpp"

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

/// Pairs per chunk of a detection round.
constexpr size_t kDetectChunk = 256;

/// What a chunk of a detection round found: the pairs of mine (indices) whose swept boxes
/// overlap (first round), those penetrating, the pairs checked, and the first pair with a node
/// beyond the nodal arrays (-1: none).
struct DetectChunk {
  std::vector<Index> kept, penetrating;
  Index detected = 0;
  Index bad = -1;
};

/// What resolving one found pair did.
struct Outcome {
  bool active = false;
  double dissipated = 0, support_work = 0, work = 0;
  std::int32_t body = -1;  ///< the rigid body among the pair's nodes, -1: none
  std::array<double, kRigidSums> rigid{};  ///< what it took (DcrRigidSum)
};

/// Re-detects the found pair at its turn and resolves it (dcr_resolve_pair), writing its
/// nodes' new states and moved stamps when it acts.
Outcome resolve_found(const FoundPair& found, std::span<Vec3> x_new, std::span<const Vec3> x_old, std::span<Vec3> v,
                      std::span<const double> inv_mass, std::span<const std::uint8_t> held_masks, const DcrLaw& law,
                      double dt, std::vector<long>& moved, long stamp, const DcrRigidBodies* rigid,
                      const PairThickness& th) {
  const ContactPair& p = found.pair;
  PairPoints X_old, X_new, V, W;
  PairWeights w;
  PairMobility mobility;
  std::int32_t body = -1;
  bool held = false, driven = false;  // a held component; one held at a non-zero velocity
  for (int i = 0; i < 4; ++i) {
    const Index n = p.nodes[i];
    X_old.col(i) = x_old[n];
    X_new.col(i) = x_new[n];
    V.col(i) = v[n];
    w[i] = inv_mass[n];
    if (rigid && rigid->node_body[n] >= 0) {
      SHATTER_REQUIRE(body < 0 || body == rigid->node_body[n],
                      "resolve_contacts: a pair with nodes of two rigid bodies (" << body << ", "
                                                                                  << rigid->node_body[n] << ")");
      body = rigid->node_body[n];
      mobility.rigid[i] = true;
      mobility.r.col(i) = x_new[n] - rigid->bodies[body].centre;
      w[i] = 0;
    }
    const std::uint8_t h = held_masks.empty() ? 0 : held_masks[n];
    for (int c = 0; c < 3; ++c) {
      const bool hc = (h >> c) & 1u;
      W(c, i) = hc ? 0.0 : w[i];
      held = held || hc;
      driven = driven || (hc && V(c, i) != 0.0);
    }
  }
  const PairPoints V_before = V;
  DcrPairResponse out;
  if (body >= 0) {
    mobility.w = W;
    mobility.inv_mass = rigid->bodies[body].inv_mass;
    mobility.inv_inertia = rigid->bodies[body].inv_inertia;
    out = dcr_resolve_pair(dcr_kind(p), X_old, X_new, V, found.normals, mobility, law, 0.5 * dt, th);
  } else {
    out = held ? dcr_resolve_pair(dcr_kind(p), X_old, X_new, V, found.normals, W, law, 0.5 * dt, th)
               : dcr_resolve_pair(dcr_kind(p), X_old, X_new, V, found.normals, w, law, 0.5 * dt, th);
  }
  Outcome o;
  if (!out.active) return o;
  o.active = true;
  o.dissipated = out.impulse.dissipated;
  o.work = out.work;
  if (body >= 0) {
    o.body = body;
    for (int i = 0; i < 4; ++i)
      if (mobility.rigid[i]) {
        const Vec3 x = X_new.col(i), J = out.impulse.applied.col(i), S = out.shift.col(i);
        const Vec3 terms[4] = {J, x.cross(J), S, x.cross(S)};
        for (int t = 0; t < 4; ++t)
          for (int c = 0; c < 3; ++c) o.rigid[3 * t + c] += terms[t][c];
      }
  }
  if (driven) {
    // The free components' kinetic energy change beyond the dissipation came from the supports.
    double gained = 0;
    for (int i = 0; i < 4; ++i)
      for (int c = 0; c < 3; ++c)
        if (W(c, i) > 0) gained += 0.5 / W(c, i) * (V(c, i) * V(c, i) - V_before(c, i) * V_before(c, i));
    o.support_work = gained + out.impulse.dissipated + out.work;
  }
  for (int i = 0; i < 4; ++i) {
    const Index n = p.nodes[i];
    x_new[n] = X_new.col(i);
    v[n] = V.col(i);
    moved[n] = stamp;
  }
  return o;
}

/// A round's found pairs (sorted by key) linked on their nodes: per pair and node, the ranks
/// of the pairs just before and after it on the node; per node (slot), this rank's pairs on
/// it in key order.
struct Links {
  std::vector<std::array<int, 4>> pred, succ;
  std::vector<Index> offsets, pairs;  ///< CSR over the slots
  std::vector<Index> nodes;           ///< per slot
};

Links link_found(std::span<const FoundPair> found, std::span<const DcrKey> keys, DcrRanks* ranks, int me,
                 std::vector<Index>& slot_of) {
  Links l;
  const size_t F = found.size();
  std::vector<DcrLink> links;
  links.reserve(4 * F);
  std::vector<Index> count;
  for (size_t f = 0; f < F; ++f)
    for (int c = 0; c < 4; ++c) {
      const Index n = found[f].pair.nodes[c];
      if (slot_of[n] < 0) {
        slot_of[n] = static_cast<Index>(l.nodes.size());
        l.nodes.push_back(n);
        count.push_back(0);
      }
      ++count[slot_of[n]];
      links.push_back({static_cast<std::uint64_t>(n), keys[f], me, 4 * f + c});
    }
  l.offsets.assign(l.nodes.size() + 1, 0);
  for (size_t k = 0; k < count.size(); ++k) l.offsets[k + 1] = l.offsets[k] + count[k];
  l.pairs.resize(l.offsets.back());
  std::vector<Index> at(l.offsets.begin(), l.offsets.end() - 1);
  for (size_t f = 0; f < F; ++f)  // ascending f: key order
    for (const Index n : found[f].pair.nodes) l.pairs[at[slot_of[n]]++] = static_cast<Index>(f);
  if (ranks) ranks->link(links);
  else order_links(links);
  l.pred.resize(F);
  l.succ.resize(F);
  for (const DcrLink& k : links) {
    l.pred[k.tag / 4][k.tag % 4] = k.pred;
    l.succ[k.tag / 4][k.tag % 4] = k.succ;
  }
  return l;
}

}  // namespace

std::vector<double> pair_gaps(std::span<const ContactPair> pairs, std::span<const Vec3> x, const DcrSurface& surface) {
  std::vector<double> gaps(pairs.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pairs.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const ContactPair& p = pairs[k];
      const int first = p.kind == ContactPair::VertexFace ? 1 : 2;
      const int begin[2] = {0, first}, end[2] = {first, 4};  // the nodes of side A and of side B
      Box side[2];
      double scale = 0;
      for (int s = 0; s < 2; ++s) {
        side[s] = {x[p.nodes[begin[s]]], x[p.nodes[begin[s]]]};
        for (int i = begin[s]; i < end[s]; ++i) {
          side[s].lo = side[s].lo.cwiseMin(x[p.nodes[i]]);
          side[s].hi = side[s].hi.cwiseMax(x[p.nodes[i]]);
          scale = std::max(scale, x[p.nodes[i]].cwiseAbs().maxCoeff());
        }
      }
      const double sides = (side[0].hi - side[0].lo).maxCoeff() + (side[1].hi - side[1].lo).maxCoeff();
      const Vec3 apart = (side[0].lo - side[1].hi).cwiseMax(side[1].lo - side[0].hi);
      gaps[k] = apart.maxCoeff() - kBoxInflation * sides - pair_thickness(p, surface).reach - 1e-9 * (scale + sides);
    }
  });
  return gaps;
}

PairThickness pair_thickness(const ContactPair& pair, const DcrSurface& surface) {
  if (surface.reach.empty()) return {};
  const auto& n = pair.nodes;
  const int b = pair.kind == ContactPair::VertexFace ? 1 : 2;
  return {surface.reach[n[0]] + surface.reach[n[b]]};
}

PairNormals pair_normals(const ContactPair& pair, const DcrSurface& surface, const TriangleNormals& tn) {
  PairNormals N = PairNormals::Zero();
  if (!surface.surface) return N;
  const auto& n = pair.nodes;
  const bool vf = pair.kind == ContactPair::VertexFace;
  N.col(0) = surface_normal(*surface.surface, *surface.around, tn, n[0], vf ? -1 : n[1]);
  if (vf) return N;
  N.col(1) = surface_normal(*surface.surface, *surface.around, tn, n[2], n[3]);
  N.col(2) = edge_face_normal(*surface.surface, *surface.around, tn, n[0], n[1]);
  N.col(3) = edge_face_normal(*surface.surface, *surface.around, tn, n[2], n[3]);
  return N;
}

DcrResult resolve_contacts(std::span<const ContactPair> mine, std::span<Vec3> x_new,
                           std::span<const Vec3> x_old, std::span<Vec3> v, std::span<const double> inv_mass, double dt,
                           const DcrOptions& options, const DcrSurface& surface, DcrScratch& scratch,
                           DcrRanks* ranks, std::span<const std::uint8_t> held_masks,
                           const DcrRigidBodies* rigid) {
  const size_t n_nodes = x_new.size();
  SHATTER_REQUIRE(x_old.size() == n_nodes && v.size() == n_nodes && inv_mass.size() == n_nodes,
                  "resolve_contacts: nodal arrays differ in size (x_new "
                      << n_nodes << ", x_old " << x_old.size() << ", v " << v.size() << ", inv_mass " << inv_mass.size()
                      << ")");
  SHATTER_REQUIRE(dt > 0, "resolve_contacts: step length dt = " << dt << " s");
  SHATTER_REQUIRE(held_masks.empty() || held_masks.size() == n_nodes,
                  "resolve_contacts: " << held_masks.size() << " held masks for " << n_nodes << " nodes");
  SHATTER_REQUIRE(options.max_sweeps >= 1, "resolve_contacts: max_sweeps = " << options.max_sweeps);
  SHATTER_REQUIRE(scratch.gaps.empty() || (scratch.gaps.size() == mine.size() && scratch.drift.size() >= n_nodes),
                  "resolve_contacts: " << scratch.gaps.size() << " gaps for " << mine.size() << " pairs, "
                                       << scratch.drift.size() << " drifts for " << n_nodes << " nodes");
  const DcrLaw law{options.restitution, options.friction, options.gap, options.placement};
  if (scratch.moved.size() < n_nodes) scratch.moved.resize(n_nodes, 0);
  if (scratch.slot.size() < n_nodes) scratch.slot.resize(n_nodes, -1);
  // The outward normals orient the pairs at the start of the step.
  TriangleNormals& tn = scratch.normals;
  if (surface.surface && !mine.empty()) triangle_normals(*surface.surface, x_old, surface.triangles, tn);

  SHATTER_REQUIRE(!rigid || rigid->node_body.size() == n_nodes,
                  "resolve_contacts: " << rigid->node_body.size() << " rigid body ids for " << n_nodes << " nodes");
  DcrResult result;
  if (rigid) result.rigid.resize(rigid->bodies.size());
  const int me = ranks ? ranks->rank() : 0;
  ContactPairs resolved;  // every pair resolved here, with repeats
  std::vector<Outcome> outcome;
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
    // Detection and its lists in fixed chunks, concatenated in chunk order below (the same
    // lists whatever the threads; collected serially, they were 3 % of a one-rank run).
    const bool screen = first_round && !scratch.gaps.empty();
    const size_t chunks = (n_check + kDetectChunk - 1) / kDetectChunk;
    std::vector<DetectChunk> chunk(chunks);
    tbb::parallel_for(size_t{0}, chunks, [&](size_t at) {
      DetectChunk& out = chunk[at];
      for (size_t k = at * kDetectChunk; k < std::min(n_check, (at + 1) * kDetectChunk); ++k) {
        const Index i = checked(k);
        const ContactPair& p = mine[i];
        // (the nodes of mine are checked in the first round, before anything reads them)
        if (first_round && std::any_of(p.nodes.begin(), p.nodes.end(),
                                       [&](Index n) { return n < 0 || static_cast<size_t>(n) >= n_nodes; })) {
          if (out.bad < 0) out.bad = i;
          continue;
        }
        if (screen) {
          const std::span<const double> d = scratch.drift;
          const bool vf = p.kind == ContactPair::VertexFace;
          const double a = vf ? d[p.nodes[0]] : std::max(d[p.nodes[0]], d[p.nodes[1]]);
          const double b = vf ? std::max({d[p.nodes[1]], d[p.nodes[2]], d[p.nodes[3]]}) : std::max(d[p.nodes[2]], d[p.nodes[3]]);
          if (scratch.gaps[k] > kGapDrift * (a + b)) continue;  // its swept boxes are apart (DcrScratch::gaps)
        }
        if (!first_round &&
            std::none_of(p.nodes.begin(), p.nodes.end(), [&](Index n) { return scratch.moved[n] == previous; }))
          continue;
        PairPoints X_old, X_new;
        for (int c = 0; c < 4; ++c) {
          X_old.col(c) = x_old[p.nodes[c]];
          X_new.col(c) = x_new[p.nodes[c]];
        }
        const PairThickness th = pair_thickness(p, surface);
        if (first_round && !pair_boxes_overlap(p.kind, X_old, X_new, th.reach)) continue;
        if (first_round) out.kept.push_back(i);
        ++out.detected;
        const auto normals = [&] { return pair_normals(p, surface, tn); };
        if (distinct_nodes(p) && dcr_detect(dcr_kind(p), X_old, X_new, normals, th).penetrating)
          out.penetrating.push_back(i);
      }
    });
    for (const DetectChunk& out : chunk)
      if (out.bad >= 0)
        for (const Index n : mine[out.bad].nodes)
          SHATTER_REQUIRE(n >= 0 && static_cast<size_t>(n) < n_nodes, "resolve_contacts: node "
                                                                          << n << " of pair " << out.bad << " beyond the "
                                                                          << n_nodes << " nodal values");
    std::vector<FoundPair> found;
    std::vector<DcrKey> keys;
    if (first_round) kept.clear();
    for (const DetectChunk& out : chunk) {
      for (const Index i : out.penetrating) {
        const ContactPair& p = mine[i];
        found.push_back({p, pair_normals(p, surface, tn)});
        std::array<std::uint64_t, 4> ids;
        for (int c = 0; c < 4; ++c) ids[c] = ranks ? ranks->id(p.nodes[c]) : static_cast<std::uint64_t>(p.nodes[c]);
        keys.push_back(dcr_key(p.kind, ids, result.sweeps));
      }
      if (first_round) kept.insert(kept.end(), out.kept.begin(), out.kept.end());
      result.detected += out.detected;
    }
    first_round = false;
    ++result.sweeps;
    if ((ranks ? ranks->total(static_cast<long>(found.size())) : static_cast<long>(found.size())) == 0) break;

    // The found pairs in key order, linked on their nodes.
    {
      std::vector<size_t> order(found.size());
      std::iota(order.begin(), order.end(), size_t{0});
      std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return keys[a] < keys[b]; });
      std::vector<FoundPair> f2(found.size());
      std::vector<DcrKey> k2(keys.size());
      for (size_t k = 0; k < order.size(); ++k) f2[k] = found[order[k]], k2[k] = keys[order[k]];
      found.swap(f2);
      keys.swap(k2);
    }
    const Links links = link_found(found, keys, ranks, me, scratch.slot);
    const size_t F = found.size();
    std::vector<int> need(F, 0);
    for (size_t f = 0; f < F; ++f)
      for (int c = 0; c < 4; ++c) need[f] += links.pred[f][c] >= 0;
    std::vector<Index> cursor(links.nodes.size(), 0), ready, batch, last;
    for (size_t f = 0; f < F; ++f)
      if (need[f] == 0) ready.push_back(static_cast<Index>(f));
    // A state from the rank of the pair before on its node: my next pair on the node may go.
    auto arrived = [&](const std::vector<DcrNodeState>& states) {
      for (const DcrNodeState& s : states) {
        x_new[s.node] = s.x_new;
        v[s.node] = s.v;
        if (s.moved) scratch.moved[s.node] = stamp;
        const Index g = scratch.slot[s.node];
        SHATTER_ASSERT(g >= 0 && cursor[g] < links.offsets[g + 1] - links.offsets[g]);
        const Index f = links.pairs[links.offsets[g] + cursor[g]];
        if (--need[f] == 0) ready.push_back(f);
      }
    };
    outcome.assign(F, {});
    std::map<int, std::vector<DcrNodeState>> posts;
    for (size_t done = 0; done < F;) {
      if (ready.empty()) {
        SHATTER_ASSERT(ranks);
        arrived(ranks->receive(true));
        continue;
      }
      batch.swap(ready);
      ready.clear();
      // The ready pairs share no node (of two pairs on a node, the later waits for the other).
      tbb::parallel_for(tbb::blocked_range<size_t>(0, batch.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k)
          outcome[batch[k]] = resolve_found(found[batch[k]], x_new, x_old, v, inv_mass, held_masks, law, dt,
                                            scratch.moved, stamp, rigid, pair_thickness(found[batch[k]].pair, surface));
      });
      for (const Index f : batch) {
        ++done;
        for (int c = 0; c < 4; ++c) {
          const Index n = found[f].pair.nodes[c], g = scratch.slot[n];
          ++cursor[g];
          const int succ = links.succ[f][c];
          const bool moved = scratch.moved[n] == stamp;
          if (succ == me) {
            const Index next = links.pairs[links.offsets[g] + cursor[g]];
            if (--need[next] == 0) ready.push_back(next);
          } else if (succ >= 0) {
            posts[succ].push_back({n, x_new[n], v[n], moved});
          } else if (moved) {
            last.push_back(n);
          }
        }
      }
      for (auto& [r, states] : posts) ranks->post(r, states);
      posts.clear();
      if (ranks) arrived(ranks->receive(false));
    }
    for (const Index n : links.nodes) scratch.slot[n] = -1;
    if (ranks)
      for (const Index n : ranks->settle(last, x_new, v)) scratch.moved[n] = stamp;
    for (size_t f = 0; f < F; ++f)
      if (outcome[f].active) {
        resolved.push_back(found[f].pair);
        result.dissipated += outcome[f].dissipated;
        result.support_work += outcome[f].support_work;
        result.work += outcome[f].work;
        if (outcome[f].body >= 0)
          for (int t = 0; t < kRigidSums; ++t) result.rigid[outcome[f].body][t] += outcome[f].rigid[t];
      }
    if (result.sweeps == options.max_sweeps) {
      result.capped = true;
      if (!found.empty())
        result.unresolved = std::min_element(found.begin(), found.end(), [](const FoundPair& a, const FoundPair& b) {
                              return a.pair < b.pair;
                            })->pair;
      break;
    }
  }
  std::sort(resolved.begin(), resolved.end());
  result.contacts = static_cast<Index>(std::unique(resolved.begin(), resolved.end()) - resolved.begin());
  return result;
}

}  // namespace shatter
