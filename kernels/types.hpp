#pragma once
// Basic fixed-size types shared by every layer.
#include <Eigen/Dense>
#include <cstdint>

namespace shatter {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
/// Local (per-rank) index of a node, element, facet or surface primitive.
using Index = std::int32_t;
/// Global id, the same on every rank; used for I/O and for naming across ranks.
using GlobalId = std::int64_t;

}  // namespace shatter
