#include "mesh/coloring.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>

namespace shatter {

Coloring greedy_coloring(std::span<const Index> item_offsets, std::span<const Index> item_nodes,
                         Index num_nodes) {
  const Index n_items = static_cast<Index>(item_offsets.size()) - 1;
  Coloring out;
  out.color.assign(n_items, 0);
  // Colors used at each node, as bit words; grown when an item needs more.
  size_t words = 1;
  std::vector<std::uint64_t> used(static_cast<size_t>(num_nodes) * words, 0);
  std::vector<std::uint64_t> forbidden;
  for (Index i = 0; i < n_items; ++i) {
    forbidden.assign(words, 0);
    for (Index k = item_offsets[i]; k < item_offsets[i + 1]; ++k)
      for (size_t w = 0; w < words; ++w) forbidden[w] |= used[item_nodes[k] * words + w];
    int c = -1;
    for (size_t w = 0; w < words && c < 0; ++w)
      if (~forbidden[w]) c = static_cast<int>(w * 64 + std::countr_one(forbidden[w]));
    if (c < 0) {  // all colors in use: widen the bit sets
      const size_t new_words = words * 2;
      std::vector<std::uint64_t> wider(static_cast<size_t>(num_nodes) * new_words, 0);
      for (Index n = 0; n < num_nodes; ++n)
        for (size_t w = 0; w < words; ++w) wider[n * new_words + w] = used[n * words + w];
      used.swap(wider);
      c = static_cast<int>(words * 64);
      words = new_words;
    }
    out.color[i] = c;
    for (Index k = item_offsets[i]; k < item_offsets[i + 1]; ++k)
      used[item_nodes[k] * words + c / 64] |= std::uint64_t{1} << (c % 64);
  }
  return coloring_from(std::move(out.color));
}

Coloring coloring_from(std::vector<int> color) {
  Coloring out;
  out.color = std::move(color);
  const Index n_items = static_cast<Index>(out.color.size());
  int n_colors = 0;
  for (int c : out.color) n_colors = std::max(n_colors, c + 1);
  out.offsets.assign(n_colors + 1, 0);
  for (Index i = 0; i < n_items; ++i) ++out.offsets[out.color[i] + 1];
  for (int c = 0; c < n_colors; ++c) out.offsets[c + 1] += out.offsets[c];
  out.items.resize(n_items);
  std::vector<Index> fill(out.offsets.begin(), out.offsets.end() - 1);
  for (Index i = 0; i < n_items; ++i) out.items[fill[out.color[i]]++] = i;
  return out;
}

}  // namespace shatter
