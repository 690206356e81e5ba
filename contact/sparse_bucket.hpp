#pragma once
// Sparse-bucket orthogonal range query (Cirak, Knap & Ortiz, "Parallel
// fragmentation with contact", the contact search section): a grid of buckets
// in two directions u, v whose non-empty cells are kept in a sorted list, and
// inside each cell the boxes sorted along the third direction w, searched by
// bisection. Memory is O(number of boxes), independent of the bounding volume.
//
// Boxes of very different sizes are handled by levels: level l has cells of
// side h_l = h_0 4^l and holds the boxes whose largest side is in
// (h_{l-1}, h_l], so every box spans at most 2 x 2 cells of its level and the
// w-extent of a cell's boxes is at most h_l. A single huge box sits alone on a
// high level and costs every query O(1) cell visits, not O(area / h_0^2).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

/// Closed axis-aligned box [lo, hi], m.
struct Box {
  Vec3 lo;
  Vec3 hi;
};

/// Closed-interval overlap: touching boxes overlap.
inline bool boxes_overlap(const Box& a, const Box& b) {
  return a.lo[0] <= b.hi[0] && b.lo[0] <= a.hi[0] && a.lo[1] <= b.hi[1] && b.lo[1] <= a.hi[1] &&
         a.lo[2] <= b.hi[2] && b.lo[2] <= a.hi[2];
}

/// The search structure over a span of boxes (which the caller keeps alive and
/// passes again to each query). Ids are positions in that span.
///
/// Layouts (L levels, C non-empty cells over all levels, N entries = box-cell
/// incidences, N <= 4 x boxes up to rounding in floor):
///   axis = {u, v, w}                w = the axis along which all boxes spread most
///   origin[2]                       lowest lo along u and v
///   cell_size[L]                    h_l = h_0 4^l; h_0 = 2 x the median largest box side
///   cell_inverse[L]                 1 / h_l
///   level_cells[L+1]                cells of level l: [level_cells[l], level_cells[l+1])
///   cell_key[C]                     (l << 58) | (i << 29) | j, ascending, with cell indices
///                                   i = floor((x_u - origin_u) / h_l), j likewise along v
///   cell_entries[C+1]               entries of cell c: [cell_entries[c], cell_entries[c+1])
///   cell_max_extent[C]              max over the cell's boxes of hi_w - lo_w
///   entry_bound[k][N + 16], k < 6   the box's {lo_w, hi_w, lo_u, hi_u, lo_v, hi_v} as floats
///                                   rounded outward; lo_w ascending within a cell (entries
///                                   sorted by it, then by id); 16 padding entries that
///                                   overlap nothing
///   entry_box[N]                    box id
/// The float bounds contain the box, so they filter the candidates of a cell
/// from contiguous memory (28 bytes an entry), 16 entries at a time
/// (sparse_bucket_filter), without dropping an overlap; only the survivors are
/// tested exactly on the double boxes.
struct SparseBucket {
  std::array<int, 3> axis = {0, 1, 2};
  std::array<double, 2> origin = {0, 0};
  std::vector<double> cell_size;
  std::vector<double> cell_inverse;
  std::vector<Index> level_cells = {0};
  std::vector<std::uint64_t> cell_key;
  std::vector<Index> cell_entries = {0};
  std::vector<double> cell_max_extent;
  enum Bound { kLoW, kHiW, kLoU, kHiU, kLoV, kHiV };
  std::array<std::vector<float>, 6> entry_bound;
  std::vector<Index> entry_box;
  static constexpr int kLanes = 16;  ///< entries filtered at once, and the padding

  int num_levels() const { return static_cast<int>(cell_size.size()); }
  static constexpr int kCellBits = 29;
  static constexpr std::uint64_t kCellMask = (std::uint64_t(1) << kCellBits) - 1;

  /// Bucket index of coordinate x along grid axis k (0 = u, 1 = v) on level l,
  /// in [0, 2^29); monotone in x, so a box's cells are [cell(lo), cell(hi)].
  std::uint64_t cell(int k, int l, double x) const {
    const double s = std::floor((x - origin[k]) * cell_inverse[l]);
    return static_cast<std::uint64_t>(std::clamp(s, 0.0, double(kCellMask)));
  }
  static std::uint64_t key(int l, std::uint64_t i, std::uint64_t j) {
    return (std::uint64_t(l) << (2 * kCellBits)) | (i << kCellBits) | j;
  }
};

/// Build the structure over `boxes` (oneTBB tasks; the result does not depend
/// on the number of threads). No tuning parameter: h_0 follows the boxes.
SparseBucket build_sparse_bucket(std::span<const Box> boxes);

/// Bytes held by the structure's arrays (the boxes themselves not included).
std::size_t memory_bytes(const SparseBucket& bucket);

/// Level of a box in a structure with base cell side h0: the smallest l with
/// largest side <= h0 4^l.
inline int sparse_bucket_level(double h0, const Box& x) {
  const double side = (x.hi - x.lo).maxCoeff();
  int l = 0;
  for (double h = h0; side > h; h *= 4.0) ++l;
  return l;
}

