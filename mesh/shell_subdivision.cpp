#include "mesh/shell_subdivision.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>

namespace shatter {

ShellMesh loop_subdivide(const ShellMesh& m, const std::string& where) {
  const Index n = m.num_vertices();
  auto key = [](Index a, Index b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::min(a, b))) << 32) |
           static_cast<std::uint32_t>(std::max(a, b));
  };
  // Each edge's end points and the vertices opposite it (one on a
  // boundary), in order of first appearance: edge e's new vertex is n + e.
  struct Edge {
    Index a, b;
    Index opposite[2];
  };
  std::vector<Edge> edges;
  std::unordered_map<std::uint64_t, Index> edge_of;
  for (const auto& c : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const auto [it, inserted] = edge_of.try_emplace(key(c[k], c[(k + 1) % 3]), static_cast<Index>(edges.size()));
      if (inserted)
        edges.push_back({c[k], c[(k + 1) % 3], {c[(k + 2) % 3], -1}});
      else
        edges[it->second].opposite[1] = c[(k + 2) % 3];
    }
  // vertex rule: the sum over the neighbours, and the neighbours along the boundary
  std::vector<Vec3> ring_sum(n, Vec3::Zero());
  std::vector<std::vector<Index>> along(n);
  for (const Edge& e : edges) {
    ring_sum[e.a] += m.reference[e.b];
    ring_sum[e.b] += m.reference[e.a];
    if (e.opposite[1] < 0) along[e.a].push_back(e.b), along[e.b].push_back(e.a);
  }
  std::vector<Vec3> x(n + edges.size());
  for (Index v = 0; v < n; ++v) {
    if (m.on_boundary[v]) {
      // Hoppe et al. (SIGGRAPH 1994): a corner of the boundary (it turns by
      // more than kCornerTurn) stays; elsewhere the cubic B-spline rule.
      const Vec3 X = m.reference[v], in = X - m.reference[along[v][0]], out = m.reference[along[v][1]] - X;
      const bool corner = in.dot(out) < std::cos(kCornerTurn) * in.norm() * out.norm();
      x[v] = corner ? X : Vec3(0.75 * X + 0.125 * (m.reference[along[v][0]] + m.reference[along[v][1]]));
      continue;
    }
    const int N = m.valence[v];
    const double cosine = 3.0 / 8 + 0.25 * std::cos(2 * std::numbers::pi / N);
    const double beta = (5.0 / 8 - cosine * cosine) / N;
    x[v] = (1 - N * beta) * m.reference[v] + beta * ring_sum[v];
  }
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const Edge& e = edges[i];
    if (e.opposite[1] < 0)
      x[n + i] = 0.5 * (m.reference[e.a] + m.reference[e.b]);
    else
      x[n + i] = 3.0 / 8 * (m.reference[e.a] + m.reference[e.b]) +
                 1.0 / 8 * (m.reference[e.opposite[0]] + m.reference[e.opposite[1]]);
  }
  std::vector<std::array<Index, 3>> tris;
  tris.reserve(4 * m.triangles.size());
  for (const auto& [a, b, c] : m.triangles) {
    const Index ab = n + edge_of.at(key(a, b)), bc = n + edge_of.at(key(b, c)), ca = n + edge_of.at(key(c, a));
    tris.insert(tris.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
  }
  return build_shell_mesh(std::move(x), std::move(tris), where);
}

}  // namespace shatter
