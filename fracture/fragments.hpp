#pragma once
// Fragments: connected components of the mesh (DESIGN.md step 5).
#include <span>
#include <vector>

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

/// Fragment id of every element and statistics per fragment.
struct Fragments {
  std::vector<Index> elem_fragment;  ///< [e]
  std::vector<FragmentStats> stats;  ///< [fragment]
  Index count() const { return static_cast<Index>(stats.size()); }
};

/// Connected components of elements joined by intact or cohesive facets
/// (a cohesive facet stops joining once release_debonded has freed it, i.e.
/// delta_max >= delta_c at all its points). Fragments are numbered in the
/// order of their smallest element global id. Two fragments never share a
/// node, so node statistics use positions `x` (m), velocities `v` (m/s) and
/// lumped masses `mass` (kg) per node, each node counted once.
Fragments find_fragments(const Mesh& mesh, const Topology& topo, std::span<const Vec3> x,
                         std::span<const Vec3> v, std::span<const double> mass);

}  // namespace shatter
