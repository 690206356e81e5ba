// The element estimate made before meshing (mesh/shape_estimate.hpp, issue
// 21): against Gmsh's own counts, with and without a refinement, and the
// extent check that keeps absurd shapes from Gmsh.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "kernels/error.hpp"
#include "mesh/shape_estimate.hpp"

namespace shatter {
namespace {

ShapeSpec box(double h) {
  ShapeSpec s;
  s.shape = "box";
  s.size = Vec3(0.02, 0.01, 0.01);
  s.element_size = h;
  return s;
}

TEST(ShapeEstimate, WithinAFactorOfThreeOfGmshsCount) {
  ShapeSpec s = box(0.001);
  EXPECT_DOUBLE_EQ(shape_volume(s), 2e-6);
  const double plain = estimated_elements(s);
  EXPECT_DOUBLE_EQ(plain, kTetsPerCube * 2e-6 / 1e-9);
  const double meshed = mesh_shape(s, 0, 0, "test").num_elements();
  EXPECT_GT(meshed, plain / 3);
  EXPECT_LT(meshed, plain * 3);
  // A refinement adds at least its ball at its size, and the estimate still
  // follows Gmsh's count.
  s.refine.push_back({Vec3(0.01, 0.005, 0.0), 0.002, 0.0003});
  const double refined = estimated_elements(s);
  EXPECT_GT(refined - plain, kTetsPerCube * 4.0 / 3.0 * M_PI * 8e-9 / 2.7e-11);
  const double meshed_refined = mesh_shape(s, 0, 0, "test").num_elements();
  EXPECT_GT(meshed_refined, 1.2 * meshed);
  EXPECT_GT(meshed_refined, refined / 3);
  EXPECT_LT(meshed_refined, refined * 3);
}

TEST(ShapeEstimate, ShapesBeyondTheCoordinateLimitAreRefused) {
  ShapeSpec s = box(0.001);
  EXPECT_NO_THROW(check_shape_extent(s, "w"));
  s.center = Vec3(1e308, 0, 0);
  EXPECT_THROW(check_shape_extent(s, "w"), InputError);
  s.center = Vec3::Zero();
  s.size = Vec3(3e9, 1, 1);
  EXPECT_THROW(check_shape_extent(s, "w"), InputError);
  s = box(0.001);
  s.center.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(check_shape_extent(s, "w"), InputError);
  ShapeSpec c;
  c.shape = "cylinder";
  c.radius = 0.5;
  c.length = 1e10;
  EXPECT_THROW(check_shape_extent(c, "w"), InputError);
}

}  // namespace
}  // namespace shatter
