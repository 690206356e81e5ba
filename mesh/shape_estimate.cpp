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
  return kTetsPerCube * shape_volume(s) / std::pow(s.element_size, 3);
}

void check_shape_extent(const ShapeSpec& s, const std::string& where) {
  // The largest distance of a point of the shape from its centre.
  const double reach = s.shape == "box" ? 0.5 * s.size.norm()
                                        : std::max({s.radius, s.outer_radius}) + 0.5 * s.length;
  const double extent = s.center.cwiseAbs().maxCoeff() + reach;
  if (std::isfinite(extent) && extent <= kMaxCoordinate) return;
  std::ostringstream os;
  os << where << ": the " << s.shape << " reaches " << extent << " m from the origin (centre and size); expected "
     << "a shape within " << kMaxCoordinate << " m";
  throw InputError(os.str());
}

}  // namespace shatter
