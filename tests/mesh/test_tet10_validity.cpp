// Curved 10-node tetrahedra: a mesh Gmsh leaves folded is refused naming the
// non-positive Jacobian, where, its scaled value and the remedy; the shapes
// shatter meshes at order 2 are valid.
#include <gmsh.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "kernels/error.hpp"
#include "mesh/gmsh_input.hpp"
#include "mesh/gmsh_model.hpp"

using namespace shatter;
namespace fs = std::filesystem;

namespace {

/// A plate 2 x 2 x 0.4 with a round hole of radius 0.1 through it, meshed by
/// Gmsh at order 2 with element size 0.5 (five times the hole's radius) and
/// the given Mesh.HighOrderOptimize; written as .msh, returns the path.
std::string plate_with_hole(int high_order_optimize) {
  const fs::path dir = fs::path(SHATTER_BINARY_DIR "/test_scratch") / "tet10_validity";
  fs::create_directories(dir);
  const std::string path = (dir / ("plate_hoo" + std::to_string(high_order_optimize) + ".msh")).string();
  GmshSession session;
  gmsh::model::add("plate");
  const int plate = gmsh::model::occ::addBox(-1, -1, -0.2, 2, 2, 0.4);
  const int hole = gmsh::model::occ::addCylinder(0, 0, -0.2, 0, 0, 0.4, 0.1);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::cut({{3, plate}}, {{3, hole}}, out, map);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 0.5);
  gmsh::option::setNumber("Mesh.ElementOrder", 2);
  gmsh::option::setNumber("Mesh.HighOrderOptimize", high_order_optimize);
  gmsh::model::mesh::generate(3);
  gmsh::write(path);
  return path;
}

}  // namespace

// Gmsh's default (no high-order optimisation) leaves an element along the
// hole folded: positive volume, negative Jacobian at a quadrature point.
// Before, it was refused as "of zero volume (volume 0.0012 m^3)". The
// message names the element, the point (on the hole's side of the plate),
// the scaled Jacobian the mesh's minimum has, and the remedy, which works.
TEST(Tet10Validity, FoldedCurvedElementIsNamedWithItsJacobianAndTheRemedy) {
  const Mesh folded = read_mesh_file(plate_with_hole(0), "", 0, 0, "w");
  ASSERT_EQ(folded.order, 2);
  const MeshScaledJacobian worst = min_scaled_jacobian(folded);
  ASSERT_LT(worst.value, 0) << "Gmsh made no folded element: the test needs another plate";
  std::string why;
  try {
    validate_mesh(folded, "w");
  } catch (const InputError& e) {
    why = e.what();
  }
  std::ostringstream scaled;
  scaled << worst.value;
  EXPECT_EQ(why.rfind("w: element " + std::to_string(worst.element) + " (10-node, volume ", 0), 0u) << why;
  EXPECT_NE(why.find(" m^3) has a non-positive Jacobian at its quadrature point near ("), std::string::npos) << why;
  EXPECT_NE(why.find("): det J / (6 x volume) = " + scaled.str() + " (1 for a straight-sided element)"),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("remesh with Gmsh's Mesh.HighOrderOptimize = 2 (elastic + optimisation), or with "
                     "straight-sided second-order elements (Mesh.SecondOrderLinear = 1)"),
            std::string::npos)
      << why;
  // The point: inside the plate, within one element size (0.5) of the hole.
  const size_t at = why.find("near (") + 6;
  double x = 0, y = 0, z = 0;
  char comma;
  std::istringstream(why.substr(at)) >> x >> comma >> y >> comma >> z;
  EXPECT_LT(std::hypot(x, y), 0.1 + 0.5);
  EXPECT_LE(std::abs(z), 0.2 + 1e-12);
  // The remedy the message names.
  const Mesh optimised = read_mesh_file(plate_with_hole(2), "", 0, 0, "w");
  EXPECT_NO_THROW(validate_mesh(optimised, "w"));
  EXPECT_GT(min_scaled_jacobian(optimised).value, 0.1);
}

// A straight-sided TET10 has scaled Jacobian 1 at every quadrature point; a
// mid-edge node moved off its edge lowers it, through 0 when the element folds.
TEST(Tet10Validity, ScaledJacobianOfOneElement) {
  const Vec3 corner[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  Tet10Nodes X;
  for (int a = 0; a < 4; ++a) X.col(a) = 3.0 * corner[a];  // any size: the measure is scaled
  for (int e = 0; e < 6; ++e) X.col(4 + e) = 0.5 * (X.col(kTet10Edges[e][0]) + X.col(kTet10Edges[e][1]));
  EXPECT_NEAR(tet10_min_scaled_jacobian(tet10_reference(X)).value, 1.0, 1e-14);
  double last = 1.0;
  for (const double s : {0.1, 0.2, 0.3}) {  // node 4 (edge 0-1) pushed towards the opposite edge
    Tet10Nodes Y = X;
    Y.col(4) += 3.0 * Vec3(0, s, s);
    const Tet10Reference r = tet10_reference(Y);
    EXPECT_GT(r.volume, 0);
    const double value = tet10_min_scaled_jacobian(r).value;
    EXPECT_LT(value, last);
    last = value;
  }
  EXPECT_LT(last, 0);  // s = 0.3: folded, volume still positive
}

// The curved shapes shatter meshes at order 2 (high-order optimisation on):
// valid at every size tried, coarse ones included, with the minimum scaled
// Jacobian well above 0 (measured 0.60 to 0.96).
TEST(Tet10Validity, ShatterOrderTwoSphereAndTubeAreValid) {
  for (const double h : {0.5, 0.3, 0.2, 0.1}) {
    SCOPED_TRACE("element size " + std::to_string(h));
    ShapeSpec sphere;
    sphere.shape = "sphere";
    sphere.radius = 1.0;
    sphere.element_size = h;
    sphere.order = 2;
    ShapeSpec tube;
    tube.shape = "tube";
    tube.inner_radius = 0.8;
    tube.outer_radius = 1.0;
    tube.length = 0.5;
    tube.element_size = h;
    tube.order = 2;
    ShapeSpec hollow = sphere;
    hollow.inner_radius = 0.7;
    for (const auto& [name, s] : {std::pair{"sphere", sphere}, std::pair{"tube", tube}, std::pair{"hollow", hollow}}) {
      SCOPED_TRACE(name);
      const Mesh m = mesh_shape(s, 0, 0, "t");
      EXPECT_NO_THROW(validate_mesh(m, "t"));
      EXPECT_GT(min_scaled_jacobian(m).value, 0.3);
    }
  }
}
