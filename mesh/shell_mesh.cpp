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
/// A vertex's weights in a ghost's position, ascending by vertex.
using Terms = std::vector<std::pair<Index, double>>;

/// a + s b, merged by vertex, zeros dropped.
Terms combine(const Terms& a, const Terms& b, double s) {
  Terms out;
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && a[i].first < b[j].first)) {
      out.push_back(a[i++]);
    } else if (i == a.size() || b[j].first < a[i].first) {
      out.emplace_back(b[j].first, s * b[j].second);
      ++j;
    } else {
      out.emplace_back(a[i].first, a[i].second + s * b[j].second);
      ++i, ++j;
    }
    if (out.back().second == 0) out.pop_back();
  }
  return out;
}

/// The ghosts' positions as x_g = shift + sum w x (ShellMesh::ghost_offsets
/// ...), reflection after reflection, each odd or even (ghost_even).
void resolve_ghosts(ShellMesh& m) {
  const Index n = m.num_vertices(), ng = m.num_ghosts();
  std::vector<Terms> terms(ng);
  m.ghost_shift.assign(ng, Vec3::Zero());
  auto entry_terms = [&](Index e) { return e < n ? Terms{{e, 1.0}} : terms[e - n]; };
  auto entry_shift = [&](Index e) { return e < n ? Vec3::Zero() : m.ghost_shift[e - n]; };
  auto entry_reference = [&](Index e) { return e < n ? m.reference[e] : m.ghost_reference[e - n]; };
  for (Index g = 0; g < ng; ++g) {
    const GhostReflection& r = m.ghost_reflection[g];
    if (m.ghost_even[g]) {
      terms[g] = entry_terms(r.mirror);
      m.ghost_shift[g] = entry_shift(r.mirror) + m.ghost_reference[g] - entry_reference(r.mirror);
      continue;
    }
    Terms t;
    for (const auto& [e, w] : r.foot) {
      t = combine(t, entry_terms(e), 2 * w);
      m.ghost_shift[g] += 2 * w * entry_shift(e);
    }
    terms[g] = combine(t, entry_terms(r.mirror), -1.0);
    m.ghost_shift[g] -= entry_shift(r.mirror);
  }
  m.ghost_offsets.assign(1, 0);
  m.ghost_vertex.clear();
  m.ghost_weight.clear();
  for (const Terms& t : terms) {
    for (const auto& [v, w] : t) m.ghost_vertex.push_back(v), m.ghost_weight.push_back(w);
    m.ghost_offsets.push_back(static_cast<Index>(m.ghost_vertex.size()));
  }
}

/// The boundary edges of the control mesh, per vertex: its neighbours along the boundary.
std::vector<std::vector<Index>> boundary_neighbours(const ShellMesh& m, const OppositeVertex& opp) {
  std::vector<std::vector<Index>> out(m.num_vertices());
  for (const auto& c : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const Index p = c[k], q = c[(k + 1) % 3];
      if (opp(q, p) < 0) out[p].push_back(q), out[q].push_back(p);
    }
  return out;
}

/// A ghost's mirror image is across the boundary from it when the offset
/// between them is normal to the boundary edge: |cos| of their angle, 0 for
/// a true mirror image. Reflections with a score above this are not mirror
/// images (e.g. through the corner of a rectangle, diagonally).
constexpr double kMirrorScore = 0.5;
/// Two boundary edges meet at a right angle when |cos| of their angle is below this.
constexpr double kRightAngle = 1e-3;

