#pragma once
// Cohesive elements: storage, extrinsic insertion with node splitting, and
// nodal forces (DESIGN.md step 5).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "fracture/facet_criterion.hpp"
#include "kernels/exact_sum.hpp"

namespace shatter {

/// Quadrature points per cohesive element: the 3-point interior rule on the
/// facet triangle, barycentrics (2/3, 1/6, 1/6) and permutations, weights 1/3
/// (exact to degree 2; Strang & Fix).
inline constexpr int kCohesivePoints = 3;

/// The cohesive elements of a mesh. Layouts (c = cohesive elements,
/// k = 3 facet nodes for TET4, 6 for TET10, slots of 6 per side):
///   facet[c]           facet of Topology
///   side_local[(2c + s) 6 + j]  local node index, in element facet_elem[f][s],
///                      of facet node j of side s; j runs over side 0's face
///                      (kTetFaces order, outward of element 0), side 1 is
///                      matched node by node (same reference position)
///   side_nodes[(2c + s) 6 + j]  the current node ids of those slots (refreshed
///                      by every insertion, since later splits renumber nodes)
///   area[c]            reference area of the facet's corner triangle, m^2
///   normal[c]          its reference unit normal, from side 0 to side 1
///   delta_max[c kCohesivePoints + q]  largest effective opening reached, m
struct CohesiveElements {
  std::vector<Index> facet;
  std::vector<std::int8_t> side_local;
  std::vector<Index> side_nodes;
  std::vector<double> area;
  std::vector<Vec3> normal;
  std::vector<double> delta_max;

