#include "mesh/shell_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include "kernels/error.hpp"
#include "kernels/loop_basis.hpp"

namespace shatter {
namespace {

using EdgeKey = std::uint64_t;

EdgeKey edge_key(Index p, Index q) {
  return (static_cast<EdgeKey>(static_cast<std::uint32_t>(p)) << 32) | static_cast<std::uint32_t>(q);
}

std::string vertices_named(Index p, Index q) {
  return "vertices " + std::to_string(p) + " and " + std::to_string(q);
}

/// Orient the triangles consistently, component by component (breadth first
/// from the component's first triangle), and a closed component outward
/// (positive enclosed volume). `edge_triangles` holds each undirected edge's
/// one or two triangles.
void orient(std::vector<std::array<Index, 3>>& tris, const std::vector<Vec3>& x,
            const std::unordered_map<EdgeKey, std::vector<Index>>& edge_triangles, const std::string& where) {
  const Index nt = static_cast<Index>(tris.size());
  std::vector<Index> component(nt, -1);
  auto has_directed = [&](Index t, Index p, Index q) {
    for (int k = 0; k < 3; ++k)
      if (tris[t][k] == p && tris[t][(k + 1) % 3] == q) return true;
    return false;
  };
  Index num_components = 0;
  std::vector<Index> queue;
  for (Index seed = 0; seed < nt; ++seed) {
    if (component[seed] >= 0) continue;
    const Index c = num_components++;
    component[seed] = c;
    queue.assign(1, seed);
    bool closed = true;
    double six_volume = 0;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const Index t = queue[head];
      const auto [a, b, d] = tris[t];
      six_volume += x[a].dot(x[b].cross(x[d]));
      for (int k = 0; k < 3; ++k) {
        const Index p = tris[t][k], q = tris[t][(k + 1) % 3];
        const auto& across = edge_triangles.at(edge_key(std::min(p, q), std::max(p, q)));
        if (across.size() == 1) closed = false;
        for (Index u : across) {
          if (u == t) continue;
          if (component[u] < 0) {
            if (has_directed(u, p, q)) std::swap(tris[u][1], tris[u][2]);
            component[u] = c;
            queue.push_back(u);
          } else if (has_directed(u, p, q)) {
            throw InputError(where + ": the surface is not orientable (triangles " + std::to_string(t) + " and " +
                             std::to_string(u) + " at " + vertices_named(p, q) + ")");
          }
        }
      }
    }
    if (closed && six_volume < 0)
      for (Index t : queue) std::swap(tris[t][1], tris[t][2]);
  }
}

/// opposite(p, q) = r for every oriented triangle (p, q, r), -1 when no
/// triangle holds the directed edge p -> q.
class OppositeVertex {
 public:
  explicit OppositeVertex(const std::vector<std::array<Index, 3>>& tris) {
    map_.reserve(3 * tris.size());
    for (const auto& c : tris)
      for (int k = 0; k < 3; ++k) map_[edge_key(c[k], c[(k + 1) % 3])] = c[(k + 2) % 3];
  }
  Index operator()(Index p, Index q) const {
    const auto it = map_.find(edge_key(p, q));
    return it == map_.end() ? Index{-1} : it->second;
  }

