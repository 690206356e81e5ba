#include "contact/sparse_bucket.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_scan.h>

#include <bit>

#include "contact/radix_sort.hpp"

namespace shatter {
namespace {

double largest_side(const Box& b) {
  return (b.hi - b.lo).maxCoeff();
}

Box bounding_box(std::span<const Box> boxes) {
  const double inf = std::numeric_limits<double>::infinity();
  const Box empty{Vec3::Constant(inf), Vec3::Constant(-inf)};
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, boxes.size()), empty,
      [&](const tbb::blocked_range<size_t>& r, Box acc) {
        for (size_t k = r.begin(); k != r.end(); ++k) {
          acc.lo = acc.lo.cwiseMin(boxes[k].lo);
          acc.hi = acc.hi.cwiseMax(boxes[k].hi);
        }
        return acc;
      },
      [](const Box& a, const Box& b) {
        return Box{a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)};
      });
}

/// h_0 = 2 x median largest side, the median taken over an evenly strided
/// sample of at most 4096 boxes (deterministic). Degenerate sets (all points)
/// fall back to the bounding box side over cbrt(n).
double base_cell_size(std::span<const Box> boxes, const Box& all) {
  const size_t stride = std::max<size_t>(1, boxes.size() / 4096);
  std::vector<double> sample;
  for (size_t k = 0; k < boxes.size(); k += stride) sample.push_back(largest_side(boxes[k]));
  auto mid = sample.begin() + sample.size() / 2;
  std::nth_element(sample.begin(), mid, sample.end());
  const double span = largest_side(all);
  double h = 2.0 * *mid;
  if (!(h > 0)) h = span / std::max(1.0, std::cbrt(static_cast<double>(boxes.size())));
  if (!(h > 0)) h = 1.0;
  // keep cell indices inside 29 bits
  return std::max(h, span * 0x1p-28);
}

}  // namespace

