#include "contact/surface.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <iterator>
#include <tuple>

#include "kernels/error.hpp"
#include "kernels/tet10.hpp"

namespace shatter {
namespace {

/// Outward faces of a positive tetrahedron (Gmsh corner order).
constexpr std::array<std::array<int, 3>, 4> kOutwardFaces = {
    {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};

/// Sorted unique edges {lo, hi} and vertices of a range of triangles.
void triangle_edges_and_vertices(std::span<const SurfaceTriangle> triangles,
                                 std::vector<std::array<Index, 2>>& edges,
                                 std::vector<Index>& vertices) {
  edges.clear();
  vertices.clear();
  edges.reserve(3 * triangles.size());
  vertices.reserve(3 * triangles.size());
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      const Index a = t.nodes[k], b = t.nodes[(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b)});
      vertices.push_back(a);
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
}

/// sorted-unique `into` := sorted-unique union of `into` and `more`.
template <class T>
void merge_unique(std::vector<T>& into, const std::vector<T>& more) {
  std::vector<T> merged;
  merged.reserve(into.size() + more.size());
  std::set_union(into.begin(), into.end(), more.begin(), more.end(), std::back_inserter(merged));
  into.swap(merged);
}

/// Local TET10 node on the edge between corners i and j.
int tet10_mid_node(int i, int j) {
  for (int e = 0; e < 6; ++e) {
    const auto [a, b] = kTet10Edges[e];
    if ((a == i && b == j) || (a == j && b == i)) return 4 + e;
  }
  SHATTER_ASSERT(false);
  return -1;
}

/// Per order (1, 2) and outward face: the local node triples of its sub-triangles.
std::array<std::array<std::vector<std::array<int, 3>>, 4>, 2> make_face_triangles() {
  std::array<std::array<std::vector<std::array<int, 3>>, 4>, 2> table;
  for (int f = 0; f < 4; ++f) {
    const auto [a, b, c] = kOutwardFaces[f];
    table[0][f] = {{a, b, c}};
    const int ab = tet10_mid_node(a, b), bc = tet10_mid_node(b, c), ca = tet10_mid_node(c, a);
    table[1][f] = {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}};
  }
  return table;
}

}  // namespace

std::span<const std::array<int, 3>> face_triangles(int order, int face) {
  static const auto table = make_face_triangles();
  return table[order - 1][face];
}

ContactSurface build_contact_surface(const Mesh& mesh) { return build_contact_surface(mesh, {}); }

ContactSurface build_contact_surface(const Mesh& mesh, std::span<const MeshFace> skip) {
  std::vector<SurfaceTriangle> triangles;
  for (const auto& [e, f] : boundary_faces(mesh, skip)) {
    const Index* n = mesh.element(e);
    for (const auto& t : face_triangles(mesh.order, f))
      triangles.push_back({{n[t[0]], n[t[1]], n[t[2]]}, mesh.elem_body[e]});
  }
  return make_contact_surface(triangles);
}

std::vector<MeshFace> boundary_faces(const Mesh& mesh, std::span<const MeshFace> skip) {
  SHATTER_REQUIRE(mesh.order == 1 || mesh.order == 2, "boundary_faces: mesh order "
                                                          << mesh.order << " (expected 1 = TET4 or 2 = TET10)");
  // Every face as (sorted corner ids, element, local face); a face is on the
  // boundary when its sorted key occurs once.
  struct Face {
    std::array<Index, 3> key;
    Index elem;
    int local;
  };
  const Index ne = mesh.num_elements();
  std::vector<Face> faces;
  faces.reserve(4 * static_cast<size_t>(ne));
  for (Index e = 0; e < ne; ++e) {
    const Index* n = mesh.element(e);
    for (int f = 0; f < 4; ++f) {
      std::array<Index, 3> key = {n[kOutwardFaces[f][0]], n[kOutwardFaces[f][1]],
                                  n[kOutwardFaces[f][2]]};
      std::sort(key.begin(), key.end());
      faces.push_back({key, e, f});
    }
  }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
    return std::tie(a.key, a.elem, a.local) < std::tie(b.key, b.elem, b.local);
  });
  std::vector<MeshFace> boundary;
  for (size_t i = 0; i < faces.size();) {
    size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i == 1 && !std::binary_search(skip.begin(), skip.end(), MeshFace(faces[i].elem, faces[i].local)))
      boundary.emplace_back(faces[i].elem, faces[i].local);
    i = j;
  }
  std::sort(boundary.begin(), boundary.end());
  return boundary;
}

ContactSurface make_contact_surface(std::span<const SurfaceTriangle> triangles) {
  ContactSurface s;
  add_triangles(s, triangles);
  return s;
}