/// The nearest float not above (not below) x, so float bounds contain the
/// double box; beyond the float range, float_below gives FLT_MAX or -inf and
/// float_above +inf or -FLT_MAX. Written without branches: the step is taken
/// or not with equal odds.
inline float float_below(double x) {
  const auto f = static_cast<float>(x);
  const auto bits = std::bit_cast<std::uint32_t>(f);
  // one float toward -inf: a positive float's bits minus one, a negative one's plus one
  const std::uint32_t down = f > 0.0f ? bits - 1 : (f < 0.0f ? bits + 1 : 0x80000001u);
  return static_cast<double>(f) > x ? std::bit_cast<float>(down) : f;
}
inline float float_above(double x) {
  const auto f = static_cast<float>(x);
  const auto bits = std::bit_cast<std::uint32_t>(f);
  const std::uint32_t up = f > 0.0f ? bits + 1 : (f < 0.0f ? bits - 1 : 0x00000001u);
  return static_cast<double>(f) < x ? std::bit_cast<float>(up) : f;
}

/// The float bounds of a box rounded outward, in SparseBucket::Bound order.
inline std::array<float, 6> float_bounds(const SparseBucket& b, const Box& x) {
  const int u = b.axis[0], v = b.axis[1], w = b.axis[2];
  return {float_below(x.lo[w]), float_above(x.hi[w]), float_below(x.lo[u]),
          float_above(x.hi[u]), float_below(x.lo[v]), float_above(x.hi[v])};
}

/// Bit t set when entry e + t (t < 16) may overlap the float box q (Bound order)
/// and its lo_w is at most q's hi_w: one comparison of each bound, 16 lanes wide.
inline std::uint32_t sparse_bucket_filter(const SparseBucket& b, size_t e, const std::array<float, 6>& q) {
  using B = SparseBucket;
  const float* lo_w = b.entry_bound[B::kLoW].data() + e;
  const float* hi_w = b.entry_bound[B::kHiW].data() + e;
  const float* lo_u = b.entry_bound[B::kLoU].data() + e;
  const float* hi_u = b.entry_bound[B::kHiU].data() + e;
  const float* lo_v = b.entry_bound[B::kLoV].data() + e;
  const float* hi_v = b.entry_bound[B::kHiV].data() + e;
  // As 0 / -1 words first, then bits: written so, GCC vectorises both loops at
  // every SIMD level of cmake/simd.cmake (a single loop only with AVX-512).
  std::int32_t keep[B::kLanes];
  for (int t = 0; t < B::kLanes; ++t)
    keep[t] = -std::int32_t((lo_w[t] <= q[B::kHiW]) & (hi_w[t] >= q[B::kLoW]) & (lo_u[t] <= q[B::kHiU]) &
                            (hi_u[t] >= q[B::kLoU]) & (lo_v[t] <= q[B::kHiV]) & (hi_v[t] >= q[B::kLoV]));
  std::uint32_t mask = 0;
  for (int t = 0; t < B::kLanes; ++t) mask |= (std::uint32_t(keep[t]) >> 31) << t;
  return mask;
}

/// Call visit(e) for every entry e in [from, end) that passes the filter for the
/// float box q, in order; stops at the first entry whose lo_w passes q's hi_w.
template <class Visit>
void sparse_bucket_scan(const SparseBucket& b, size_t from, size_t end, const std::array<float, 6>& q,
                        Visit&& visit) {
  const std::vector<float>& lo_w = b.entry_bound[SparseBucket::kLoW];
  for (size_t e = from; e < end; e += SparseBucket::kLanes) {
    std::uint32_t mask = sparse_bucket_filter(b, e, q);
    if (end - e < SparseBucket::kLanes) mask &= (std::uint32_t(1) << (end - e)) - 1;
    for (; mask != 0; mask &= mask - 1) visit(e + static_cast<size_t>(std::countr_zero(mask)));
    // lo_w ascends within a cell: past q's hi_w here, so is every later entry.
    if (lo_w[std::min(end, e + SparseBucket::kLanes) - 1] > q[SparseBucket::kHiW]) break;
  }
}