 private:
  std::unordered_map<EdgeKey, Index> map_;
};

using Lattice = std::array<int, 2>;

/// The 12-vertex patch of triangle c (corners 4, 7, 8 = c[0], c[1], c[2])
/// with a corner on the boundary, completed by ghost vertices, or false.
/// The fans of the three corners are unfolded onto the regular lattice
/// (each must fit it: interior corners of valence 6, no overlap); a lattice
/// point of the patch with no vertex, next to a boundary edge, becomes a
/// ghost vertex (the candidates are below).
/// New ghost rules are appended to m.ghost_rule (deduplicated by `ghost_id`).
bool ghost_completed_patch(ShellMesh& m, const OppositeVertex& opp, const std::array<Index, 3>& c,
                           std::map<std::array<Index, 3>, Index>& ghost_id, std::array<Index, 12>& patch) {
  // rot60(d): the lattice vector d turned by +60 degrees
  auto rot60 = [](Lattice d) { return Lattice{-d[1], d[0] + d[1]}; };
  auto add = [](Lattice a, Lattice b, int s) { return Lattice{a[0] + s * b[0], a[1] + s * b[1]}; };
  std::map<Index, Lattice> at;
  bool flat = true;
  auto place = [&](Index v, Lattice x) {
    const auto [it, inserted] = at.try_emplace(v, x);
    flat = flat && (inserted || it->second == x);
  };
  place(c[0], {0, 0});
  place(c[1], {1, 0});
  place(c[2], {0, 1});
  for (int k = 0; k < 3 && flat; ++k) {
    const Index p = c[k], q = c[(k + 1) % 3];
    if (!m.on_boundary[p] && m.valence[p] != 6) return false;
    // counter-clockwise: triangle (p, prev, r) has r = p + rot60(prev - p)
    Index prev = q;
    for (Index r = opp(p, prev); r >= 0 && r != q && flat; prev = r, r = opp(p, prev))
      place(r, add(at[p], rot60(add(at[prev], at[p], -1)), 1));
    // clockwise: triangle (prev, p, s) has s = prev + rot60(p - prev)
    prev = q;
    for (Index s = opp(prev, p); s >= 0 && s != q && flat; prev = s, s = opp(prev, p))
      place(s, add(at[prev], rot60(add(at[p], at[prev], -1)), 1));
  }
  if (!flat) return false;
  std::map<Lattice, Index> vertex_at;
  for (const auto& [v, x] : at)
    if (!vertex_at.emplace(x, v).second) return false;  // the fans overlap: not a flat lattice
  static constexpr Lattice kAround[6] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};
  for (int a = 0; a < 12; ++a) {
    const Lattice P{kLoopRegularLattice[a][0], kLoopRegularLattice[a][1]};
    if (const auto it = vertex_at.find(P); it != vertex_at.end()) {
      patch[a] = it->second;
      continue;
    }
    // Candidates, for each boundary edge (B1, B2) next to P: the reflection
    // of the edge triangle's third vertex A through the edge's midpoint
    // (B1 + B2 - A), and of the vertex Q = 2 B - P through either end B
    // (2 B - Q). All put the ghost on the lattice point; the one whose
    // partner (A or Q) is the ghost's mirror image across the edge (its
    // offset most nearly normal to the edge) is taken, so that held
    // boundary vertices make an odd reflection of the control net.
    std::array<Index, 3> best{};
    double best_score = HUGE_VAL;
    auto consider = [&](const std::array<Index, 3>& rule, Index partner, const Vec3& edge) {
      const Vec3 ghost = m.reference[rule[0]] + m.reference[rule[1]] - m.reference[rule[2]];
      const Vec3 d = m.reference[partner] - ghost;
      const double score = std::abs(d.dot(edge)) / (d.norm() * edge.norm());
      if (score < best_score - 1e-9) best_score = score, best = rule;
    };
    for (int k = 0; k < 6; ++k) {
      const auto b1 = vertex_at.find(add(P, kAround[k], 1)), b2 = vertex_at.find(add(P, kAround[(k + 1) % 6], 1));
      if (b1 == vertex_at.end() || b2 == vertex_at.end()) continue;
      const Index B1 = b1->second, B2 = b2->second;
      const Index A12 = opp(B1, B2), A21 = opp(B2, B1);
      if ((A12 >= 0) == (A21 >= 0)) continue;  // not a boundary edge
      const Index A = A12 >= 0 ? A12 : A21;
      const Vec3 edge = m.reference[B2] - m.reference[B1];
      const Lattice reflected = add(add(b1->first, b2->first, 1), P, -1);
      if (const auto ia = at.find(A); ia == at.end() || ia->second == reflected)
        consider({std::min(B1, B2), std::max(B1, B2), A}, A, edge);
      for (const auto& b : {b1, b2})
        if (const auto q = vertex_at.find(add(add(b->first, b->first, 1), P, -1)); q != vertex_at.end())
          consider({b->second, b->second, q->second}, q->second, edge);
    }
    if (best_score == HUGE_VAL) return false;
    const auto [g, inserted] = ghost_id.try_emplace(best, static_cast<Index>(m.ghost_rule.size()));
    if (inserted) {
      m.ghost_rule.push_back(best);
      m.ghost_mode.push_back(GhostMode::odd);
    }
    patch[a] = m.num_vertices() + g->second;
  }
  return true;
}

}  // namespace