void add_triangles(ContactSurface& surface, std::span<const SurfaceTriangle> triangles) {
  surface.triangles.reserve(surface.triangles.size() + triangles.size());
  surface.body.reserve(surface.body.size() + triangles.size());
  for (const auto& t : triangles) {
    surface.triangles.push_back(t.nodes);
    surface.body.push_back(t.body);
  }
  std::vector<std::array<Index, 2>> edges;
  std::vector<Index> vertices;
  triangle_edges_and_vertices(triangles, edges, vertices);
  merge_unique(surface.edges, edges);
  merge_unique(surface.vertices, vertices);
}

double median_edge_length(const ContactSurface& surface, std::span<const Vec3> x) {
  if (surface.edges.empty()) return 0;
  std::vector<double> lengths;
  lengths.reserve(surface.edges.size());
  for (const auto& [a, b] : surface.edges) lengths.push_back((x[a] - x[b]).norm());
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  return lengths[lengths.size() / 2];
}

VertexTriangles vertex_triangles(const ContactSurface& surface) {
  // A counting sort: the triangles are visited in order, so each vertex's come ascending.
  VertexTriangles out;
  out.position.assign(surface.vertices.empty() ? 0 : surface.vertices.back() + 1, -1);
  for (size_t k = 0; k < surface.vertices.size(); ++k) out.position[surface.vertices[k]] = static_cast<Index>(k);
  out.offsets.assign(surface.vertices.size() + 1, 0);
  for (const auto& t : surface.triangles)
    for (const Index n : t) ++out.offsets[out.position[n] + 1];
  for (size_t k = 0; k < surface.vertices.size(); ++k) out.offsets[k + 1] += out.offsets[k];
  out.items.resize(out.offsets.back());
  std::vector<Index> fill(out.offsets.begin(), out.offsets.end() - 1);
  for (size_t t = 0; t < surface.triangles.size(); ++t)
    for (const Index n : surface.triangles[t]) out.items[fill[out.position[n]]++] = static_cast<Index>(t);
  return out;
}

void triangle_normals(const ContactSurface& surface, std::span<const Vec3> x, std::span<const Index> triangles,
                      TriangleNormals& tn) {
  const size_t nt = surface.triangles.size(), n = triangles.empty() ? nt : triangles.size();
  tn.normal.resize(nt);
  tn.length.resize(nt);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const size_t i = triangles.empty() ? k : static_cast<size_t>(triangles[k]);
      const auto& t = surface.triangles[i];
      tn.normal[i] = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
      tn.length[i] = tn.normal[i].norm();
    }
  });
}

TriangleNormals triangle_normals(const ContactSurface& surface, std::span<const Vec3> x) {
  TriangleNormals tn;
  triangle_normals(surface, x, {}, tn);
  return tn;
}

Vec3 surface_normal(const ContactSurface& surface, const VertexTriangles& around, const TriangleNormals& tn,
                    Index node, Index other) {
  SHATTER_REQUIRE(node >= 0 && static_cast<size_t>(node) < around.position.size() && around.position[node] >= 0 &&
                      around.offsets.size() == surface.vertices.size() + 1 &&
                      tn.normal.size() == surface.triangles.size(),
                  "surface_normal: node " << node << " is not a vertex of the surface, or the vertex -> triangle "
                                          << "CSR or the triangle normals are not the surface's");
  const auto k = static_cast<size_t>(around.position[node]);
  Vec3 n = Vec3::Zero();
  double sum = 0;  // of the triangles' |normal|: what the two sides of a sheet cancel to round-off
  for (Index j = around.offsets[k]; j < around.offsets[k + 1]; ++j) {
    const Index i = around.items[j];
    const auto& t = surface.triangles[i];
    if (other < 0 || t[0] == other || t[1] == other || t[2] == other) {
      n += tn.normal[i];
      sum += tn.length[i];
    }
  }
  return n.norm() > 1e-9 * sum ? n : Vec3::Zero();
}

Vec3 edge_face_normal(const ContactSurface& surface, const VertexTriangles& around, const TriangleNormals& tn,
                      Index from, Index to) {
  SHATTER_REQUIRE(from >= 0 && static_cast<size_t>(from) < around.position.size() && around.position[from] >= 0 &&
                      tn.normal.size() == surface.triangles.size(),
                  "edge_face_normal: node " << from << " is not a vertex of the surface, or the triangle normals "
                                            << "are not the surface's");
  const auto k = static_cast<size_t>(around.position[from]);
  int forward = 0, backward = 0;
  Vec3 n = Vec3::Zero();
  for (Index j = around.offsets[k]; j < around.offsets[k + 1]; ++j) {
    const Index i = around.items[j];
    const auto& t = surface.triangles[i];
    for (int c = 0; c < 3; ++c) {
      if (t[c] == from && t[(c + 1) % 3] == to) ++forward, n = tn.normal[i];
      if (t[c] == to && t[(c + 1) % 3] == from) ++backward;
    }
  }
  return forward == 1 && backward == 1 ? n : Vec3::Zero();
}

}  // namespace shatter
