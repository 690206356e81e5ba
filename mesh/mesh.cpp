#include "mesh/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "kernels/error.hpp"
#include "kernels/tet10.hpp"
#include "kernels/tet4.hpp"

namespace shatter {

void Mesh::build_node_elements() {
  const Index n = num_nodes(), ne = num_elements();
  const int k = nodes_per_element();
  node_elem_offsets.assign(static_cast<size_t>(n) + 1, 0);
  for (Index e = 0; e < ne; ++e)
    for (int a = 0; a < k; ++a) ++node_elem_offsets[element(e)[a] + 1];
  for (Index i = 0; i < n; ++i) node_elem_offsets[i + 1] += node_elem_offsets[i];
  node_elem.resize(node_elem_offsets[n]);
  std::vector<Index> fill(node_elem_offsets.begin(), node_elem_offsets.end() - 1);
  for (Index e = 0; e < ne; ++e)
    for (int a = 0; a < k; ++a) node_elem[fill[element(e)[a]]++] = e;
}

void append_mesh(Mesh& a, const Mesh& b) {
  if (a.num_nodes() == 0 && a.num_elements() == 0) a.order = b.order;
  SHATTER_REQUIRE(a.order == b.order, "append_mesh: bodies of different element order");
  const Index node_shift = a.num_nodes();
  // Ids of `b` (Gmsh tags, from 1) follow the largest id of `a`.
  const GlobalId elem_gid_shift = a.elem_gid.empty() ? 0 : *std::max_element(a.elem_gid.begin(), a.elem_gid.end());
  const GlobalId node_gid_shift = a.node_gid.empty() ? 0 : *std::max_element(a.node_gid.begin(), a.node_gid.end());
  a.reference.insert(a.reference.end(), b.reference.begin(), b.reference.end());
  a.node_body.insert(a.node_body.end(), b.node_body.begin(), b.node_body.end());
  for (GlobalId g : b.node_gid) a.node_gid.push_back(g + node_gid_shift);
  for (Index c : b.conn) a.conn.push_back(c + node_shift);
  for (GlobalId g : b.elem_gid) a.elem_gid.push_back(g + elem_gid_shift);
  a.elem_body.insert(a.elem_body.end(), b.elem_body.begin(), b.elem_body.end());
  a.elem_material.insert(a.elem_material.end(), b.elem_material.begin(), b.elem_material.end());
  a.build_node_elements();
}

Tet10ScaledJacobian element_min_scaled_jacobian(const Mesh& mesh, Index e) {
  SHATTER_ASSERT(mesh.order == 2);
  Tet10Nodes X;
  for (int a = 0; a < 10; ++a) X.col(a) = mesh.reference[mesh.element(e)[a]];
  return tet10_min_scaled_jacobian(tet10_reference(X));
}

MeshScaledJacobian min_scaled_jacobian(const Mesh& mesh) {
  MeshScaledJacobian worst;
  if (mesh.order != 2) return worst;
  worst.value = HUGE_VAL;
  for (Index e = 0; e < mesh.num_elements(); ++e) {
    const double value = element_min_scaled_jacobian(mesh, e).value;
    if (value < worst.value) worst = {value, mesh.elem_gid[e]};
  }
  return worst;
}

double element_reference_volume(const Mesh& mesh, Index e) {
  const Index* c = mesh.element(e);
  if (mesh.order == 1)
    return tet_signed_volume(mesh.reference[c[0]], mesh.reference[c[1]], mesh.reference[c[2]],
                             mesh.reference[c[3]]);
  Tet10Nodes X;
  for (int a = 0; a < 10; ++a) X.col(a) = mesh.reference[c[a]];
  return tet10_reference(X).volume;
}

void validate_mesh(const Mesh& mesh, const std::string& where) {
  auto fail = [&](const std::string& what) {
    throw InputError(where + ": " + what);
  };
  if (mesh.num_elements() == 0) fail("the mesh has no tetrahedra");
  const int k = mesh.nodes_per_element();
  std::vector<char> used(mesh.num_nodes(), 0);
  for (Index e = 0; e < mesh.num_elements(); ++e) {
    const Index* c = mesh.element(e);
    for (int a = 0; a < k; ++a) {
      if (c[a] < 0 || c[a] >= mesh.num_nodes()) {
        std::ostringstream os;
        os << "element " << mesh.elem_gid[e] << " refers to a node that does not exist";
        fail(os.str());
      }
      used[c[a]] = 1;
      const Vec3& X = mesh.reference[c[a]];
      if (!(X.array().abs() <= kMaxCoordinate).all()) {
        std::ostringstream os;
        os << "node " << mesh.node_gid[c[a]] << " of element " << mesh.elem_gid[e] << " is at (" << X.x() << ", "
           << X.y() << ", " << X.z() << "); expected finite coordinates within " << kMaxCoordinate
           << " m of the origin";
        fail(os.str());
      }
    }
    // Scale-aware zero-volume test: volume against the cube of the longest edge.
    double lmax = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        lmax = std::max(lmax, (mesh.reference[c[a]] - mesh.reference[c[b]]).norm());
    const double vol = element_reference_volume(mesh, e);
    if (!(vol > 1e-12 * lmax * lmax * lmax)) {
      std::ostringstream os;
      os << "element " << mesh.elem_gid[e] << " is " << (vol < 0 ? "inverted" : "of zero volume")
         << " (volume " << vol << " m^3); expected positive volume with Gmsh node order";
      fail(os.str());
    }
    if (mesh.order == 2) {
      const Tet10ScaledJacobian s = element_min_scaled_jacobian(mesh, e);
      if (!(s.value > 0)) {
        Tet10Nodes X;
        for (int a = 0; a < 10; ++a) X.col(a) = mesh.reference[c[a]];
        const Vec3 at = X * tet10_shape(tet10_quadrature_points()[s.point]);
        std::ostringstream os;
        os << "element " << mesh.elem_gid[e] << " (10-node, volume " << vol
           << " m^3) has a non-positive Jacobian at its quadrature point near (" << at.x() << ", " << at.y() << ", "
           << at.z() << "): det J / (6 x volume) = " << s.value
           << " (1 for a straight-sided element): its curved edges fold it; expected det J > 0 at every "
              "quadrature point: remesh with Gmsh's Mesh.HighOrderOptimize = 2 (elastic + optimisation), or "
              "with straight-sided second-order elements (Mesh.SecondOrderLinear = 1)";
        fail(os.str());
      }
    }
  }
  for (Index i = 0; i < mesh.num_nodes(); ++i)
    if (!used[i]) {
      std::ostringstream os;
      os << "node " << mesh.node_gid[i] << " is not used by any tetrahedron";
      fail(os.str());
    }
}

}  // namespace shatter
