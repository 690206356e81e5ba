#pragma once
// Fragments of the whole model from each rank's owned elements
// (docs/parallel.md "Fragments on ranks"): connected components through
// facets that are not free, found by a union-find over the owned elements
// and merged across the ranks by exchanging the labels of the elements on
// rank boundaries with the neighbouring ranks only (no gather of the mesh).
#include <memory>

#include "fracture/fragments.hpp"
#include "runtime/decomposition.hpp"

namespace shatter {

class Halo;

class FragmentLabels {
 public:
  /// The ranks' boundary elements (an owned element with a facet to an
  /// element another rank owns) and their exchange. Collective. `topo` is the
  /// model's facet topology (whose facets never change, only their states).
  FragmentLabels(const Model& model, const Topology& topo, const Decomposition& dec);
  ~FragmentLabels();

  /// The fragments of the current facet states, numbered in the order of
  /// their smallest element global id (as label_fragments on one rank):
  /// `elem_fragment` is set for the owned elements and the elements that
  /// share a facet with one (-1 elsewhere), `fragments` is the whole model's
  /// count. Collective: one label exchange and one reduction per round of
  /// merging (as many rounds as a fragment crosses ranks in a chain, plus
  /// one), then one gather of the fragments' smallest element ids.
  Fragments label(const Topology& topo) const;

 private:
  const Model& model_;
  const Decomposition& dec_;
  std::vector<Index> owned_;          ///< owned elements, ascending
  std::vector<char> is_owned_;        ///< per local element
  std::unique_ptr<Halo> halo_;        ///< owned boundary elements' labels to the neighbours (null on one rank)
};

}  // namespace shatter
