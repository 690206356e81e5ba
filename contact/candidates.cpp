#include "contact/candidates.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <bit>

#include "contact/radix_sort.hpp"
#include "kernels/error.hpp"

namespace shatter {
namespace {

/// The inflated box of K points moving from x_old(k) to x_new(k), k < K.
template <size_t K, class Old, class New>
Box swept_box(Old x_old, New x_new) {
  Box b{x_old(0), x_old(0)};
  for (size_t k = 0; k < K; ++k) {
    b.lo = b.lo.cwiseMin(x_old(k)).cwiseMin(x_new(k));
    b.hi = b.hi.cwiseMax(x_old(k)).cwiseMax(x_new(k));
  }
  const double grow = kBoxInflation * (b.hi - b.lo).maxCoeff();
  b.lo.array() -= grow;
  b.hi.array() += grow;
  return b;
}

template <size_t K>
Box swept_box(const std::array<Index, K>& nodes, std::span<const Vec3> x_old, std::span<const Vec3> x_new) {
  return swept_box<K>([&](size_t k) { return x_old[nodes[k]]; }, [&](size_t k) { return x_new[nodes[k]]; });
}

/// The swept box of the K columns of a pair's points from column `first` on.
template <size_t K>
Box swept_box(const PairPoints& X_old, const PairPoints& X_new, int first) {
  return swept_box<K>([&](size_t k) { return Vec3(X_old.col(first + k)); },
                      [&](size_t k) { return Vec3(X_new.col(first + k)); });
}

template <size_t K, class Nodes>
void fill_boxes(std::vector<Box>& out, const Nodes& nodes, std::span<const Vec3> x_old,
                std::span<const Vec3> x_new) {
  out.resize(nodes.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nodes.size()),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t k = r.begin(); k != r.end(); ++k) {
                        if constexpr (K == 1)
                          out[k] = swept_box(std::array<Index, 1>{nodes[k]}, x_old, x_new);
                        else
                          out[k] = swept_box(nodes[k], x_old, x_new);
                      }
                    });
}

}  // namespace

SweptBoxes swept_boxes(const ContactSurface& surface, std::span<const Vec3> x_old,
                       std::span<const Vec3> x_new) {
  SHATTER_REQUIRE(x_old.size() == x_new.size(),
                  "swept_boxes: x_old has " << x_old.size() << " nodes, x_new " << x_new.size());
  SHATTER_REQUIRE(
      surface.vertices.empty() || static_cast<size_t>(surface.vertices.back()) < x_old.size(),
      "swept_boxes: surface node " << surface.vertices.back() << " beyond the " << x_old.size()
                                   << " positions");
  SweptBoxes boxes;
  fill_boxes<3>(boxes.triangles, surface.triangles, x_old, x_new);
  fill_boxes<2>(boxes.edges, surface.edges, x_old, x_new);
  fill_boxes<1>(boxes.vertices, surface.vertices, x_old, x_new);
  return boxes;
}

std::optional<ContactPair> vertex_face_pair(const ContactSurface& surface, Index v, Index t) {
  const Index n = surface.vertices[v];
  const auto& tri = surface.triangles[t];
  if (n == tri[0] || n == tri[1] || n == tri[2]) return std::nullopt;
  return ContactPair{ContactPair::VertexFace, {n, tri[0], tri[1], tri[2]}};
}

std::optional<ContactPair> edge_edge_pair(const ContactSurface& surface, Index e, Index f) {
  SHATTER_ASSERT(e < f);
  const auto& a = surface.edges[e];
  const auto& b = surface.edges[f];
  if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) return std::nullopt;
  return ContactPair{ContactPair::EdgeEdge, {a[0], a[1], b[0], b[1]}};
}

bool pair_boxes_overlap(ContactPair::Kind kind, const PairPoints& X_old, const PairPoints& X_new, double reach) {
  const bool vf = kind == ContactPair::VertexFace;
  Box a = vf ? swept_box<1>(X_old, X_new, 0) : swept_box<2>(X_old, X_new, 0);
  const Box b = vf ? swept_box<3>(X_old, X_new, 1) : swept_box<2>(X_old, X_new, 2);
  if (reach > 0.0) {
    a.lo.array() -= reach;
    a.hi.array() += reach;
  }
  return boxes_overlap(a, b);
}

bool pair_boxes_overlap(const ContactPair& pair, std::span<const Vec3> x_old, std::span<const Vec3> x_new) {
  PairPoints X_old, X_new;
  for (int k = 0; k < 4; ++k) {
    X_old.col(k) = x_old[pair.nodes[k]];
    X_new.col(k) = x_new[pair.nodes[k]];
  }
  return pair_boxes_overlap(pair.kind, X_old, X_new);
}

namespace {

/// The records in the canonical order of their pairs, without repeats (a record
/// is a pair, or a pair and its primitive, which the pair determines). A radix sort
/// on (kind, nodes) packed into 96 bits when every node id fits 23 bits (8.4 M
/// nodes), oneTBB's comparison sort otherwise: the same list either way, for any
/// thread count.
template <class Record, class PairOf>
void sort_pairs_unique(std::vector<Record>& records, PairOf pair_of) {
  const size_t n = records.size();
  const Index most = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, n), Index{0},
      [&](const tbb::blocked_range<size_t>& r, Index m) {
        for (size_t k = r.begin(); k != r.end(); ++k)
          for (const Index node : pair_of(records[k]).nodes) m = std::max(m, node);
        return m;
      },
      [](Index a, Index b) { return std::max(a, b); });
  const int w = static_cast<int>(std::bit_width(static_cast<std::uint32_t>(most)));
  if (1 + 4 * w <= 96) {
    std::vector<RadixRecord> keys(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k != r.end(); ++k) {
        const ContactPair& p = pair_of(records[k]);
        unsigned __int128 key = p.kind;
        for (const Index node : p.nodes) key = (key << w) | static_cast<std::uint32_t>(node);
        keys[k] = {static_cast<std::uint64_t>(key >> 32), static_cast<std::uint32_t>(key), static_cast<Index>(k)};
      }
    });
    radix_sort(keys);
    std::vector<Record> sorted(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k != r.end(); ++k) sorted[k] = records[keys[k].id];
    });
    records.swap(sorted);
  } else {
    tbb::parallel_sort(records.begin(), records.end());
  }
  records.erase(std::unique(records.begin(), records.end()), records.end());
}

}  // namespace

