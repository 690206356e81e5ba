#pragma once
// Step 5 of the time loop (DESIGN.md): the facet check, extrinsic insertion
// of cohesive elements with node splitting, cohesive forces and fragments,
// for scenes with a material that has a fracture block.
#include <optional>
#include <span>
#include <vector>

#include "fracture/cohesive_elements.hpp"
#include "fracture/fragments.hpp"
#include "runtime/model.hpp"

namespace shatter {

class FractureStage {
 public:
  /// The compression penalty of each material's cohesive law is
  /// k_p = E / h_min (h_min: smallest element altitude of that material), as
  /// stiff as the adjacent elements, so it keeps crack faces from
  /// interpenetrating without shrinking the stable step.
  explicit FractureStage(Model& model);

  /// Adds cohesive forces dE/dx at positions x to f_int; returns the energies.
  CohesiveEnergy add_forces(std::span<const Vec3> x, std::span<Vec3> f_int);

  /// Facets whose traction (from the elements' Cauchy stresses, 6 Voigt
  /// components per element) reaches the strength, sorted by facet gid.
  std::vector<Index> check(std::span<const Vec3> x, std::span<const double> stress6);
  /// The facets become cohesive elements (in canonical order, whatever the
  /// order given); nodes split. Returns what changed (new nodes to fill in by
  /// the caller).
  Insertion insert(std::span<const Index> facets);
  /// The nodes of all cohesive elements (both sides), ascending.
  std::vector<Index> cohesive_nodes() const;
  const Topology& topology() const { return topology_; }
  /// The facet of each cohesive element.
  std::span<const Index> cohesive_facets() const { return cohesive_.facet; }

  /// Frees fully debonded facets; returns how many.
  Index release();

  Fragments fragments(std::span<const Vec3> x, std::span<const Vec3> v, std::span<const double> mass) const {
    return find_fragments(model_.mesh, topology_, x, v, mass);
  }
  Index cohesive_count() const { return cohesive_.size(); }
  double check_seconds() const { return check_seconds_; }

 private:
  Model& model_;
  Topology topology_;
  CohesiveElements cohesive_;
  std::vector<std::optional<CohesiveLaw>> laws_;
  double check_seconds_ = 0;
};

}  // namespace shatter
