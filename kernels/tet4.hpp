#pragma once
// Linear 4-node tetrahedron, one quadrature point (constant strain).
// Node order: Gmsh's (corners 0..3, positive volume when
// (x1-x0) . ((x2-x0) x (x3-x0)) > 0).
// With Ds = [x1-x0, x2-x0, x3-x0] (current) and Dm the same of the reference
// coordinates, F = Ds Dm^-1 and the nodal internal forces are
//   [f1 f2 f3] = -V0 P Dm^-T,   f0 = -(f1 + f2 + f3)
// (e.g. Sifakis & Barbic, "FEM simulation of 3D deformable solids", SIGGRAPH
// 2012 course notes, sec. 4.2).
#include <array>
#include <cmath>

#include "kernels/neo_hookean.hpp"
#include "kernels/types.hpp"

namespace shatter {

/// Signed volume of the tetrahedron (a, b, c, d), m^3.
inline double tet_signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

/// Smallest altitude of the tetrahedron (a, b, c, d) = 3 |V| / (largest face area), m.
/// The characteristic length of the stable time step.
inline double tet_min_altitude(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 ab = b - a, ac = c - a, ad = d - a, bc = c - b, bd = d - b;
  const double twice_area_max = std::max(std::max(ab.cross(ac).squaredNorm(), ab.cross(ad).squaredNorm()),
                                         std::max(ac.cross(ad).squaredNorm(), bc.cross(bd).squaredNorm()));
  const double six_volume = std::abs(ab.dot(ac.cross(ad)));
  return six_volume / std::sqrt(twice_area_max);  // 3V / A = (6V) / (2A)
}

/// Reference constants of one TET4: Dm^-1 and the reference volume V0.
struct Tet4Reference {
  Mat3 Dm_inv;
  double volume;
};

inline Tet4Reference tet4_reference(const Vec3& X0, const Vec3& X1, const Vec3& X2, const Vec3& X3) {
  Mat3 Dm;
  Dm << X1 - X0, X2 - X0, X3 - X0;
  return {Dm.inverse(), Dm.determinant() / 6.0};
}

/// Deformation gradient of a TET4 from its current corner positions.
inline Mat3 tet4_deformation_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                                      const Mat3& Dm_inv) {
  Mat3 Ds;
  Ds << x1 - x0, x2 - x0, x3 - x0;
  return Ds * Dm_inv;
}

/// Internal nodal forces (N, columns = nodes 0..3) and strain energy (J) of
/// one TET4; also its deformation gradient determinant J for the stable step.
struct Tet4Force {
  Eigen::Matrix<double, 3, 4> f;
  double energy;
  double J;
};

template <class Material>
inline Tet4Force tet4_internal_force(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                                     const Mat3& Dm_inv, double V0, const Material& mat) {
  const Mat3 F = tet4_deformation_gradient(x0, x1, x2, x3, Dm_inv);
  Mat3 P;
  double W;
  mat.stress_energy(F, P, W);
  Tet4Force out;
  const Mat3 H = V0 * P * Dm_inv.transpose();
  out.f.template rightCols<3>() = H;
  out.f.col(0) = -H.rowwise().sum();
  out.energy = V0 * W;
  out.J = F.determinant();
  return out;
}

}  // namespace shatter
