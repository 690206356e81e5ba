#pragma once
// Fragments: connected components of the mesh (DESIGN.md step 5).
#include <span>
#include <vector>

#include "kernels/exact_sum.hpp"
#include "mesh/topology.hpp"

namespace shatter {

/// Statistics of one fragment (SI units).
struct FragmentStats {
  double mass = 0;               ///< sum of its nodal masses, kg
  double volume = 0;             ///< sum of its elements' current volumes, m^3
  Vec3 centre = Vec3::Zero();    ///< mass-weighted mean position, m
  Vec3 velocity = Vec3::Zero();  ///< momentum / mass, m/s
  Index elements = 0;            ///< element count
};

/// Fragment id of every element and, when computed, statistics per fragment.
struct Fragments {
  std::vector<Index> elem_fragment;  ///< [e]
  Index fragments = 0;               ///< how many
  std::vector<FragmentStats> stats;  ///< [fragment], or empty (label_fragments)
  Index count() const { return fragments; }
};

/// The terms of FragmentStats, summed exactly per fragment (so that partial
/// sums over any split of the nodes and elements, e.g. over MPI ranks, add up
/// to the same bits): [fragment * kFragmentSums + term], terms mass, m x (3),
/// m v (3), volume, element count.
inline constexpr int kFragmentSums = 9;

/// Connected components of elements joined by intact or cohesive facets
/// (a cohesive facet stops joining once release_debonded has freed it, i.e.
/// delta_max >= delta_c at all its points). Fragments are numbered in the
/// order of their smallest element global id. Two fragments never share a
/// node, so node statistics use positions `x` (m), velocities `v` (m/s) and
/// lumped masses `mass` (kg) per node, each node counted once.
Fragments find_fragments(const Mesh& mesh, const Topology& topo, std::span<const Vec3> x,
                         std::span<const Vec3> v, std::span<const double> mass);

/// The fragments' element ids and count only: topology, no positions.
Fragments label_fragments(const Mesh& mesh, const Topology& topo);

/// Union-find: the root of a's set in `parent` (each entry its parent, a
/// root its own), halving the path on the way.
Index find_root(std::vector<Index>& parent, Index a);

/// The exact partial sums of the statistics of `frags` over `nodes` and
/// `elements` (each node counts in the fragment of the first element of its
/// star, each element in its own).
std::vector<ExactSum> fragment_sums(const Mesh& mesh, const Fragments& frags, std::span<const Index> nodes,
                                    std::span<const Index> elements, std::span<const Vec3> x,
                                    std::span<const Vec3> v, std::span<const double> mass);

/// frags.stats from complete sums (fragment_sums over every node and element).
void set_fragment_stats(Fragments& frags, std::span<const ExactSum> sums);

}  // namespace shatter
