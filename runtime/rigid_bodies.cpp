#include "runtime/rigid_bodies.hpp"

#include <algorithm>

#include "kernels/error.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/loads.hpp"

namespace shatter {

template <int K, class Term>
std::vector<std::array<double, K>> RigidBodies::body_sums(Term term) const {
  std::vector<ExactSum> sums(states_.size() * K);
  std::array<double, K> t;
  for (const Index i : nodes_)
    if (dec_.owns_node(i)) {
      t.fill(0.0);
      const int b = node_state_[i];
      term(i, b, t);
      for (int k = 0; k < K; ++k) sums[b * K + k] += t[k];
    }
  dec_.sum(sums);
  std::vector<std::array<double, K>> out(states_.size());
  for (size_t b = 0; b < states_.size(); ++b)
    for (int k = 0; k < K; ++k) out[b][k] = sums[b * K + k].value();
  return out;
}

RigidBodies::RigidBodies(const Model& model, const Decomposition& dec) : model_(model), dec_(dec) {
  const Scene& scene = model.scene;
  for (const BodySpec& b : scene.bodies) {
    index_.push_back(b.has_rigid_state() ? static_cast<int>(states_.size()) : -1);
    if (b.has_rigid_state()) {
      states_.emplace_back();
      prescribed_.push_back(b.rigid);
    }
  }
  const Mesh& mesh = model.mesh;
  node_state_.assign(mesh.num_nodes(), -1);
  node_body_.assign(mesh.num_nodes(), -1);
  for (Index i = 0; i < mesh.num_nodes(); ++i)
    if ((node_state_[i] = index_[mesh.node_body[i]]) >= 0) {
      nodes_.push_back(i);
      if (!prescribed_[node_state_[i]]) node_body_[i] = node_state_[i];
    }
  // Mass, centre and momentum; then about the centre the inertia tensor and angular momentum.
  const std::vector<Vec3>& X = mesh.reference;
  const std::vector<Vec3>& v0 = model.initial_velocity;
  const auto first = body_sums<7>([&](Index i, int, std::array<double, 7>& t) {
    const double m = model.mass[i];
    t[0] = m;
    for (int c = 0; c < 3; ++c) t[1 + c] = m * X[i][c], t[4 + c] = m * v0[i][c];
  });
  for (size_t b = 0; b < states_.size(); ++b) {
    RigidBodyState& s = states_[b];
    s.mass = first[b][0];
    SHATTER_REQUIRE(s.mass > 0, "rigid body " << b << " has mass " << s.mass);
    s.centre = Vec3(first[b][1], first[b][2], first[b][3]) / s.mass;
    s.velocity = Vec3(first[b][4], first[b][5], first[b][6]) / s.mass;
  }
  const auto second = body_sums<9>([&](Index i, int b, std::array<double, 9>& t) {
    const double m = model.mass[i];
    const Vec3 r = X[i] - states_[b].centre, L = m * r.cross(v0[i]);
    const double rr = r.squaredNorm();
    t[0] = m * (rr - r.x() * r.x()), t[1] = m * (rr - r.y() * r.y()), t[2] = m * (rr - r.z() * r.z());
    t[3] = -m * r.y() * r.z(), t[4] = -m * r.x() * r.z(), t[5] = -m * r.x() * r.y();
    for (int c = 0; c < 3; ++c) t[6 + c] = L[c];
  });
  for (size_t b = 0; b < states_.size(); ++b) {
    RigidBodyState& s = states_[b];
    if (prescribed_[b]) {
      // Its scene's motion, exactly: unit moments and L = omega make omega = J^-1 L.
      const BodySpec& spec = scene.bodies[std::find(index_.begin(), index_.end(), static_cast<int>(b)) - index_.begin()];
      s.velocity = spec.initial_velocity;
      s.inertia = Vec3::Ones();
      s.angular_momentum = spec.angular_velocity;
      continue;
    }
    const auto& t = second[b];
    Mat3 J;
    J << t[0], t[5], t[4], t[5], t[1], t[3], t[4], t[3], t[2];
    principal_axes(J, s.inertia, s.orientation);
    SHATTER_REQUIRE(s.inertia.minCoeff() > 0, "rigid body " << b << " has principal moments " << s.inertia.transpose());
    s.angular_momentum = Vec3(t[6], t[7], t[8]);
  }
  arm_.resize(nodes_.size());
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const RigidBodyState& s = states_[node_state_[nodes_[k]]];
    arm_[k] = s.orientation.transpose() * (X[nodes_[k]] - s.centre);
  }
  mobility_.resize(states_.size());
}

void RigidBodies::place(std::span<Vec3> x) const {
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const RigidBodyState& s = states_[node_state_[nodes_[k]]];
    x[nodes_[k]] = s.centre + s.orientation * arm_[k];
  }
}

void RigidBodies::set_velocities(std::span<const Vec3> x, std::span<Vec3> v) const {
  std::vector<Vec3> omega(states_.size());
  for (size_t b = 0; b < states_.size(); ++b) omega[b] = rigid_angular_velocity(states_[b]);
  for (const Index i : nodes_) {
    const int b = node_state_[i];
    v[i] = states_[b].velocity + omega[b].cross(x[i] - states_[b].centre);
  }
}

