#pragma once
// Shared set-up of the fracture tests: meshed boxes, lumped masses, laws.
#include <optional>
#include <vector>

#include "kernels/cohesive.hpp"
#include "kernels/tet10.hpp"
#include "mesh/gmsh_input.hpp"
#include "mesh/mesh.hpp"

namespace shatter::test {

inline Mesh box_mesh(double element_size, int order) {
  ShapeSpec s;
  s.shape = "box";
  s.size = Vec3(1.0, 0.8, 0.6);
  s.element_size = element_size;
  s.order = order;
  return mesh_shape(s, 0, 0, "fracture test box");
}

/// Lumped nodal masses rho x element volume: 1/4 per corner (TET4), HRZ (TET10).
inline std::vector<double> lumped_masses(const Mesh& mesh, double rho) {
  std::vector<double> m(mesh.num_nodes(), 0.0);
  for (Index e = 0; e < mesh.num_elements(); ++e) {
    const Index* c = mesh.element(e);
    const double me = rho * element_reference_volume(mesh, e);
    if (mesh.order == 1) {
      for (int a = 0; a < 4; ++a) m[c[a]] += 0.25 * me;
    } else {
      Tet10Nodes X;
      for (int a = 0; a < 10; ++a) X.col(a) = mesh.reference[c[a]];
      const Eigen::Matrix<double, 10, 1> w = tet10_hrz_mass_fractions(X);
      for (int a = 0; a < 10; ++a) m[c[a]] += w[a] * me;
    }
  }
  return m;
}

inline std::vector<std::optional<CohesiveLaw>> one_law(const CohesiveLaw& law) {
  return {law};
}

}  // namespace shatter::test
