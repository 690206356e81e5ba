#include "runtime/fracture_stage.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "fracture/facet_criterion.hpp"
#include "kernels/tet4.hpp"

namespace shatter {

FractureStage::FractureStage(Model& model) : model_(model), topology_(build_topology(model.mesh)) {
  const Mesh& mesh = model.mesh;
  std::vector<double> h_min(model.scene.materials.size(), HUGE_VAL);
  for (Index e = 0; e < mesh.num_elements(); ++e) {
    const Index* c = mesh.element(e);
    const auto& X = mesh.reference;
    h_min[mesh.elem_material[e]] =
        std::min(h_min[mesh.elem_material[e]], tet_min_altitude(X[c[0]], X[c[1]], X[c[2]], X[c[3]]));
  }
  for (size_t m = 0; m < model.scene.materials.size(); ++m) {
    const MaterialSpec& ms = model.scene.materials[m];
    if (ms.fracture)
      laws_.emplace_back(make_cohesive_law(ms.fracture->strength, ms.fracture->energy, ms.fracture->beta,
                                           ms.young / h_min[m]));
    else
      laws_.emplace_back(std::nullopt);
  }
}

CohesiveEnergy FractureStage::add_forces(std::span<const Vec3> x, std::span<Vec3> f_int) {
  if (cohesive_.size() == 0) return {};
  return cohesive_forces(model_.mesh, topology_, cohesive_, laws_, x, f_int);
}

std::vector<Index> FractureStage::check(std::span<const Vec3> x, std::span<const double> stress6) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Index> critical = critical_facets(model_.mesh, topology_, x, stress6, 6, laws_);
  check_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return critical;
}

Insertion FractureStage::insert(std::span<const Index> facets) {
  if (facets.empty()) return {};
  return insert_cohesive_elements(model_.mesh, topology_, cohesive_, facets);
}

std::vector<Index> FractureStage::cohesive_nodes() const {
  const int k = model_.mesh.order == 1 ? 3 : 6;
  std::vector<Index> nodes;
  nodes.reserve(static_cast<size_t>(cohesive_.size()) * 2 * k);
  for (Index c = 0; c < cohesive_.size(); ++c)
    for (int s = 0; s < 2; ++s)
      for (int j = 0; j < k; ++j) nodes.push_back(cohesive_.side_nodes[(2 * static_cast<size_t>(c) + s) * 6 + j]);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

double FractureStage::stable_dt(double element_dt, std::span<const double> mass) {
  if (cohesive_.size() == 0) return element_dt;
  const std::array<Index, 2> key = {cohesive_.size(), model_.mesh.num_nodes()};
  if (key != bound_key_) {
    eigenvalue_bound_ = cohesive_eigenvalue_bound(model_.mesh, topology_, cohesive_, laws_, mass);
    bound_key_ = key;
  }
  const double omega_e = 2.0 / element_dt;
  return 2.0 / std::sqrt(omega_e * omega_e + eigenvalue_bound_);
}

Index FractureStage::release() {
  if (cohesive_.size() == 0) return 0;
  return release_debonded(model_.mesh, topology_, cohesive_, laws_);
}

}  // namespace shatter