void canonicalize(ContactPairs& pairs) {
  sort_pairs_unique(pairs, [](const ContactPair& p) -> const ContactPair& { return p; });
}

ContactPairs find_candidates(const ContactSurface& surface, std::span<const Vec3> x_old,
                             std::span<const Vec3> x_new) {
  return find_candidates(surface, swept_boxes(surface, x_old, x_new));
}

namespace {

/// The search of find_candidates: out(pair, primitive) for every candidate (the primitive
/// being the face, or the first edge, numbered as in OwnedPairs), on the thread's
/// buffer; an edge-edge pair only when its first edge is kept (kept_edges empty: all).
template <class Record, class Make>
std::vector<Record> search_pairs(const ContactSurface& surface, const SweptBoxes& boxes,
                                 std::span<const std::uint8_t> kept_edges, Make make) {
  SparseBucket triangles, edges;
  tbb::parallel_invoke([&] { triangles = build_sparse_bucket(boxes.triangles); },
                       [&] { edges = build_sparse_bucket(boxes.edges); });
  tbb::enumerable_thread_specific<std::vector<Record>> buffers;
  // One range of independent tasks: vertex queries against the triangles,
  // then the edge self join by cells, then edges against larger edges on
  // higher levels (none when all edges share one level).
  const size_t nv = boxes.vertices.size(), nc = edges.cell_key.size();
  const size_t ne_above = edges.num_levels() > 1 ? boxes.edges.size() : 0;
  const auto nt = static_cast<Index>(surface.triangles.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv + nc + ne_above, 64),
                    [&](const tbb::blocked_range<size_t>& r) {
                      std::vector<Record>& out = buffers.local();
                      auto add_edge_pair = [&](Index a, Index b) {
                        const Index first = std::min(a, b);
                        if (!kept_edges.empty() && !kept_edges[first]) return;
                        if (auto p = edge_edge_pair(surface, first, std::max(a, b)))
                          out.push_back(make(*p, nt + first));
                      };
                      for (size_t k = r.begin(); k != r.end(); ++k) {
                        if (k < nv) {
                          const auto v = static_cast<Index>(k);
                          query_sparse_bucket(triangles, boxes.triangles, boxes.vertices[k],
                                              [&](Index t) {
                                                if (auto p = vertex_face_pair(surface, v, t))
                                                  out.push_back(make(*p, t));
                                              });
                        } else if (k < nv + nc) {
                          self_join_sparse_bucket_cell(edges, boxes.edges,
                                                       static_cast<Index>(k - nv), add_edge_pair);
                        } else {
                          self_join_sparse_bucket_above(
                              edges, boxes.edges, static_cast<Index>(k - nv - nc), add_edge_pair);
                        }
                      }
                    });
  // Which buffer holds a record depends on the schedule; the caller's sort on a total
  // order makes the list unique.
  size_t total = 0;
  for (const auto& b : buffers) total += b.size();
  std::vector<Record> all;
  all.reserve(total);
  for (const auto& b : buffers) all.insert(all.end(), b.begin(), b.end());
  return all;
}

}  // namespace

ContactPairs find_candidates(const ContactSurface& surface, const SweptBoxes& boxes) {
  ContactPairs pairs =
      search_pairs<ContactPair>(surface, boxes, {}, [](const ContactPair& p, Index) { return p; });
  canonicalize(pairs);
  return pairs;
}

OwnedPairs find_owned_candidates(const ContactSurface& surface, const SweptBoxes& boxes,
                                 std::span<const std::uint8_t> kept_edges) {
  using Record = std::pair<ContactPair, Index>;
  std::vector<Record> found = search_pairs<Record>(surface, boxes, kept_edges,
                                                   [](const ContactPair& p, Index q) { return Record{p, q}; });
  sort_pairs_unique(found, [](const Record& r) -> const ContactPair& { return r.first; });
  OwnedPairs out;
  out.pairs.reserve(found.size());
  out.primitive.reserve(found.size());
  for (const auto& [p, q] : found) out.pairs.push_back(p), out.primitive.push_back(q);
  return out;
}

ContactPairs find_candidates_brute_force(const ContactSurface& surface, const SweptBoxes& boxes) {
  ContactPairs pairs;
  const auto nv = static_cast<Index>(boxes.vertices.size()),
             nt = static_cast<Index>(boxes.triangles.size());
  const auto ne = static_cast<Index>(boxes.edges.size());
  for (Index v = 0; v < nv; ++v)
    for (Index t = 0; t < nt; ++t)
      if (boxes_overlap(boxes.vertices[v], boxes.triangles[t]))
        if (auto p = vertex_face_pair(surface, v, t)) pairs.push_back(*p);
  for (Index e = 0; e < ne; ++e)
    for (Index f = e + 1; f < ne; ++f)
      if (boxes_overlap(boxes.edges[e], boxes.edges[f]))
        if (auto p = edge_edge_pair(surface, e, f)) pairs.push_back(*p);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

}  // namespace shatter
