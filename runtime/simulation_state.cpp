// Simulation: the state between two steps (SimulationState), saved every
// step as the last good state, restored for --restart, written as a
// checkpoint (runtime/checkpoint.hpp).
#include <algorithm>
#include <optional>

#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/contact_stage.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/row_blocks.hpp"
#include "runtime/simulation.hpp"

#include "runtime/loads.hpp"
#include "runtime/rigid_bodies.hpp"
#include "runtime/timed.hpp"

namespace shatter {

void Simulation::save_checkpoint(const std::filesystem::path& path, SimulationState& s, const std::string& reason) {
  if (dec_->distributed()) {
    // Every node's values from its owner, in the whole model's node order, on
    // rank 0; the reactions through a nodal array, with a flag per node that has them.
    const Index n = model_.mesh.num_nodes();
    std::vector<Vec3> reaction(n, Vec3::Zero()), has(n, Vec3::Zero());
    for (size_t b = 0; b < bc_nodes_.size(); ++b) reaction[bc_nodes_[b]] = s.reaction[b], has[bc_nodes_[b]].x() = 1;
    const std::span<const Vec3> arrays[] = {s.x, s.v, s.a, s.f_int, s.f_ext, reaction, has};
    std::vector<std::vector<Vec3>> whole;
    timed(comm_seconds_, [&] { whole = dec_->gather_to_root(arrays); });
    if (dec_->rank() == 0) {
      s.x = std::move(whole[0]), s.v = std::move(whole[1]), s.a = std::move(whole[2]);
      s.f_int = std::move(whole[3]), s.f_ext = std::move(whole[4]);
      s.reaction.clear();
      for (size_t i = 0; i < whole[6].size(); ++i)
        if (whole[6][i].x() != 0) s.reaction.push_back(whole[5][i]);
    }
  }
  // The whole model's fracture state, from the owners, in place of rank 0's own
  // until the checkpoint is written (the next saves fill in their own).
  std::optional<FractureState> mine;
  if (fracture_ && dec_->distributed()) {
    FractureState whole;
    timed(comm_seconds_, [&] { whole = fracture_->gather(*s.fracture); });
    if (dec_->rank() == 0) {
      mine = std::move(*s.fracture);
      *s.fracture = std::move(whole);
    }
  }
  std::string failure;
  if (dec_->rank() == 0) try {
      write_checkpoint(path, model_, s, reason);
    } catch (const Error& e) {
      failure = e.what();
    }
  if (mine) *s.fracture = std::move(*mine);
  if (dec_->max(failure.empty() ? 0 : 1)) throw Error(failure.empty() ? "writing the checkpoint failed on rank 0" : failure);
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