/// Call report(id) once for every box on level l that overlaps q, whose float
/// bounds are qf (float_bounds; see query_sparse_bucket).
template <class Report>
void query_sparse_bucket_level(const SparseBucket& b, std::span<const Box> boxes, const Box& q,
                               const std::array<float, 6>& qf, int l, Report&& report) {
  const int u = b.axis[0], v = b.axis[1], w = b.axis[2];
  // relative size of a float ulp, twice, plus the smallest normal float
  constexpr double kRound = 0x1p-22;
  constexpr double kTiny = std::numeric_limits<float>::min();
  const std::uint64_t i0 = b.cell(0, l, q.lo[u]), i1 = b.cell(0, l, q.hi[u]);
  const std::uint64_t j0 = b.cell(1, l, q.lo[v]), j1 = b.cell(1, l, q.hi[v]);
  const std::vector<float>& entry_lo = b.entry_bound[SparseBucket::kLoW];
  const auto first = b.cell_key.begin() + b.level_cells[l],
             last = b.cell_key.begin() + b.level_cells[l + 1];
  // Walk only the non-empty cells of rows i0..i1, jumping over gaps by bisection.
  auto it = std::lower_bound(first, last, SparseBucket::key(l, i0, j0));
  while (it != last) {
    const std::uint64_t i = (*it >> SparseBucket::kCellBits) & SparseBucket::kCellMask;
    const std::uint64_t j = *it & SparseBucket::kCellMask;
    if (i > i1) break;
    if (j < j0) {
      it = std::lower_bound(it, last, SparseBucket::key(l, i, j0));
      continue;
    }
    if (j > j1) {
      it = std::lower_bound(it, last, SparseBucket::key(l, i + 1, j0));
      continue;
    }
    const auto c = static_cast<Index>(it - b.cell_key.begin());
    // Boxes with lo_w < q.lo_w - max extent end before q; the slack covers the
    // float rounding of the lo_w bounds, so the bisection stays conservative.
    const double m = b.cell_max_extent[c];
    const double w_from = q.lo[w] - m - kRound * (std::abs(q.lo[w]) + m) - kTiny;
    const auto lo_first = entry_lo.begin() + b.cell_entries[c];
    const auto lo_last = entry_lo.begin() + b.cell_entries[c + 1];
    const auto from = static_cast<size_t>(std::lower_bound(lo_first, lo_last, w_from) - entry_lo.begin());
    sparse_bucket_scan(b, from, static_cast<size_t>(b.cell_entries[c + 1]), qf, [&](size_t e) {
      const Index id = b.entry_box[e];
      const Box& x = boxes[id];
      if (!boxes_overlap(q, x)) return;
      if (b.cell(0, l, std::max(q.lo[u], x.lo[u])) == i && b.cell(1, l, std::max(q.lo[v], x.lo[v])) == j)
        report(id);
    });
    ++it;
  }
}

/// Call report(id) once for every box of `boxes` (the span the structure was
/// built on) that overlaps q. Each pair is reported from one cell only: the
/// cell that holds the lowest corner of the intersection, max(q.lo, box.lo).
template <class Report>
void query_sparse_bucket(const SparseBucket& b, std::span<const Box> boxes, const Box& q,
                         Report&& report) {
  const std::array<float, 6> qf = float_bounds(b, q);
  for (int l = 0; l < b.num_levels(); ++l) query_sparse_bucket_level(b, boxes, q, qf, l, report);
}

/// Self join, part 1: call report(a, b) for every overlapping pair of boxes
/// of cell c's level whose intersection's lowest corner lies in cell c, by a
/// sweep along w over the cell's sorted entries: O(entries + pairs tested).
/// Over all cells c in [0, C) every overlapping same-level pair comes once.
template <class Report>
void self_join_sparse_bucket_cell(const SparseBucket& b, std::span<const Box> boxes, Index c,
                                  Report&& report) {
  const int u = b.axis[0], v = b.axis[1];
  const std::uint64_t key = b.cell_key[c];
  const int l = static_cast<int>(key >> (2 * SparseBucket::kCellBits));
  const std::uint64_t i = (key >> SparseBucket::kCellBits) & SparseBucket::kCellMask;
  const std::uint64_t j = key & SparseBucket::kCellMask;
  const auto end = static_cast<size_t>(b.cell_entries[c + 1]);
  for (auto p = static_cast<size_t>(b.cell_entries[c]); p != end; ++p) {
    // Later entries start at or after p's lo_w: those that start by its hi_w and meet it along u, v.
    std::array<float, 6> qp;
    for (int k = 0; k < 6; ++k) qp[k] = b.entry_bound[k][p];
    const Box& x = boxes[b.entry_box[p]];
    sparse_bucket_scan(b, p + 1, end, qp, [&](size_t q) {
      const Box& y = boxes[b.entry_box[q]];
      if (!boxes_overlap(x, y)) return;
      if (b.cell(0, l, std::max(x.lo[u], y.lo[u])) == i && b.cell(1, l, std::max(x.lo[v], y.lo[v])) == j)
        report(b.entry_box[p], b.entry_box[q]);
    });
  }
}

/// Self join, part 2: call report(k, id) for every box id on a level above
/// box k's that overlaps box k. With part 1 over all cells and part 2 over
/// all boxes, every overlapping pair of distinct boxes comes exactly once.
template <class Report>
void self_join_sparse_bucket_above(const SparseBucket& b, std::span<const Box> boxes, Index k,
                                   Report&& report) {
  if (b.num_levels() < 2) return;
  const std::array<float, 6> qf = float_bounds(b, boxes[k]);
  for (int l = sparse_bucket_level(b.cell_size[0], boxes[k]) + 1; l < b.num_levels(); ++l)
    query_sparse_bucket_level(b, boxes, boxes[k], qf, l, [&](Index id) { report(k, id); });
}

}  // namespace shatter
