#pragma once
// Extrinsic insertion criterion (DESIGN.md step 5): which intact facets break.
#include <optional>
#include <span>
#include <vector>

#include "kernels/cohesive.hpp"
#include "mesh/topology.hpp"

namespace shatter {

/// Cohesive law of each material, indexed by Mesh::elem_material; empty for a
/// material without a `fracture` block (its facets never break).
using FractureLaws = std::span<const std::optional<CohesiveLaw>>;

/// The law of an interior facet: the law of the material of element 0 (the
/// one of smaller global id) when both adjacent materials fracture, else none.
const CohesiveLaw* facet_law(const Mesh& mesh, const Topology& topo, FractureLaws laws, Index f);

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