  Index size() const { return static_cast<Index>(facet.size()); }
};

/// What an insertion changed, for the caller to update its own arrays.
struct Insertion {
  /// (new node, parent node) in creation order. Before using the new nodes the
  /// caller resizes its nodal arrays to mesh.num_nodes() and, in this order,
  /// copies position, velocity (and displacement) from the parent, then
  /// recomputes the lumped masses of the parent and the copy from their
  /// element stars (mass of a node = sum of its elements' contributions), so
  /// that mass and momentum are unchanged. Element reference constants do not
  /// change (copies keep the reference position), and an element coloring
  /// stays conflict-free (splitting only removes shared nodes).
  std::vector<std::array<Index, 2>> new_nodes;
  /// New crack faces: (element, local face) for both sides of every inserted
  /// facet, oriented outward of the element (nodes: face_nodes(mesh, e, face),
  /// read after the call). Splitting also renames nodes of older surface
  /// triangles, so when new_nodes is not empty a contact surface must be
  /// rebuilt from the mesh rather than appended to; a facet whose two sides
  /// still share all their nodes is not open and is no contact face.
  std::vector<std::array<Index, 2>> crack_faces;
  /// The new cohesive elements are [first_cohesive, cohesive.size()).
  Index first_cohesive = 0;
  /// The nodes whose element stars changed: the split nodes and their copies, ascending.
  std::vector<Index> changed_nodes() const;
};

/// Insert cohesive elements on the given intact interior facets, which must
/// have a law (facet_law; critical_facets returns only such facets) (extrinsic:
/// delta_max = 0, traction sigma_c at first opening). The facets are processed
/// in canonical order (sorted by Topology::facet_gid) whatever their order in
/// `facets`, so the result does not depend on how they were found. Marks the
/// facets cohesive, splits the nodes whose star falls apart (split_nodes),
/// updates `mesh` (conn, reference, node_gid, node_body, node -> element CSR)
/// and the side node ids of all cohesive elements.
Insertion insert_cohesive_elements(Mesh& mesh, Topology& topo, CohesiveElements& cohesive,
                                   std::span<const Index> facets);

/// A rank's share of the cohesive elements (MPI, docs/parallel.md "Cohesive
/// elements on ranks"): `computed`, ascending, the elements it computes (those
/// with a node it integrates); `counted[i]` whether computed[i] is its own
/// (its energies and decisions are this rank's). `every` (the default, one
/// rank): every element, all counted, the spans unused. A rank's share may be
/// empty: then it computes nothing.
struct CohesiveShare {
  std::span<const Index> computed;
  std::span<const std::uint8_t> counted;
  bool every = true;
};

/// Energies of the cohesive elements, J, summed exactly over the counted
/// ones (so that partial sums over ranks add up to the same bits).
struct CohesiveEnergy {
  ExactSum stored;      ///< recoverable (secant and compression penalty)
  ExactSum dissipated;  ///< dissipated up to the current delta_max
};

/// Cohesive nodal forces at current positions `x` (m): adds the internal force
/// dE/dx (same sign as the volume elements' internal forces, N) of every
/// computed cohesive element (`share`) to `f_int`, updates its delta_max, and
/// returns the energies of the counted ones.
/// Traction per unit reference area, integrated on the reference facet with
/// the 3-point rule; the opening is interpolated with the facet's shape
/// functions (linear, or quadratic on TET10 facets), the normal is that of the
/// current mid-surface corner triangle (Ortiz & Pandolfi 1999, sec. 3). The
/// forces are the full gradient of the cohesive energy at fixed delta_max,
/// including the variation of the normal (CohesiveTraction::dphi_dn), so
/// they keep linear and angular momentum. A freed facet (release_debonded)
/// exerts no force, not even the compression penalty, and counts Gc x area
/// as dissipated.
/// Element-local forces are computed with oneTBB and scattered in element
/// order: bitwise identical for any number of threads, and a node gets the
/// same bits from any share that computes every element around it.
CohesiveEnergy cohesive_forces(const Mesh& mesh, const Topology& topo, CohesiveElements& cohesive,
                               FractureLaws laws, std::span<const Vec3> x, std::span<Vec3> f_int,
                               CohesiveShare share = {});

/// Upper bound of the largest eigenvalue of M^-1 K_c, 1/s^2, where K_c is the
/// stiffness of the cohesive forces (facets in state `cohesive`) and M the
/// lumped masses `mass` (kg, per node). Each traction stiffness is at most
/// cohesive_stiffness_bound(law) = k (Pa/m), so by Gershgorin's theorem the
/// bound is max over nodes i of (1 / m_i) sum over its cohesive slots of
///   2 k sum_q w_q |N_i(x_q)| sum_l |N_l(x_q)|
/// (the factor 2: both sides of the facet; 2 k A / 3 per TET4 corner).
/// Since the eigenvalues of M^-1 (K_e + K_c) are at most the sum of the two
/// bounds, a step 2 / sqrt(omega_e^2 + this) is stable for the volume
/// elements (omega_e = 2 / stable dt of the elements) and the cohesive
/// elements together. 0 when there is no cohesive element. Over the computed
/// elements of `share`: the rows of the nodes they hold whole (every node an
/// integrating rank computes all elements of) are exact, the others smaller,
/// so the largest over the ranks is the bound of the whole model.
double cohesive_eigenvalue_bound(const Mesh& mesh, const Topology& topo,
                                 const CohesiveElements& cohesive, FractureLaws laws,
                                 std::span<const double> mass, CohesiveShare share = {});

/// Damage of every element, in [0, 1], for output: the largest over its
/// facets of min(1, delta_max / delta_c) (largest over the facet's points)
/// for a cohesive facet, 1 for a freed crack facet, 0 for intact facets and
/// the outer boundary. Layout [e].
std::vector<double> element_damage(const Mesh& mesh, const Topology& topo,
                                   const CohesiveElements& cohesive, FractureLaws laws);

/// Crack surfaces of the cohesive elements (reference facet areas, m^2),
/// summed exactly (partial sums over ranks add up to the same bits).
struct CrackArea {
  ExactSum debonded;           ///< facets opened past delta_c at every point (no traction left)
  ExactSum between_fragments;  ///< the part of `debonded` between elements of different fragments
  ExactSum debonded_dissipated;  ///< Gc x area over the debonded facets, J (the rest of the
                                 ///< dissipated energy is in facets still cohesive)
};

/// The crack surface of the counted elements of `share`: debonded facets
/// (every point past delta_c), and those of them whose two elements are in
/// different fragments (`elem_fragment`, Fragments::elem_fragment): the
/// through-cracks.
CrackArea crack_area(const Mesh& mesh, const Topology& topo, const CohesiveElements& cohesive,
                     FractureLaws laws, std::span<const Index> elem_fragment, CohesiveShare share = {});

/// Mark free the cohesive facets whose every quadrature point has come apart
/// (kPointApart, set by cohesive_forces: opened past delta_c, then not in
/// compression; no traction and no penalty left, so nothing leaves the
/// ledger; the two sides now belong to separate fragments unless joined
/// elsewhere). Returns the number of facets freed.
Index release_debonded(Topology& topo, const CohesiveElements& cohesive);

/// The facets release_debonded would free among the counted elements of
/// `share`, ascending in cohesive element order, without freeing them.
std::vector<Index> debonded_facets(const Topology& topo, const CohesiveElements& cohesive, CohesiveShare share = {});

}  // namespace shatter