/// The 12-vertex patch of triangle c (corners 4, 7, 8 = c[0], c[1], c[2])
/// with a corner on the boundary, completed by ghost vertices, or false.
/// The fans of the three corners are unfolded onto the regular lattice
/// (each must fit it: interior corners of valence 6, no overlap); a lattice
/// point P of the patch with no vertex becomes a ghost vertex, the
/// reflection of a lattice point across the boundary (candidates below),
/// or at a corner of the boundary, where no single reflection is a mirror
/// image, the reflection across one edge of a ghost across the other.
/// New ghosts are appended to m (deduplicated by their weights, `ghost_id`).
bool ghost_completed_patch(ShellMesh& m, const OppositeVertex& opp, const std::vector<std::vector<Index>>& along,
                           const std::array<Index, 3>& c, std::map<Terms, Index>& ghost_id,
                           std::vector<Terms>& ghost_terms, std::array<Index, 12>& patch) {
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
  // The fan of p onto the lattice, from its placed neighbour q.
  auto unfold = [&](Index p, Index q) {
    // counter-clockwise: triangle (p, prev, r) has r = p + rot60(prev - p)
    Index prev = q;
    for (Index r = opp(p, prev); r >= 0 && r != q && flat; prev = r, r = opp(p, prev))
      place(r, add(at[p], rot60(add(at[prev], at[p], -1)), 1));
    // clockwise: triangle (prev, p, s) has s = prev + rot60(p - prev)
    prev = q;
    for (Index s = opp(prev, p); s >= 0 && s != q && flat; prev = s, s = opp(prev, p))
      place(s, add(at[prev], rot60(add(at[p], at[prev], -1)), 1));
  };
  for (int k = 0; k < 3 && flat; ++k) {
    if (!m.on_boundary[c[k]] && m.valence[c[k]] != 6) return false;
    unfold(c[k], c[(k + 1) % 3]);
  }
  // and the fans of the boundary vertices among them, where the mirror
  // images of the ghosts lie (the two patches on either side of an edge then
  // see the same candidates)
  std::vector<std::pair<Index, Index>> boundary_fans;
  for (const auto& [v, x] : at)
    if (m.on_boundary[v] && v != c[0] && v != c[1] && v != c[2])
      for (const Index q : along[v])
        if (at.count(q)) boundary_fans.emplace_back(v, q);
  for (const auto& [v, q] : boundary_fans)
    if (flat) unfold(v, q);
  if (!flat) return false;
  const Index n = m.num_vertices();
  std::map<Lattice, Index> entry_at;  // lattice point -> patch entry (vertex, or n + ghost)
  for (const auto& [v, x] : at)
    if (!entry_at.emplace(x, v).second) return false;  // the fans overlap: not a flat lattice
  auto reference = [&](Index e) { return e < n ? m.reference[e] : m.ghost_reference[e - n]; };
  auto terms_of = [&](Index e) { return e < n ? Terms{{e, 1.0}} : ghost_terms[e - n]; };

  struct Candidate {
    GhostReflection rule;
    double score = HUGE_VAL;
  };
  // The reflection of `mirror` through `foot` across the boundary edge (b, e),
  // scored by how nearly it is the ghost's mirror image across that edge.
  auto consider = [&](Candidate& best, const Terms& foot, Index mirror, Index b, Index e) {
    Vec3 x_foot = Vec3::Zero();
    for (const auto& [f, w] : foot) x_foot += w * reference(f);
    const Vec3 d = reference(mirror) - (2 * x_foot - reference(mirror));
    const Vec3 edge = m.reference[e] - m.reference[b];
    const double score = std::abs(d.dot(edge)) / (d.norm() * edge.norm());
    if (score < best.score - 1e-9) best = {{{std::min(b, e), std::max(b, e)}, foot, mirror}, score};
  };
  auto add_ghost = [&](Index a, const GhostReflection& rule) {
    Terms t;
    Vec3 x_foot = Vec3::Zero();
    for (const auto& [f, w] : rule.foot) t = combine(t, terms_of(f), 2 * w), x_foot += w * reference(f);
    t = combine(t, terms_of(rule.mirror), -1.0);
    const auto [g, inserted] = ghost_id.try_emplace(t, m.num_ghosts());
    if (inserted) {
      m.ghost_reflection.push_back(rule);
      m.ghost_reference.push_back(2 * x_foot - reference(rule.mirror));
      m.ghost_even.push_back(0);
      ghost_terms.push_back(std::move(t));
    }
    patch[a] = n + g->second;
    entry_at[{kLoopRegularLattice[a][0], kLoopRegularLattice[a][1]}] = n + g->second;
  };
  static constexpr Lattice kAround[6] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};
  std::vector<std::pair<int, Candidate>> corner;  // lattice points left for the corner rule
  for (int a = 0; a < 12; ++a) {
    const Lattice P{kLoopRegularLattice[a][0], kLoopRegularLattice[a][1]};
    if (const auto it = entry_at.find(P); it != entry_at.end()) {
      patch[a] = it->second;
      continue;
    }
    // Candidates: for each boundary edge (B1, B2) next to P, the reflection
    // of the edge triangle's third vertex A through the edge's midpoint; for
    // each boundary vertex B next to P, of the vertex Q = 2 B - P through B,
    // across either boundary edge at B. All put the ghost on the lattice
    // point; the one whose partner (A or Q) is most nearly the ghost's mirror
    // image across its edge is taken, so that held boundary vertices make an
    // odd reflection of the control net.
    Candidate best;
    for (int k = 0; k < 6; ++k) {
      const auto b1 = entry_at.find(add(P, kAround[k], 1)), b2 = entry_at.find(add(P, kAround[(k + 1) % 6], 1));
      if (b1 == entry_at.end() || b1->second >= n || !m.on_boundary[b1->second]) continue;
      const Index B = b1->second;
      if (const auto q = entry_at.find(add(add(b1->first, b1->first, 1), P, -1)); q != entry_at.end() && q->second < n)
        for (const Index e : along[B]) consider(best, {{B, 1.0}}, q->second, B, e);
      if (b2 == entry_at.end() || b2->second >= n) continue;
      const Index B2 = b2->second, A12 = opp(B, B2), A21 = opp(B2, B);
      if ((A12 >= 0) == (A21 >= 0)) continue;  // not a boundary edge
      const Index A = A12 >= 0 ? A12 : A21;
      const Lattice reflected = add(add(b1->first, b2->first, 1), P, -1);
      if (const auto ia = at.find(A); ia == at.end() || ia->second == reflected)
        consider(best, {{std::min(B, B2), 0.5}, {std::max(B, B2), 0.5}}, A, B, B2);
    }
    if (best.score < kMirrorScore)
      add_ghost(a, best.rule);
    else
      corner.emplace_back(a, best);
  }
  // At a right-angled corner of the boundary: P = 2 B - Q along a lattice
  // line, B a ghost and Q a ghost or vertex, across the boundary edge of the
  // patch most nearly normal to the line and at right angles to B's (the
  // reflection across the second edge of a ghost across the first).
  // Without one, the best single reflection.
  std::vector<std::array<Index, 2>> edges;
  for (const auto& [v, x] : at)
    for (const Index e : along[v])
      if (v < e && at.count(e)) edges.push_back({v, e});
  for (auto& [a, best] : corner) {
    const Lattice P{kLoopRegularLattice[a][0], kLoopRegularLattice[a][1]};
    Candidate composed;
    for (const Lattice& d : kAround) {
      const auto b = entry_at.find(add(P, d, 1)), q = entry_at.find(add(P, d, 2));
      if (b == entry_at.end() || q == entry_at.end() || b->second < n) continue;
      const auto& [f1, f2] = m.ghost_reflection[b->second - n].edge;
      const Vec3 first = m.reference[f2] - m.reference[f1];
      for (const auto& [e1, e2] : edges) {
        // Only at a right-angled corner do the two reflections commute (the
        // patches on either side of an edge then agree); elsewhere (corners
        // of 60 or 120 degrees) the best single reflection, kept where the
        // patches agree (drop_nonconforming_patches).
        const Vec3 second = m.reference[e2] - m.reference[e1];
        if (std::abs(first.dot(second)) < kRightAngle * first.norm() * second.norm())
          consider(composed, {{b->second, 1.0}}, q->second, e1, e2);
      }
    }
    const Candidate& take = composed.score < kMirrorScore ? composed : best;
    if (take.score == HUGE_VAL) return false;
    add_ghost(a, take.rule);
  }
  return true;
}