SparseBucket build_sparse_bucket(std::span<const Box> boxes) {
  SparseBucket b;
  const size_t n = boxes.size();
  if (n == 0) return b;
  const Box all = bounding_box(boxes);
  const Vec3 spread = all.hi - all.lo;
  int w = 0;
  for (int k = 1; k < 3; ++k)
    if (spread[k] > spread[w]) w = k;
  b.axis = {(w + 1) % 3, (w + 2) % 3, w};
  b.origin = {all.lo[b.axis[0]], all.lo[b.axis[1]]};
  const double h0 = base_cell_size(boxes, all);

  // Level of each box: the smallest l with largest side <= h0 4^l.
  std::vector<int> level(n);
  const int max_level = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, n), 0,
      [&](const tbb::blocked_range<size_t>& r, int acc) {
        for (size_t k = r.begin(); k != r.end(); ++k) {
          level[k] = sparse_bucket_level(h0, boxes[k]);
          acc = std::max(acc, level[k]);
        }
        return acc;
      },
      [](int a, int c) { return std::max(a, c); });
  for (int l = 0; l <= max_level; ++l) {
    b.cell_size.push_back(std::ldexp(h0, 2 * l));
    b.cell_inverse.push_back(1.0 / b.cell_size.back());
  }

  const int u = b.axis[0], v = b.axis[1];
  auto cell_range = [&](size_t k, std::uint64_t& i0, std::uint64_t& i1, std::uint64_t& j0,
                        std::uint64_t& j1) {
    const int l = level[k];
    i0 = b.cell(0, l, boxes[k].lo[u]);
    i1 = b.cell(0, l, boxes[k].hi[u]);
    j0 = b.cell(1, l, boxes[k].lo[v]);
    j1 = b.cell(1, l, boxes[k].hi[v]);
  };

  // Each box's float bounds, rounded outward.
  const int wa = b.axis[2];
  std::vector<std::array<float, 6>> bounds(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) bounds[k] = float_bounds(b, boxes[k]);
  });

  // Entries: one per (box, cell it spans); offsets by a parallel prefix sum.
  std::vector<size_t> first(n + 1, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      std::uint64_t i0, i1, j0, j1;
      cell_range(k, i0, i1, j0, j1);
      first[k + 1] = size_t(i1 - i0 + 1) * size_t(j1 - j0 + 1);
    }
  });
  tbb::parallel_scan(
      tbb::blocked_range<size_t>(1, n + 1), size_t(0),
      [&](const tbb::blocked_range<size_t>& r, size_t sum, bool is_final) {
        for (size_t k = r.begin(); k != r.end(); ++k) {
          sum += first[k];
          if (is_final) first[k] = sum;
        }
        return sum;
      },
      [](size_t a, size_t c) { return a + c; });
  // Sorted by cell, then by the float lo_w (the order the queries bisect), then by box
  // (the sort is stable): the same array for any thread count. The cell is packed as
  // (l, i, j) in just the bits the level-0 grid needs (higher levels need fewer).
  const int wi = static_cast<int>(std::bit_width(b.cell(0, 0, all.hi[u]))),
            wj = static_cast<int>(std::bit_width(b.cell(1, 0, all.hi[v])));
  std::vector<RadixRecord> entries(first[n]);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      std::uint64_t i0, i1, j0, j1;
      cell_range(k, i0, i1, j0, j1);
      const std::uint32_t lo = float_order_key(bounds[k][0]);
      const auto l = static_cast<std::uint64_t>(level[k]) << (wi + wj);
      size_t p = first[k];
      for (std::uint64_t i = i0; i <= i1; ++i)
        for (std::uint64_t j = j0; j <= j1; ++j) entries[p++] = {l | (i << wj) | j, lo, static_cast<Index>(k)};
    }
  });
  radix_sort(entries);

  const size_t m = entries.size();
  // The padding lanes: lo bounds +inf, hi bounds -inf.
  const float inf = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 6; ++k) b.entry_bound[k].assign(m + SparseBucket::kLanes, k % 2 == 0 ? inf : -inf);
  b.entry_box.resize(m);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, m), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t e = r.begin(); e != r.end(); ++e) {
      const auto& f = bounds[entries[e].id];
      for (int k = 0; k < 6; ++k) b.entry_bound[k][e] = f[k];
      b.entry_box[e] = entries[e].id;
    }
  });
  const std::uint64_t mask_i = (std::uint64_t(1) << wi) - 1, mask_j = (std::uint64_t(1) << wj) - 1;
  // The cells: where each starts (in order), then their keys and extents.
  b.level_cells.assign(1, 0);
  b.cell_entries.assign(1, 0);
  for (size_t k = 1; k <= m; ++k)
    if (k == m || entries[k].hi != entries[k - 1].hi) b.cell_entries.push_back(static_cast<Index>(k));
  const size_t cells = b.cell_entries.size() - 1;
  b.cell_key.resize(cells);
  b.cell_max_extent.resize(cells);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cells), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t c = r.begin(); c != r.end(); ++c) {
      double extent = 0;
      for (auto e = static_cast<size_t>(b.cell_entries[c]); e != static_cast<size_t>(b.cell_entries[c + 1]); ++e) {
        const Box& x = boxes[entries[e].id];
        extent = std::max(extent, x.hi[wa] - x.lo[wa]);
      }
      b.cell_max_extent[c] = extent;
      const std::uint64_t packed = entries[b.cell_entries[c]].hi;
      b.cell_key[c] = SparseBucket::key(static_cast<int>(packed >> (wi + wj)), (packed >> wj) & mask_i, packed & mask_j);
    }
  });
  for (size_t c = 0; c < cells; ++c) {
    const auto level_c = static_cast<int>(b.cell_key[c] >> (2 * SparseBucket::kCellBits));
    while (static_cast<int>(b.level_cells.size()) <= level_c) b.level_cells.push_back(static_cast<Index>(c));
  }
  while (static_cast<int>(b.level_cells.size()) <= max_level + 1)
    b.level_cells.push_back(static_cast<Index>(b.cell_key.size()));
  return b;
}

std::size_t memory_bytes(const SparseBucket& b) {
  return sizeof(SparseBucket) +
         (b.cell_size.capacity() + b.cell_inverse.capacity()) * sizeof(double) +
         b.level_cells.capacity() * sizeof(Index) + b.cell_key.capacity() * sizeof(std::uint64_t) +
         b.cell_entries.capacity() * sizeof(Index) + b.cell_max_extent.capacity() * sizeof(double) +
         6 * b.entry_bound[0].capacity() * sizeof(float) +
         b.entry_box.capacity() * sizeof(Index);
}

}  // namespace shatter