ShellMesh build_shell_mesh(std::vector<Vec3> points, std::vector<std::array<Index, 3>> triangles,
                           const std::string& where) {
  ShellMesh m;
  m.reference = std::move(points);
  m.triangles = std::move(triangles);
  const Index n = m.num_vertices(), nt = m.num_triangles();
  std::vector<Index> incident(n, 0);
  std::unordered_map<EdgeKey, std::vector<Index>> edge_triangles;
  for (Index t = 0; t < nt; ++t) {
    const auto& c = m.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (c[k] < 0 || c[k] >= n)
        throw InputError(where + ": triangle " + std::to_string(t) + " names vertex " + std::to_string(c[k]) + " of " +
                         std::to_string(n));
      if (c[k] == c[(k + 1) % 3])
        throw InputError(where + ": triangle " + std::to_string(t) + " repeats vertex " + std::to_string(c[k]));
    }
    for (int k = 0; k < 3; ++k) {
      ++incident[c[k]];
      const Index p = c[k], q = c[(k + 1) % 3];
      auto& tris = edge_triangles[edge_key(std::min(p, q), std::max(p, q))];
      tris.push_back(t);
      if (tris.size() > 2)
        throw InputError(where + ": the edge of " + vertices_named(p, q) + " has 3 or more triangles");
    }
  }
  for (Index v = 0; v < n; ++v)
    if (incident[v] == 0) throw InputError(where + ": vertex " + std::to_string(v) + " is in no triangle");
  orient(m.triangles, m.reference, edge_triangles, where);

  const OppositeVertex opp(m.triangles);

  m.valence.assign(n, 0);
  m.on_boundary.assign(n, 0);
  for (const auto& [key, tris] : edge_triangles) {
    const Index p = static_cast<Index>(key >> 32), q = static_cast<Index>(key & 0xffffffffu);
    ++m.valence[p];
    ++m.valence[q];
    if (tris.size() == 1) m.on_boundary[p] = m.on_boundary[q] = 1;
  }
  // One fan per vertex: walking the triangles around p from one of its
  // neighbours (from the clockwise end of the fan on a boundary) must visit
  // all of them, and meet as many edges as p has.
  std::vector<Index> some_neighbour(n, -1);
  for (const auto& c : m.triangles)
    for (int k = 0; k < 3; ++k) some_neighbour[c[k]] = c[(k + 1) % 3];
  for (Index p = 0; p < n; ++p) {
    Index q = some_neighbour[p], walked = 0;
    if (m.on_boundary[p])
      for (Index s = opp(q, p); s >= 0 && walked <= incident[p]; s = opp(q, p), ++walked) q = s;
    walked = 0;
    for (Index r = opp(p, q); r >= 0 && walked <= incident[p]; r = opp(p, r)) {
      ++walked;
      if (r == q) break;  // back at the start: an interior vertex
    }
    if (walked != incident[p] || m.valence[p] != incident[p] + m.on_boundary[p])
      throw InputError(where + ": the triangles at vertex " + std::to_string(p) + " do not form one fan");
  }

  // The ring of interior vertex p counter-clockwise from its neighbour q.
  auto ring = [&](Index p, Index q) {
    std::vector<Index> r(1, q);
    for (Index s = opp(p, q); s != q; s = opp(p, s)) r.push_back(s);
    return r;
  };
  m.patch_kind.resize(nt);
  m.patch_offsets.assign(1, 0);
  std::map<std::array<Index, 3>, Index> ghost_id;
  for (Index t = 0; t < nt; ++t) {
    auto& c = m.triangles[t];
    int irregular = 0, first_irregular = 0;
    bool boundary = false;
    for (int k = 0; k < 3; ++k) {
      boundary = boundary || m.on_boundary[c[k]];
      if (m.valence[c[k]] != 6 && irregular++ == 0) first_irregular = k;
    }
    std::array<Index, 12> completed;
    if (boundary && ghost_completed_patch(m, opp, c, ghost_id, completed)) {
      m.patch_kind[t] = ShellPatchKind::boundary;
      m.patch.insert(m.patch.end(), completed.begin(), completed.end());
    } else if (boundary) {
      m.patch_kind[t] = ShellPatchKind::unsupported_boundary;
    } else if (irregular > 1) {
      m.patch_kind[t] = ShellPatchKind::several_extraordinary;
    } else {
      std::rotate(c.begin(), c.begin() + first_irregular, c.end());
      const auto ra = ring(c[0], c[1]), rb = ring(c[1], c[2]), rc = ring(c[2], c[0]);
      if (irregular == 0) {
        m.patch_kind[t] = ShellPatchKind::regular;
        m.patch.insert(m.patch.end(),
                       {ra[4], ra[3], ra[5], c[0], ra[2], rb[3], c[1], c[2], rc[4], rb[4], rb[5], rc[3]});
      } else {
        m.patch_kind[t] = ShellPatchKind::extraordinary;
        m.patch.push_back(c[0]);
        m.patch.insert(m.patch.end(), ra.begin(), ra.end());
        m.patch.insert(m.patch.end(), {rb[3], rb[4], rb[5], rc[3], rc[4]});
      }
    }
    m.patch_offsets.push_back(static_cast<Index>(m.patch.size()));
  }
  return m;
}

}  // namespace shatter
