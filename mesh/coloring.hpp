#pragma once
// Graph coloring for conflict-free parallel scatter (DESIGN.md "Parallel
// model"): items (element blocks, contact pairs) that share a node never get
// the same color, so all items of one color can run in parallel tasks while
// every node receives its contributions in a fixed order (color, then item):
// results are bitwise identical for any thread count.
#include <span>
#include <vector>

#include "kernels/types.hpp"

namespace shatter {

/// Items grouped by color: the items of color c are
/// items[offsets[c] .. offsets[c+1]), in ascending item order.
struct Coloring {
  std::vector<Index> offsets;
  std::vector<Index> items;
  std::vector<int> color;  ///< color of each item
  int num_colors() const { return static_cast<int>(offsets.size()) - 1; }
  std::span<const Index> items_of(int c) const {
    return {items.data() + offsets[c], static_cast<size_t>(offsets[c + 1] - offsets[c])};
  }
};

/// Greedy first-fit coloring in item order (deterministic). The nodes of item
/// i are item_nodes[item_offsets[i] .. item_offsets[i+1]); node ids < num_nodes.
Coloring greedy_coloring(std::span<const Index> item_offsets, std::span<const Index> item_nodes,
                         Index num_nodes);

/// The items grouped by the given colors (color[i] >= 0 for item i).
Coloring coloring_from(std::vector<int> color);

}  // namespace shatter