/// Two lattice patches (regular or boundary) on either side of an edge
/// share the 10 lattice points whose basis functions reach the edge (the
/// others' vanish there with their first and second derivatives): the patches
/// meet with their tangent planes when those are the same 10 entries. Where
/// ghosts chosen in each patch disagree (a boundary that is not straight in
/// the lattice, as Gmsh's unstructured ones), the boundary patches become
/// unsupported_boundary.
void drop_nonconforming_patches(ShellMesh& m, const std::unordered_map<EdgeKey, std::vector<Index>>& edge_triangles) {
  auto lattice = [&](Index t) {
    return m.patch_kind[t] == ShellPatchKind::regular || m.patch_kind[t] == ShellPatchKind::boundary;
  };
  std::vector<char> drop(m.num_triangles(), 0);
  for (const auto& [key, tris] : edge_triangles) {
    if (tris.size() != 2 || !lattice(tris[0]) || !lattice(tris[1])) continue;
    std::array<Index, 12> a, b;
    std::copy_n(m.patch_of(tris[0]), 12, a.begin());
    std::copy_n(m.patch_of(tris[1]), 12, b.begin());
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    std::array<Index, 12> common;
    if (std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), common.begin()) - common.begin() == 10) continue;
    for (const Index t : tris) drop[t] = m.patch_kind[t] == ShellPatchKind::boundary;
  }
  std::vector<Index> patch;
  std::vector<Index> offsets(1, 0);
  for (Index t = 0; t < m.num_triangles(); ++t) {
    if (drop[t]) m.patch_kind[t] = ShellPatchKind::unsupported_boundary;
    else patch.insert(patch.end(), m.patch_of(t), m.patch_of(t) + m.patch_size(t));
    offsets.push_back(static_cast<Index>(patch.size()));
  }
  m.patch = std::move(patch);
  m.patch_offsets = std::move(offsets);
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
  std::map<Terms, Index> ghost_id;
  std::vector<Terms> ghost_terms;
  const auto along = boundary_neighbours(m, opp);
  for (Index t = 0; t < nt; ++t) {
    auto& c = m.triangles[t];
    int irregular = 0, first_irregular = 0;
    bool boundary = false;
    for (int k = 0; k < 3; ++k) {
      boundary = boundary || m.on_boundary[c[k]];
      if (m.valence[c[k]] != 6 && irregular++ == 0) first_irregular = k;
    }
    std::array<Index, 12> completed;
    if (boundary && ghost_completed_patch(m, opp, along, c, ghost_id, ghost_terms, completed)) {
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
  drop_nonconforming_patches(m, edge_triangles);
  resolve_ghosts(m);
  return m;
}

void clamp_shell_edges(ShellMesh& m, const std::vector<std::uint8_t>& clamped) {
  for (Index g = 0; g < m.num_ghosts(); ++g) {
    const auto [a, b] = m.ghost_reflection[g].edge;
    m.ghost_even[g] = clamped[a] && clamped[b];
  }
  resolve_ghosts(m);
}

}  // namespace shatter
