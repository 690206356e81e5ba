#pragma once
// The rigid bodies of a scene that have a state (BodySpec::has_rigid_state) in
// the time loop (docs/physics.md "Rigid bodies"): the free ones
// (bodies[i].rigid: free), and the prescribed ones (rigid: true) that spin.
// A prescribed body moves with its V and omega for ever: no force, torque or
// impulse acts on it (its nodes' conditions hold their translation, DCR sees
// them held: infinite mass), and it is kept as a body with unit principal
// moments and L = omega, whose free rotation is the exact rotation about
// omega. A free body is one particle with mass M,
// centre c and principal inertia I (of its nodes' lumped masses); its nodes sit
// at x_i = c + R s_i (s_i their arms in the principal frame, fixed) and move
// with v_i = V + omega x (x_i - c). The body's state is held whole on every
// rank: its sums over nodes (initial mass, moments and momenta; loads' force
// and torque; what DCR gave it) are exact sums over each node's owner, summed
// over the ranks (Decomposition::sum), so every rank holds the same bits on
// any decomposition and places every node of the body it holds (owned, ghost or
// in its contact patch) itself.
//
// The step, around the nodes' central difference (simulation.hpp):
//   predict:  V += dt/2 F/M, L += dt/2 tau; c += dt V; R by the free rotation
//             over dt (kernels/rigid_body.hpp); the nodes placed, with the
//             chord velocity (x(n+1) - x(n)) / dt that DCR's linear motion assumes;
//   contact:  DCR moves a pair's nodes of the body with its mobility
//             (PairMobility); then the body takes the pairs' impulses
//             (V += sum J / M, L += sum (x - c) x J) and shifts (c += sum S / M,
//             R turned by J^-1 sum (x - c) x S) and its nodes are placed again;
//   correct:  F, tau at x(n+1); V += dt/2 F/M, L += dt/2 tau; v_i = V + omega x r_i.
// F is M g plus the loads' nodal forces; tau the loads' torque about c (gravity's
// is 0: c is the centre of the lumped masses). The elements of rigid bodies are
// not computed (ElementForces), so the stable step is that of the other bodies.
#include <array>
#include <span>
#include <vector>

#include "contact/dcr.hpp"
#include "kernels/exact_sum.hpp"
#include "kernels/rigid_body.hpp"
#include "runtime/model.hpp"

namespace shatter {

class Decomposition;
class SurfaceLoads;

class RigidBodies {
 public:
  /// The rigid bodies of `model` with a state: mass and centre from the lumped masses; a
  /// free body's principal inertia too, and its momenta from the nodes' initial velocities;
  /// a prescribed one's V and omega from the scene (collective over dec's ranks).
  RigidBodies(const Model& model, const Decomposition& dec);

  /// Per body (of the scene): its index into states(), -1 for bodies without a state.
  const std::vector<int>& body_index() const { return index_; }
  const std::vector<RigidBodyState>& states() const { return states_; }
  /// Whether node i belongs to a body with a state (its place and velocity are set here).
  bool placed(Index i) const { return node_state_[i] >= 0; }

  /// Node splitting (fracture of other bodies) made n nodes; the new ones are not rigid.
  void grow(Index n) {
    node_body_.resize(n, -1);
    node_state_.resize(n, -1);
  }
  /// Predictor: the bodies kicked by dt/2 and moved over dt; their nodes placed in x,
  /// with the chord velocity in v.
  void predict(double dt, std::span<Vec3> x, std::span<Vec3> v);
  /// DCR's view of the bodies at the predicted configuration.
  const DcrRigidBodies& for_contact();
  /// What DCR gave the bodies (this rank's part: DcrResult::rigid; empty: nothing), summed
  /// over the ranks (collective); the bodies moved and kicked by it and their nodes placed.
  void apply_contact(std::vector<std::array<ExactSum, kRigidSums>> sums, double dt, std::span<Vec3> x,
                     std::span<Vec3> v);
  /// F and tau at positions x from gravity and the loads' forces (null: none here; collective).
  void gather_forces(std::span<const Vec3> x, const SurfaceLoads* loads);
  /// Corrector: the bodies kicked by dt/2, their nodes' velocities set.
  void correct(double dt, std::span<const Vec3> x, std::span<Vec3> v);
  /// The nodes of the bodies held here placed in x, their velocities in v.
  void place_nodes(std::span<Vec3> x, std::span<Vec3> v) const;
  /// A checkpoint's states (of the same bodies); the nodes placed in x and v.
  void restore(const std::vector<RigidBodyState>& states, std::span<Vec3> x, std::span<Vec3> v);

 private:
  /// x_i = c + R s_i for every node of the bodies held here.
  void place(std::span<Vec3> x) const;
  /// v_i = V + omega x (x_i - c).
  void set_velocities(std::span<const Vec3> x, std::span<Vec3> v) const;
  /// Exact sums per state of term(node, state, out[K]) over the nodes this rank owns, over the ranks.
  template <int K, class Term>
  std::vector<std::array<double, K>> body_sums(Term term) const;

  const Model& model_;
  const Decomposition& dec_;
  std::vector<int> index_;
  std::vector<RigidBodyState> states_;
  std::vector<char> prescribed_;          ///< per state: a rigid: true body (no force acts on it)
  std::vector<std::int32_t> node_state_;  ///< per node: its body's state, -1: none
  std::vector<std::int32_t> node_body_;   ///< per node: its free body's state (DCR's view), -1: none
  std::vector<Index> nodes_;  ///< the nodes of the bodies held here, ascending
  std::vector<Vec3> arm_;     ///< per nodes_: s_i, its arm in the principal frame, m
  std::vector<Vec3> centre_old_;       ///< per body: c(n) during a step
  std::vector<Mat3> orientation_old_;  ///< per body: R(n) during a step
  /// gather_forces' scratch, per node (zero and 0 between calls): the loads' force, and
  /// whether a load acts on the node
  std::vector<Vec3> load_force_;
  std::vector<char> loaded_;
  std::vector<DcrRigidBodies::Body> mobility_;
  DcrRigidBodies dcr_;
};

}  // namespace shatter