void RigidBodies::predict(double dt, std::span<Vec3> x, std::span<Vec3> v) {
  centre_old_.resize(states_.size());
  orientation_old_.resize(states_.size());
  for (size_t b = 0; b < states_.size(); ++b) {
    RigidBodyState& s = states_[b];
    centre_old_[b] = s.centre;
    orientation_old_[b] = s.orientation;
    if (!prescribed_[b]) {
      s.velocity += (0.5 * dt / s.mass) * s.force;
      s.angular_momentum += 0.5 * dt * s.torque;
    }
    s.centre += dt * s.velocity;
    rigid_free_rotation(s, dt);
  }
  place(x);
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const int b = node_state_[nodes_[k]];
    v[nodes_[k]] = (x[nodes_[k]] - (centre_old_[b] + orientation_old_[b] * arm_[k])) / dt;
  }
}

const DcrRigidBodies& RigidBodies::for_contact() {
  for (size_t b = 0; b < states_.size(); ++b)
    mobility_[b] = {1.0 / states_[b].mass, rigid_inverse_inertia(states_[b]), states_[b].centre};
  dcr_.node_body = node_body_;
  dcr_.bodies = mobility_;
  return dcr_;
}

void RigidBodies::apply_contact(std::vector<std::array<ExactSum, kRigidSums>> sums, double dt, std::span<Vec3> x,
                                std::span<Vec3> v) {
  sums.resize(states_.size());
  std::vector<ExactSum> flat;
  flat.reserve(states_.size() * kRigidSums);
  for (const auto& s : sums) flat.insert(flat.end(), s.begin(), s.end());
  dec_.sum(flat);
  for (size_t b = 0; b < states_.size(); ++b) {
    std::array<Vec3, 4> t;
    bool any = false;
    for (int k = 0; k < 4; ++k) {
      for (int c = 0; c < 3; ++c) t[k][c] = flat[b * kRigidSums + 3 * k + c].value();
      any = any || t[k] != Vec3::Zero();
    }
    if (!any) continue;
    RigidBodyState& s = states_[b];
    // About the centre: sum (x - c) x J = sum x x J - c x sum J.
    const Vec3 dP = t[0], dL = t[1] - s.centre.cross(t[0]), dS = t[2], dK = t[3] - s.centre.cross(t[2]);
    const Mat3 J_inv = rigid_inverse_inertia(s);
    const Vec3 centre_predicted = s.centre;
    const Mat3 orientation_predicted = s.orientation;
    const Vec3 dV = dP / s.mass, dW = J_inv * dL;
    s.velocity += dV;
    s.angular_momentum += dL;
    s.centre += dS / s.mass;
    s.orientation = rotation_by_vector(J_inv * dK) * s.orientation;
    // The nodes: placed again, with the chord velocity of the prediction plus the impulses' change.
    for (size_t k = 0; k < nodes_.size(); ++k) {
      const Index i = nodes_[k];
      if (node_state_[i] != static_cast<int>(b)) continue;
      const Vec3 old = centre_old_[b] + orientation_old_[b] * arm_[k];
      const Vec3 predicted = centre_predicted + orientation_predicted * arm_[k];
      x[i] = s.centre + s.orientation * arm_[k];
      v[i] = (predicted - old) / dt + dV + dW.cross(x[i] - s.centre);
    }
  }
}

void RigidBodies::gather_forces(std::span<const Vec3> x, const SurfaceLoads* loads) {
  const Vec3 g = model_.scene.gravity;
  std::vector<std::array<double, 6>> load(states_.size(), std::array<double, 6>{});
  // Every rank sums (collective), those without loaded faces too.
  if (!model_.scene.loads.empty()) {
    // (Scratch kept between steps: the loaded nodes are a few, the mesh's nodes many.)
    load_force_.resize(model_.mesh.num_nodes(), Vec3::Zero());
    loaded_.resize(model_.mesh.num_nodes(), 0);
    const std::span<const Index> nodes = loads ? loads->nodes() : std::span<const Index>{};
    for (size_t k = 0; k < nodes.size(); ++k) {
      load_force_[nodes[k]] += loads->force()[k];
      loaded_[nodes[k]] = 1;
    }
    load = body_sums<6>([&](Index i, int b, std::array<double, 6>& t) {
      if (!loaded_[i]) return;
      const Vec3& f = load_force_[i];
      const Vec3 tau = (x[i] - states_[b].centre).cross(f);
      for (int c = 0; c < 3; ++c) t[c] = f[c], t[3 + c] = tau[c];
    });
    for (const Index i : nodes) load_force_[i] = Vec3::Zero(), loaded_[i] = 0;
  }
  for (size_t b = 0; b < states_.size(); ++b) {
    if (prescribed_[b]) continue;  // its conditions' reactions take them
    states_[b].force = states_[b].mass * g + Vec3(load[b][0], load[b][1], load[b][2]);
    states_[b].torque = Vec3(load[b][3], load[b][4], load[b][5]);
  }
}

void RigidBodies::correct(double dt, std::span<const Vec3> x, std::span<Vec3> v) {
  for (size_t b = 0; b < states_.size(); ++b) {
    if (prescribed_[b]) continue;
    RigidBodyState& s = states_[b];
    s.velocity += (0.5 * dt / s.mass) * s.force;
    s.angular_momentum += 0.5 * dt * s.torque;
  }
  set_velocities(x, v);
}

void RigidBodies::restore(const std::vector<RigidBodyState>& states, std::span<Vec3> x, std::span<Vec3> v) {
  SHATTER_REQUIRE(states.size() == states_.size(),
                  "restore_state: the state has " << states.size() << " rigid bodies, the scene " << states_.size());
  states_ = states;
  place_nodes(x, v);
}

void RigidBodies::place_nodes(std::span<Vec3> x, std::span<Vec3> v) const {
  place(x);
  set_velocities(x, v);
}

}  // namespace shatter
