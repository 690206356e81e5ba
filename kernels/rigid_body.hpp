#pragma once
// One free rigid body (scene key bodies[i].rigid: free): its mass, centre of
// mass and inertia come from the lumped masses of its nodes, its motion is the
// translation of the centre plus a rotation. The rotation is integrated by the
// symmetric splitting of the free rigid body of Dullweber, Leimkuhler &
// McLachlan, "Symplectic splitting methods for rigid body molecular
// dynamics", J. Chem. Phys. 107 (1997) 5840-5851 (below: [DLM]): the kinetic
// energy T = sum_k pi_k^2 / (2 I_k) (pi the angular momentum in the principal
// frame) is split into its three terms, each of whose flows is an exact
// rotation about one principal axis, composed as 1(h/2) 2(h/2) 3(h) 2(h/2)
// 1(h/2). Every sub-flow keeps the spatial angular momentum L = R pi exactly
// (so the composition does, to round-off), the scheme is explicit, symplectic
// and second order: T oscillates within O((omega h)^2) without drift.
// Pure functions on fixed-size Eigen types: no allocation, no threads, no I/O.
#include <cmath>

#include <Eigen/Eigenvalues>

#include "kernels/types.hpp"

namespace shatter {

/// The state of one rigid body between two steps (SI units, world frame unless said).
struct RigidBodyState {
  double mass = 0;                    ///< M = sum of its nodes' lumped masses, kg
  Vec3 inertia = Vec3::Zero();        ///< principal moments I_1..I_3 about the centre, kg m^2
  Vec3 centre = Vec3::Zero();         ///< centre of mass c, m
  Vec3 velocity = Vec3::Zero();       ///< of the centre, V, m/s
  Mat3 orientation = Mat3::Identity();  ///< R: principal (body) frame -> world
  Vec3 angular_momentum = Vec3::Zero();  ///< L about the centre, kg m^2/s
  Vec3 force = Vec3::Zero();          ///< F, sum of the nodal external forces at the current configuration, N
  Vec3 torque = Vec3::Zero();         ///< about the centre, N m
};

/// R diag(1/I) R^T: the inverse inertia tensor in the world frame, 1/(kg m^2).
inline Mat3 rigid_inverse_inertia(const RigidBodyState& b) {
  return b.orientation * b.inertia.cwiseInverse().asDiagonal() * b.orientation.transpose();
}

/// omega = J^-1 L (world frame), rad/s.
inline Vec3 rigid_angular_velocity(const RigidBodyState& b) {
  return b.orientation * (b.orientation.transpose() * b.angular_momentum).cwiseQuotient(b.inertia);
}

/// The rotation by angle theta (rad) about the unit axis k (0, 1, 2) of the frame.
inline Mat3 rotation_about_axis(int k, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  Mat3 Q = Mat3::Identity();
  Q(i, i) = c, Q(i, j) = -s, Q(j, i) = s, Q(j, j) = c;
  return Q;
}

/// The rotation by the vector theta (rad; axis theta / |theta|) by Rodrigues' formula.
inline Mat3 rotation_by_vector(const Vec3& theta) {
  const double a = theta.norm();
  if (!(a > 0)) return Mat3::Identity();
  return Eigen::AngleAxisd(a, theta / a).toRotationMatrix();
}

/// The free rotation over h ([DLM] splitting, symmetric): R changes, the spatial L is kept
/// (the caller's; the body-frame pi = R^T L turns with the sub-rotations).
inline void rigid_free_rotation(RigidBodyState& b, double h) {
  Vec3 pi = b.orientation.transpose() * b.angular_momentum;
  auto flow = [&](int k, double t) {
    // The flow of T_k: a rotation about principal axis k by t pi_k / I_k; pi turns back.
    const Mat3 Q = rotation_about_axis(k, t * pi[k] / b.inertia[k]);
    b.orientation = b.orientation * Q;
    pi = Q.transpose() * pi;
  };
  flow(0, 0.5 * h);
  flow(1, 0.5 * h);
  flow(2, h);
  flow(1, 0.5 * h);
  flow(0, 0.5 * h);
}

/// The principal moments and axes of an inertia tensor J (symmetric, kg m^2): J = A diag(I) A^T,
/// A a rotation (det +1), I ascending.
inline void principal_axes(const Mat3& J, Vec3& moments, Mat3& axes) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(J);
  moments = eig.eigenvalues();
  axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
}

/// Kinetic energy 1/2 M V^2 + 1/2 L . omega, J.
inline double rigid_kinetic_energy(const RigidBodyState& b) {
  return 0.5 * b.mass * b.velocity.squaredNorm() + 0.5 * b.angular_momentum.dot(rigid_angular_velocity(b));
}

}  // namespace shatter
