// Simulation: the state between two steps (SimulationState), saved every
// step as the last good state, restored for --restart, written as a
// checkpoint (runtime/checkpoint.hpp).
#include <algorithm>

#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/contact_stage.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/simulation.hpp"

#include "runtime/loads.hpp"
#include "runtime/rigid_bodies.hpp"
#include "runtime/timed.hpp"

namespace shatter {

void Simulation::save_checkpoint(const std::filesystem::path& path, SimulationState& s, const std::string& reason) {
  if (!dec_->distributed()) return write_checkpoint(path, model_, s, reason);
  // Every rank writes its own rows (checkpoint.hpp): a node's from the
  // smallest rank touching it, an element's and a cohesive element's from
  // their owners. The failure text is rank 0's, the one the file holds.
  CheckpointRows rows;
  rows.comm = dec_->comm();
  const size_t nodes = s.fracture ? std::min(s.x.size(), s.fracture->reference.size()) : s.x.size();
  for (Index n : dec_->touched_nodes())
    if (static_cast<size_t>(n) < nodes && dec_->node_owner(n) == dec_->rank()) rows.nodes.push_back(n);
  std::sort(rows.nodes.begin(), rows.nodes.end(),
            [&](Index a, Index b) { return model_.whole_node(a) < model_.whole_node(b); });
  if (fracture_) {
    rows.elements.assign(dec_->owned_element_ids().begin(), dec_->owned_element_ids().end());
    rows.cohesive = fracture_->owned_cohesive(*s.fracture);
  }
  write_checkpoint(path, model_, s, dec_->broadcast(reason, 0), &rows);

}

void Simulation::save_state(SimulationState& s) const {
  s.step = step_;
  s.time = time_;
  s.dt = dt_;
  s.stable_dt = stable_dt_;
  s.step_control = step_control_;
  // Every step saves the state before it (the last good state of a failure): only the nodes
  // this rank touches, in parallel; a checkpoint takes each node from its owner.
  const Index n = model_.mesh.num_nodes();
  for (auto* a : {&s.x, &s.v, &s.a, &s.f_int, &s.f_ext}) a->resize(n);
  dec_->for_touched(n, [&](Index i) {
    s.x[i] = x_[i];
    s.v[i] = v_[i];
    s.a[i] = a_[i];
    s.f_int[i] = f_int_[i];
    s.f_ext[i] = f_ext_[i];
  });
  s.reaction = reaction_;
  s.ledger = ledger_;
  s.total0 = total0_;
  s.energy_scale = energy_scale_;
  s.model_fingerprint = model_fingerprint_;
  s.model_nodes = model_nodes_;
  s.rigid = rigid_ ? rigid_->states() : std::vector<RigidBodyState>{};
  if (fracture_) {
    if (!s.fracture) s.fracture.emplace();
    fracture_->save(*s.fracture);
  } else {
    s.fracture.reset();
  }
}

void Simulation::restore_state(const SimulationState& s) {
  SHATTER_REQUIRE(!fracture_ == !s.fracture, "restore_state: the state " << (s.fracture ? "has" : "has no")
                                              << " fracture part, the scene " << (fracture_ ? "has" : "has no")
                                              << " fracture");
  if (fracture_) {
    // The mesh after splits, as grow_nodes left it; bc nodes stay in node
    // order, since split copies are appended in creation order.
    const std::uint64_t built_revision = model_.mesh.revision;
    fracture_->restore(*s.fracture);
    node_arrays_from_model();
    dec_->rebuild_nodes(fracture_->side_nodes(), kCohesiveSlots);
    if (contact_ && model_.mesh.revision != built_revision) rebuild_contact_surface();
    share_plans();
  }
  // (A part's state holds its own rows: read_checkpoint.)
  const size_t n = model_.mesh.num_nodes();
  SHATTER_REQUIRE(s.x.size() == n && s.v.size() == n && s.a.size() == n && s.f_int.size() == n && s.f_ext.size() == n &&
                      s.reaction.size() == bc_nodes_.size(),
                  "restore_state: the state has " << s.x.size() << " nodes and " << s.reaction.size()
                                                  << " reactions, the model " << n << " and " << bc_nodes_.size());
  x_ = s.x;
  v_ = s.v;
  a_ = s.a;
  f_int_ = s.f_int;
  f_ext_ = s.f_ext;
  reaction_ = s.reaction;
  SHATTER_REQUIRE(s.rigid.empty() || rigid_, "restore_state: the state has " << s.rigid.size()
                                                                           << " free rigid bodies, the scene none");
  if (rigid_) rigid_->restore(s.rigid, x_, v_);
  restore_scalars(s);
  if (loads_) {
    // The loads at x(n), which the next step's work starts from.
    loads_->rebuild();
    loads_->compute(x_, time_);
  }
}

void Simulation::restore_scalars(const SimulationState& s) {
  step_ = s.step;
  time_ = s.time;
  dt_ = s.dt;
  stable_dt_ = s.stable_dt;
  step_control_ = s.step_control;
  ledger_ = s.ledger;
  total0_ = s.total0;
  energy_scale_ = s.energy_scale;
  last_elements_.stable_dt = s.stable_dt;
  restored_ = true;
}

}  // namespace shatter
