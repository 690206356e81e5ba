#include "mesh/shape_estimate.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "kernels/error.hpp"
#include "mesh/mesh.hpp"

namespace shatter {

double shape_volume(const ShapeSpec& s) {
  const double pi = std::numbers::pi;
  if (s.shape == "box") return s.size.prod();
  if (s.shape == "cylinder") return pi * s.radius * s.radius * s.length;
  if (s.shape == "tube") return pi * (s.outer_radius * s.outer_radius - s.inner_radius * s.inner_radius) * s.length;
  if (s.shape == "sphere") return 4.0 / 3.0 * pi * (std::pow(s.radius, 3) - std::pow(s.inner_radius, 3));
  return 0;
}

double estimated_elements(const ShapeSpec& s) {
  double n = kTetsPerCube * shape_volume(s) / std::pow(s.element_size, 3);
  // Each refinement adds its ball at h and the shell graded from h to the
  // body's size (mesh_shape), counted whole (an upper bound at a surface).
  const double pi = std::numbers::pi;
  for (const RefineSpec& r : s.refine) {
    double cubes = 4.0 / 3.0 * pi * std::pow(r.radius, 3) / std::pow(r.element_size, 3);
    const double width = (s.element_size - r.element_size) / kRefineGrading;
    constexpr int kSteps = 200;  // midpoint rule over the shell
    for (int i = 0; i < kSteps; ++i) {
      const double d = (i + 0.5) * width / kSteps, radius = r.radius + d;
      cubes += 4.0 * pi * radius * radius * (width / kSteps) / std::pow(r.element_size + kRefineGrading * d, 3);
    }
    n += kTetsPerCube * cubes;
  }
  return n;
}

void check_shape_extent(const ShapeSpec& s, const std::string& where) {
  // The largest distance of a point of the shape from its centre.
  const double reach = s.shape == "box" ? 0.5 * s.size.norm()
                                        : std::max({s.radius, s.outer_radius}) + 0.5 * s.length;
  // (Eigen's maxCoeff may skip a NaN: a centre not finite is NaN here.)
  const double extent = s.center.allFinite() ? s.center.cwiseAbs().maxCoeff() + reach : std::nan("");
  if (std::isfinite(extent) && extent <= kMaxCoordinate) return;
  std::ostringstream os;
  os << where << ": the " << s.shape << " reaches " << extent << " m from the origin (centre and size); expected "
     << "a shape within " << kMaxCoordinate << " m";
  throw InputError(os.str());
}

}  // namespace shatter
