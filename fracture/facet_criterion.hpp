#pragma once
// Extrinsic insertion criterion (DESIGN.md step 5): which intact facets break.
#include <concepts>
#include <optional>
#include <span>
#include <vector>

#include "kernels/cohesive.hpp"
#include "kernels/facet_traction.hpp"
#include "mesh/topology.hpp"

namespace shatter {

/// The cohesive laws of a mesh.
struct FractureLaws {
  /// The materials' laws alone (no scatter): from any contiguous range of them.
  template <class Laws>
    requires std::convertible_to<const Laws&, std::span<const std::optional<CohesiveLaw>>>
  FractureLaws(const Laws& laws) : material(laws) {}  // NOLINT(google-explicit-constructor)
  FractureLaws(std::span<const std::optional<CohesiveLaw>> laws, std::span<const double> strength,
               double weakest)
      : material(laws), facet_strength(strength), weakest_facet(weakest) {}

  /// Law of each material, indexed by Mesh::elem_material; empty for a
  /// material without a `fracture` block (its facets never break).
  std::span<const std::optional<CohesiveLaw>> material;
  /// Strength of each facet of the Topology, Pa (strength scatter,
  /// fracture/strength_scatter.hpp); empty: every facet has its material's.
  std::span<const double> facet_strength = {};
  /// The smallest value of facet_strength, Pa (read only when it is not empty).
  double weakest_facet = 0;
};

/// The law of an interior facet: the law of the material of element 0 (the
/// one of smaller global id) when both adjacent materials fracture, with the
/// facet's own strength under scatter (same Gc); else none.
std::optional<CohesiveLaw> facet_law(const Mesh& mesh, const Topology& topo, FractureLaws laws, Index f);

/// Cauchy stress of element e from `stress`, laid out per element as
/// 6 Voigt components (xx, yy, zz, yz, xz, xy) or 9 row-major components
/// (`stress_size`), Pa.
Mat3 element_cauchy_stress(std::span<const double> stress, int stress_size, Index e);

/// Intact interior facets where the criterion of Camacho & Ortiz holds:
///   sqrt(<tn>^2 + tau^2 / beta^2) >= sigma_c,  t = sigma n,  tn = t . n,
///   tau = |t - tn n|,
/// with sigma the average of the two adjacent elements' Cauchy stresses and n
/// the unit normal of the facet's corner triangle at the current positions
/// `x` (m, per node). Evaluated with oneTBB; the result (local facet ids) is
/// sorted by Topology::facet_gid, the canonical insertion order, and does not
/// depend on the number of threads.
///
/// On MPI ranks: `local` (ascending) lists the elements whose stresses are
/// current (owned and ghost), `owned` (ascending, within `local`) those the
/// rank owns; only the facets whose element of smaller index is owned are
/// checked (each facet by one rank; both its elements are local). Empty
/// lists: every element, on one rank.
std::vector<Index> critical_facets(const Mesh& mesh, const Topology& topo, std::span<const Vec3> x,
                                   std::span<const double> stress, int stress_size, FractureLaws laws,
                                   std::span<const Index> local = {}, std::span<const Index> owned = {});

}  // namespace shatter
