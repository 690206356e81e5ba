#include "runtime/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <cstdio>
#include <sstream>

#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/contact_stage.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/failure.hpp"
#include "runtime/field_output.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/global_sum.hpp"
#include "runtime/parallel.hpp"
#include "runtime/report.hpp"

namespace shatter {
namespace {

/// Runs f and adds its wall time to `seconds`.
template <class F>
void timed(double& seconds, F f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct BodyRow {
  double mass = 0;
  Vec3 mx = Vec3::Zero(), mv = Vec3::Zero();
};

/// What, where and when for a step whose DCR sweeps reached the cap, when
/// the scene says contact.on_sweep_cap: fail. `step` is the step under way.
std::string sweep_cap_diagnosis(const Model& model, std::span<const Vec3> x, const ContactPairs& pairs,
                                const DcrResult& r, long step, double time) {
  std::ostringstream os;
  os << "step " << step << ", t = " << time << " s: DCR sweeps reached the cap (contact.max_sweeps = "
     << model.scene.contact->max_sweeps << ") with penetrations left (contact.on_sweep_cap: fail)";
  if (r.unresolved >= 0 && static_cast<size_t>(r.unresolved) < pairs.size()) {
    const ContactPair& p = pairs[r.unresolved];
    Vec3 centre = Vec3::Zero();
    os << "; still penetrating: " << (p.kind == ContactPair::VertexFace ? "vertex-face" : "edge-edge")
       << " pair of nodes";
    for (const Index n : p.nodes) {
      os << " " << model.mesh.node_gid[n] << " ('" << model.scene.bodies[model.mesh.node_body[n]].name << "')";
      centre += 0.25 * x[n];
    }
    os << " near (" << centre.x() << ", " << centre.y() << ", " << centre.z() << ")";
  }
  os << "; try a smaller time.safety or a larger contact.max_sweeps";
  return os.str();
}

/// What, where and when for a ledger that is no longer finite at the end of
/// step `step` (a NaN or overflow that has not reached the positions yet).
std::string non_finite_diagnosis(const Model& model, std::span<const Vec3> x, std::span<const Vec3> v,
                                 std::span<const Vec3> a, const Ledger& l, long step, double time) {
  std::ostringstream os;
  os << "step " << step << ", t = " << time << " s: the energy ledger is not finite (kinetic " << l.kinetic
     << ", strain " << l.strain << ", cohesive " << l.cohesive_stored << " + " << l.cohesive_dissipated
     << ", contact " << l.contact_dissipated << ", external work " << l.external_work << ")";
  for (size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite() || !a[i].allFinite()) {
      os << "; node " << model.mesh.node_gid[i] << " (body '" << model.scene.bodies[model.mesh.node_body[i]].name
         << "') at (" << x[i].x() << ", " << x[i].y() << ", " << x[i].z() << ") has velocity (" << v[i].x() << ", "
         << v[i].y() << ", " << v[i].z() << ")";
      break;
    }
  os << "; try a smaller time.safety or a finer mesh";
  return os.str();
}

}  // namespace

Simulation::Simulation(Model& model, RunOptions options)
    : model_(model),
      opt_(std::move(options)),
      dec_(std::make_unique<Decomposition>(model, opt_.ranks > 1 ? MPI_COMM_WORLD : MPI_COMM_SELF)),
      elements_(model) {
  const Mesh& mesh = model_.mesh;
  model_fingerprint_ = model_fingerprint(model_);
  if (dec_->distributed()) {
    // Every rank meshed the scene itself: check that they agree.
    std::uint64_t fp[2] = {model_fingerprint_, ~model_fingerprint_};
    MPI_Allreduce(MPI_IN_PLACE, fp, 2, MPI_UINT64_T, MPI_MAX, dec_->comm());
    if (fp[0] != ~fp[1])
      throw Error(model_.scene.file + ": the MPI ranks built different models from the scene (meshing differs "
                  "between processes)");
  }
  const Index n = mesh.num_nodes();
  model_nodes_ = n;
  x_ = mesh.reference;
  v_ = model_.initial_velocity;
  a_.assign(n, Vec3::Zero());
  f_int_.assign(n, Vec3::Zero());
  f_ext_.assign(n, Vec3::Zero());
  if (model_.scene.contact) {
    contact_ = std::make_unique<ContactStage>(model_, *model_.scene.contact, dec_.get());
    book_contact_work_ =
        model_.scene.contact->restitution < 1.0 || model_.scene.contact->friction > 0.0;
  }
  node_arrays_from_model();
  reaction_.assign(bc_nodes_.size(), Vec3::Zero());
  if (model_.scene.fracture_enabled()) {
    fracture_ = std::make_unique<FractureStage>(model_);
    stress6_.resize(6 * static_cast<size_t>(model_.mesh.num_elements()));
  }
  ledger_.fragments = static_cast<long>(model_.scene.bodies.size());
  share_plans();
  compute_forces(0, 0.0);
  update_ledger();
  total0_ = ledger_.total();
  stable_dt0_ = stable_dt_;
  energy_scale_ = std::max(ledger_.kinetic + ledger_.strain, 1e-300);
  if (model_.scene.fixed_dt && *model_.scene.fixed_dt > stable_dt_ && !opt_.quiet && dec_->rank() == 0)
    std::fprintf(stderr, "warning: %s: time.dt = %.3e s is above the stable step %.3e s; the run may blow up\n",
                 model_.scene.file.c_str(), *model_.scene.fixed_dt, stable_dt_);
}

Simulation::~Simulation() = default;

double StepControl::next(double safe) {
  if (dt > 0 && safe >= dt) {
    window_min = std::min(window_min, safe);
    if (++window_steps < kWindow) return dt;
    // The end of a window of kWindow steps at this step.
    dt = std::max(dt, std::min(kGrowth * dt, kHeadroom * window_min));
  } else {
    dt = dt > 0 ? kHeadroom * safe : safe;
  }
  window_min = HUGE_VAL;
  window_steps = 0;
  return dt;
}

double Simulation::next_dt() {
  const double dt = model_.scene.fixed_dt ? *model_.scene.fixed_dt
                                          : step_control_.next(model_.scene.safety * stable_dt_);
  const double remaining = model_.scene.end_time - time_;
  // Land on end_time exactly, without a sliver of a last step.
  return remaining < 1.5 * dt && remaining > dt ? 0.5 * remaining : std::min(dt, remaining);
}

void Simulation::compute_forces(long step, double time, const std::function<void()>& between) {
  if (cohesive_nodes_) {
    const std::span<Vec3> arrays[] = {x_};
    timed(comm_seconds_, [&] { dec_->share(*cohesive_nodes_, arrays); });
  }
  // `between` (the end of the ghost update) is timed as communication.
  const double comm_before = comm_seconds_;
  timed(element_seconds_, [&] { last_elements_ = elements_.compute(x_, f_int_, stress6_, between); });
  element_seconds_ -= comm_seconds_ - comm_before;
  if (fracture_) {
    const CohesiveEnergy ce = fracture_->add_forces(x_, f_int_);
    ledger_.cohesive_stored = ce.stored;
    ledger_.cohesive_dissipated = ce.dissipated;
  }
  // With cohesive elements the stable step also bounds their stiffness.
  stable_dt_ = dec_->min(fracture_ ? fracture_->stable_dt(last_elements_.stable_dt, model_.mass)
                                   : last_elements_.stable_dt);
  if (dec_->distributed()) {
    // The worst element over all ranks (NaN first, then the smallest det F,
    // then the smallest index, as on one rank).
    struct {
      double J;
      int e;
    } worst{std::isnan(last_elements_.min_jacobian) ? -HUGE_VAL : last_elements_.min_jacobian,
            last_elements_.worst_element < 0 ? std::numeric_limits<int>::max() : last_elements_.worst_element};
    MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE_INT, MPI_MINLOC, dec_->comm());
    last_elements_.min_jacobian = worst.J == -HUGE_VAL ? std::nan("") : worst.J;
    last_elements_.worst_element = worst.e == std::numeric_limits<int>::max() ? -1 : worst.e;
  }
  if (!(last_elements_.min_jacobian > 0)) {
    const Index e = last_elements_.worst_element;
    Vec3 centre = Vec3::Zero();
    // The element's owner has its current positions.
    if (e >= 0 && dec_->owns_element(e))
      for (int a = 0; a < 4; ++a) centre += 0.25 * x_[model_.mesh.element(e)[a]];
    if (e >= 0) dec_->broadcast({centre.data(), 3}, dec_->granule_rank(e / ElementForces::kGranule));
    std::ostringstream os;
    os << "step " << step << ", t = " << time << " s: element " << (e >= 0 ? model_.mesh.elem_gid[e] : -1)
       << " (body '" << (e >= 0 ? model_.scene.bodies[model_.mesh.elem_body[e]].name : "?") << "') "
       << (std::isnan(last_elements_.min_jacobian) ? "has NaN coordinates" : "is inverted") << " (det F = "
       << last_elements_.min_jacobian << ") near (" << centre.x() << ", " << centre.y() << ", " << centre.z()
       << "); try a smaller time.safety or a finer mesh";
    throw Error(os.str());
  }
  const Vec3 g = model_.scene.gravity;
  const Index n = model_.mesh.num_nodes();
  dec_->for_touched(n, [&](Index i) {
    f_ext_[i] = model_.mass[i] * g;
    a_[i] = inv_mass_[i] * (f_ext_[i] - f_int_[i]);
  });
  // Prescribed components: no acceleration; the reaction is the force that holds them.
  for (size_t b = 0; b < bc_nodes_.size(); ++b) {
    const Index i = bc_nodes_[b];
    for (int c = 0; c < 3; ++c)
      if (model_.bc_mask[i] & (1u << c)) {
        reaction_[b][c] = f_int_[i][c] - f_ext_[i][c];
        a_[i][c] = 0.0;
      } else {
        reaction_[b][c] = 0.0;
      }
  }
}

void Simulation::step() {
  if (step_ + 1 == opt_.fail_step && dec_->rank() == opt_.fail_rank)
    throw Error("step " + std::to_string(step_ + 1) + ": failure injected on rank " +
                std::to_string(opt_.fail_rank) + " by SHATTER_TEST_FAIL");
  dt_ = next_dt();
  const double dt = dt_, half = 0.5 * dt;
  const Index n = model_.mesh.num_nodes();
  const Vec3 g = model_.scene.gravity;
  // External work over the step: gravity exactly (constant force), reactions
  // by the trapezoidal rule, W += (R(n) + R(n+1))/2 . dx.
  std::vector<Vec3> dx_bc(bc_nodes_.size());
  const std::vector<Vec3> reaction_old = reaction_;

  auto half_kick = [&](Index i) {
    v_[i] += half * a_[i];
    if (model_.bc_mask[i])
      for (int c = 0; c < 3; ++c)
        if (model_.bc_mask[i] & (1u << c)) v_[i][c] = model_.bc_velocity[i][c];
  };
  dec_->for_touched(n, half_kick);
  for (size_t b = 0; b < bc_nodes_.size(); ++b) dx_bc[b] = dt * v_[bc_nodes_[b]];
  if (contact_) x_prev_ = x_;
  dec_->for_touched(n, [&](Index i) { x_[i] += dt * v_[i]; });
  if (contact_) {
    // Every rank resolves the whole contact surface from the owners' states.
    if (surface_nodes_) {
      const std::span<Vec3> arrays[] = {x_prev_, x_, v_};
      timed(comm_seconds_, [&] { dec_->share(*surface_nodes_, arrays); });
    }
    const std::vector<Index>& vertices = contact_->surface().vertices;
    if (book_contact_work_) {
      contact_dx_.resize(vertices.size());
      contact_dv_.resize(vertices.size());
      for (size_t k = 0; k < vertices.size(); ++k)
        contact_dx_[k] = x_[vertices[k]], contact_dv_[k] = v_[vertices[k]];
    }
    const DcrResult r = contact_->apply(x_prev_, x_, v_, contact_inv_mass_, dt);
    if (book_contact_work_)
      for (size_t k = 0; k < vertices.size(); ++k) {
        contact_dx_[k] = x_[vertices[k]] - contact_dx_[k];
        contact_dv_[k] = v_[vertices[k]] - contact_dv_[k];
      }
    ledger_.contacts = r.contacts;
    ledger_.contact_dissipated += r.dissipated;
    if (r.capped) {
      if (model_.scene.contact->sweep_cap_fatal)
        throw Error(sweep_cap_diagnosis(model_, x_, contact_->candidates(), r, step_ + 1, time_ + dt));
      if (ledger_.contact_capped_steps == 0 && !opt_.quiet && dec_->rank() == 0)
        std::fprintf(stderr, "\nwarning: step %ld: DCR sweeps reached the cap (%d) with penetrations left; "
                     "counted in history.csv column contact_capped_steps\n", step_ + 1, model_.scene.contact->max_sweeps);
      ++ledger_.contact_capped_steps;
    }
  }
  // The ghost-only positions travel while the elements that do not read them
  // are computed (ElementForces::restrict_to).
  timed(comm_seconds_, [&] { dec_->begin_ghost_update(x_); });
  // Gravity's work over the step's displacement (the projection's included).
  if (g.squaredNorm() != 0)
    step_work_[kGravityWork] += exact_sums<1>(dec_->owned_nodes(), [&](Index i, std::array<ExactSum, 1>& w) {
      w[0] += model_.mass[i] * g.dot(contact_ ? Vec3(x_[i] - x_prev_[i]) : Vec3(dt * v_[i]));
    })[0];

  compute_forces(step_ + 1, time_ + dt, [&] { timed(comm_seconds_, [&] { dec_->end_ghost_update(x_); }); });
  if (book_contact_work_) {
    // What the contact's changes dx of x(n+1) and dv of v(n+1/2) did to the central-difference
    // energy besides the impulses' kinetic-energy loss, to first order: -f(n+1) . (dx - dt/2 dv)
    // (docs/contact.md, "The ledger with e < 1"); booked as contact dissipation.
    const std::vector<Index>& vertices = contact_->surface().vertices;
    for (size_t k = 0; k < vertices.size(); ++k) {
      const Index i = vertices[k];
      if (dec_->node_owner(i) == dec_->rank() &&
          (contact_dx_[k] != Vec3::Zero() || contact_dv_[k] != Vec3::Zero()))
        step_work_[kContactWork] += (f_ext_[i] - f_int_[i]).dot(contact_dx_[k] - half * contact_dv_[k]);
    }
  }

  dec_->for_touched(n, half_kick);
  for (size_t b = 0; b < bc_nodes_.size(); ++b)
    if (dec_->node_owner(bc_nodes_[b]) == dec_->rank())
      step_work_[kReactionWork] += 0.5 * (reaction_old[b] + reaction_[b]).dot(dx_bc[b]);
  time_ += dt;
  ++step_;
  if (fracture_ && step_ % model_.scene.fracture_check_every == 0) apply_fracture();
  update_ledger();
  if (!std::isfinite(ledger_.total())) throw Error(non_finite_diagnosis(model_, x_, v_, a_, ledger_, step_, time_));
}

void Simulation::apply_fracture() {
  // Every rank holds the positions of every cohesive node (compute_forces),
  // so releases are the same everywhere.
  fracture_->release(x_);
  // A facet is checked by the owner of its smaller element, which holds both
  // elements' stresses; every rank inserts the same list.
  std::vector<Index> critical = dec_->distributed() ? dec_->allgather(fracture_->check(
                                                          x_, stress6_, dec_->local_elements(), dec_->owned_element_ids()))
                                                    : fracture_->check(x_, stress6_);
  const Index before = fracture_->cohesive_count();
  const Insertion ins = fracture_->insert(critical);
  ledger_.cohesive_elements = fracture_->cohesive_count();
  if (ledger_.cohesive_elements == before) return;
  if (!ins.new_nodes.empty()) {
    grow_nodes(ins.new_nodes);
    if (contact_) contact_->rebuild(model_.mesh);
  }
  share_plans();
  // The split nodes' masses and forces changed: recompute the accelerations
  // that the next half step uses (the velocities were copied, so momentum is
  // unchanged).
  if (!ins.new_nodes.empty()) compute_forces(step_, time_);
}

void Simulation::share_plans() {
  if (!dec_->distributed()) return;
  elements_.restrict_to(dec_->local_elements(), dec_->held_nodes(), dec_->ghost_only_nodes());
  auto plan = [&](std::vector<Index> nodes) { return std::make_unique<SharedNodes>(dec_->shared_nodes(std::move(nodes))); };
  if (contact_) surface_nodes_ = plan(contact_->surface().vertices);
  if (fracture_ && fracture_->cohesive_count() > 0) cohesive_nodes_ = plan(fracture_->cohesive_nodes());
}

void Simulation::grow_nodes(const std::vector<std::array<Index, 2>>& new_nodes) {
  const Index n = model_.mesh.num_nodes();
  for (auto* a : {&x_, &v_, &a_, &f_int_, &f_ext_, &model_.bc_velocity, &model_.initial_velocity}) a->resize(n);
  model_.bc_mask.resize(n);
  model_.mass.resize(n);
  inv_mass_.resize(n);
  if (contact_) contact_inv_mass_.resize(n);
  std::vector<Index> touched;
  for (const auto& [child, parent] : new_nodes) {
    x_[child] = x_[parent];
    v_[child] = v_[parent];
    model_.bc_mask[child] = model_.bc_mask[parent];
    model_.bc_velocity[child] = model_.bc_velocity[parent];
    model_.initial_velocity[child] = model_.initial_velocity[parent];
    if (model_.bc_mask[child]) {
      bc_nodes_.push_back(child);
      reaction_.push_back(Vec3::Zero());
    }
    touched.push_back(child);
    touched.push_back(parent);
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  recompute_node_masses(model_, touched);
  for (Index i : touched) {
    inv_mass_[i] = 1.0 / model_.mass[i];
    if (contact_) contact_inv_mass_[i] = model_.bc_mask[i] ? 0.0 : inv_mass_[i];
  }
  dec_->rebuild_nodes();
}

void Simulation::save_checkpoint(const std::filesystem::path& path, SimulationState& s, const std::string& reason) {
  if (dec_->distributed()) {
    // Every node's values from its owner; reactions through a nodal array.
    std::vector<Vec3> reaction(model_.mesh.num_nodes(), Vec3::Zero());
    for (size_t b = 0; b < bc_nodes_.size(); ++b) reaction[bc_nodes_[b]] = s.reaction[b];
    const std::span<Vec3> arrays[] = {s.x, s.v, s.a, s.f_int, s.f_ext, reaction};
    dec_->gather_to_root(arrays);
    for (size_t b = 0; b < bc_nodes_.size(); ++b) s.reaction[b] = reaction[bc_nodes_[b]];
  }
  std::string failure;
  if (dec_->rank() == 0) try {
      write_checkpoint(path, model_, s, reason);
    } catch (const Error& e) {
      failure = e.what();
    }
  if (dec_->max(failure.empty() ? 0 : 1)) throw Error(failure.empty() ? "writing the checkpoint failed on rank 0" : failure);
}

void Simulation::node_arrays_from_model() {
  const Index n = model_.mesh.num_nodes();
  inv_mass_.resize(n);
  bc_nodes_.clear();
  for (Index i = 0; i < n; ++i) {
    inv_mass_[i] = 1.0 / model_.mass[i];
    if (model_.bc_mask[i]) bc_nodes_.push_back(i);
  }
  // DCR treats a node with any prescribed component as immovable.
  if (contact_) {
    contact_inv_mass_.resize(n);
    for (Index i = 0; i < n; ++i) contact_inv_mass_[i] = model_.bc_mask[i] ? 0.0 : inv_mass_[i];
  }
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
    dec_->rebuild_nodes();
    if (contact_ && model_.mesh.revision != built_revision) contact_->rebuild(model_.mesh);
    share_plans();
  }
  const size_t n = model_.mesh.num_nodes();
  SHATTER_REQUIRE(s.x.size() == n && s.v.size() == n && s.a.size() == n && s.f_int.size() == n &&
                      s.f_ext.size() == n && s.reaction.size() == bc_nodes_.size(),
                  "restore_state: the state has " << s.x.size() << " nodes and " << s.reaction.size()
                                                  << " reactions, the model " << n << " and " << bc_nodes_.size());
  step_ = s.step;
  time_ = s.time;
  dt_ = s.dt;
  stable_dt_ = s.stable_dt;
  step_control_ = s.step_control;
  x_ = s.x;
  v_ = s.v;
  a_ = s.a;
  f_int_ = s.f_int;
  f_ext_ = s.f_ext;
  reaction_ = s.reaction;
  ledger_ = s.ledger;
  total0_ = s.total0;
  energy_scale_ = s.energy_scale;
  last_elements_.stable_dt = s.stable_dt;
  restored_ = true;
}

void Simulation::update_ledger() {
  // Exact sums over the owned nodes, the owned granules' strain energy and
  // the step's work, then over the ranks: the same bits for any
  // decomposition and thread count.
  constexpr int kKinetic = 0, kP = 1, kL = 4, kStrain = 7, kLocal = 8, kSums = kLocal + int{kStepWorks};
  const std::array<ExactSum, kLocal> nodes =
      exact_sums<kLocal>(dec_->owned_nodes(), [&](Index i, std::array<ExactSum, kLocal>& s) {
        const Vec3 p = model_.mass[i] * v_[i], L = x_[i].cross(p);
        s[kKinetic] += 0.5 * p.dot(v_[i]);
        for (int c = 0; c < 3; ++c) s[kP + c] += p[c], s[kL + c] += L[c];
      });
  std::array<ExactSum, kSums> t;
  std::copy(nodes.begin(), nodes.end(), t.begin());
  const std::span<const double> strain = elements_.granule_energy();
  for (Index gr : dec_->owned_granules()) t[kStrain] += strain[gr];
  std::copy(step_work_.begin(), step_work_.end(), t.begin() + kLocal);
  step_work_ = {};
  timed(comm_seconds_, [&] { dec_->sum(t); });
  ledger_.kinetic = t[kKinetic].value();
  ledger_.momentum = Vec3(t[kP].value(), t[kP + 1].value(), t[kP + 2].value());
  ledger_.angular_momentum = Vec3(t[kL].value(), t[kL + 1].value(), t[kL + 2].value());
  ledger_.strain = t[kStrain].value();
  ledger_.external_work += t[kLocal + kGravityWork].value() + t[kLocal + kReactionWork].value();
  ledger_.contact_dissipated += t[kLocal + kContactWork].value();
  // Energy errors are relative to the largest energy the model has held.
  energy_scale_ = std::max(energy_scale_, ledger_.kinetic + ledger_.strain + ledger_.cohesive_stored +
                                              std::abs(ledger_.external_work));
}

std::array<std::span<const Vec3>, 2> Simulation::root_state(std::vector<Vec3>& x, std::vector<Vec3>& v) {
  if (!dec_->distributed()) return {x_, v_};
  x = x_;
  v = v_;
  const std::span<Vec3> arrays[] = {x, v};
  dec_->gather_to_root(arrays);
  return {x, v};
}

void Simulation::write_outputs(bool fields) {
  if (opt_.out_dir.empty()) return;
  const bool root = dec_->rank() == 0;
  // The fragments' element ids: topology, the same on every rank.
  std::optional<Fragments> frags;
  if (fracture_) {
    frags = fracture_->fragment_labels();
    ledger_.fragments = frags->count();
  }
  const Ledger& l = ledger_;
  if (root) {
    *history_ << step_ << time_ << dt_ << l.kinetic << l.strain << l.cohesive_stored << l.cohesive_dissipated
              << l.contact_dissipated << l.external_work << l.total() << l.momentum.x() << l.momentum.y()
              << l.momentum.z() << l.angular_momentum.x() << l.angular_momentum.y() << l.angular_momentum.z()
              << l.contacts << l.cohesive_elements << l.fragments << l.contact_capped_steps;
    history_->end_row();
  }

  // Body rows: mass, m x, m v per body, exact sums over the owned nodes.
  const Mesh& mesh = model_.mesh;
  const int nb = static_cast<int>(model_.scene.bodies.size());
  std::vector<ExactSum> sums(static_cast<size_t>(nb) * 7);
  for (Index i : dec_->owned_nodes()) {
    ExactSum* r = sums.data() + static_cast<size_t>(mesh.node_body[i]) * 7;
    const double m = model_.mass[i];
    r[0] += m;
    for (int c = 0; c < 3; ++c) r[1 + c] += m * x_[i][c], r[4 + c] += m * v_[i][c];
  }
  timed(comm_seconds_, [&] { dec_->sum(sums); });
  std::vector<BodyRow> rows(nb);
  for (int b = 0; b < nb; ++b) {
    const ExactSum* r = sums.data() + static_cast<size_t>(b) * 7;
    rows[b].mass = r[0].value();
    rows[b].mx = Vec3(r[1].value(), r[2].value(), r[3].value());
    rows[b].mv = Vec3(r[4].value(), r[5].value(), r[6].value());
  }
  for (int b = 0; b < nb && root; ++b) {
    const Vec3 c = rows[b].mx / rows[b].mass, v = rows[b].mv / rows[b].mass;
    *bodies_ << step_ << time_ << model_.scene.bodies[b].name << rows[b].mass << c.x() << c.y() << c.z() << v.x()
             << v.y() << v.z();
    bodies_->end_row();
  }

  if (fields && fields_) {
    // Rank 0 writes every row (from the owners' values); the others take
    // part in the collective writes with none.
    std::vector<Vec3> x_all, v_all;
    const std::array<std::span<const Vec3>, 2> xv = root_state(x_all, v_all);
    std::vector<Vec3> u;
    std::vector<double> stress, vm;
    FieldFrame f;
    f.step = static_cast<int>(step_);
    f.time = time_;
    Mesh empty;
    empty.order = mesh.order;
    std::vector<int> fragment_id;
    std::vector<double> damage;
    if (root) {
      element_stresses(model_, xv[0], stress, vm);
      u.resize(mesh.num_nodes());
      for (Index i = 0; i < mesh.num_nodes(); ++i) u[i] = xv[0][i] - mesh.reference[i];
      f.displacement = u;
      f.velocity = xv[1];
      f.stress = stress;
      f.von_mises = vm;
      f.body = mesh.elem_body;
      if (frags) {
        fragment_id.assign(frags->elem_fragment.begin(), frags->elem_fragment.end());
        f.fragment = fragment_id;
        damage = fracture_->damage();
        f.damage = damage;
      }
    }
    fields_->write(root ? mesh : empty, f);
  }
}

long Simulation::run() {
  const Scene& scene = model_.scene;
  const auto wall0 = std::chrono::steady_clock::now();
  const bool root = dec_->rank() == 0;
  long field_every = scene.output_every;
  if (field_every < 0) {
    // Default: about 20 frames over the run.
    const double est_steps = scene.end_time / (scene.fixed_dt ? *scene.fixed_dt : scene.safety * stable_dt0_);
    field_every = std::max(1L, static_cast<long>(std::ceil(est_steps / 20)));
  }
  if (!opt_.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt_.out_dir, ec);
    if (ec) throw Error("cannot create the output folder " + opt_.out_dir.string() + ": " + ec.message());
    // A restart keeps the rows up to its step and appends the rest.
    if (restored_ && root)
      for (const char* csv : {"history.csv", "bodies.csv"}) truncate_rows_after(opt_.out_dir / csv, step_);
    if (root) {
    history_ = std::make_unique<CsvWriter>(
        opt_.out_dir / "history.csv",
        std::vector<std::string>{"step", "time", "dt", "kinetic", "strain", "cohesive_stored", "cohesive_dissipated",
                                 "contact_dissipated", "external_work", "total", "px", "py", "pz", "Lx", "Ly", "Lz",
                                 "contacts", "cohesive_elements", "fragments", "contact_capped_steps"},
        restored_);
    bodies_ = std::make_unique<CsvWriter>(
        opt_.out_dir / "bodies.csv",
        std::vector<std::string>{"step", "time", "body", "mass", "cx", "cy", "cz", "vx", "vy", "vz"}, restored_);
    }
    // A restart's frames go to OUTDIR/restart_<step>/; fields.h5 keeps the earlier ones.
    const std::filesystem::path field_dir =
        restored_ ? opt_.out_dir / ("restart_" + std::to_string(step_)) : opt_.out_dir;
    if (field_every > 0)
      fields_ = std::make_unique<FieldWriter>(field_dir, dec_->distributed() ? dec_->comm() : MPI_COMM_WORLD);
  }
  Progress progress(scene.end_time, opt_.quiet || !root);
  if (!restored_) write_outputs(field_every > 0);
  // Checkpoints (checkpoint.hpp): periodic, on SIGINT/SIGTERM, and of the
  // last good state when a step fails. On
  // several ranks, rank 0 writes the owners' values (save_checkpoint).
  const std::filesystem::path checkpoint = opt_.out_dir / "checkpoint.h5";
  const bool checkpoints = !opt_.out_dir.empty();
  SimulationState good;  // the state before the current step
  auto last_checkpoint = std::chrono::steady_clock::now();
  const double tiny = 1e-12 * scene.end_time;
  while (time_ < scene.end_time - tiny) {
    if (checkpoints) save_state(good);
    try {
      step();
    } catch (const std::exception& e) {
      if (!checkpoints) throw;
      progress.finish();
      // On several ranks the state is saved only when every rank failed in
      // this step; a failure of this rank alone leaves the others in a
      // collective, and the CLI aborts them all.
      if (dec_->distributed() && opt_.failures && !opt_.failures->agree(1).all_ranks) throw;
      try {
        save_checkpoint(checkpoint, good, e.what());
      } catch (const Error& w) {
        throw Error(std::string(e.what()) + "\n" + w.what());
      }
      throw Error(std::string(e.what()) + "\nthe last good state (step " + std::to_string(good.step) +
                  ") is in " + checkpoint.string() + ": continue from it with --restart " + checkpoint.string() +
                  " and a smaller --set time.safety=...");
    }
    const bool last = time_ >= scene.end_time - tiny;
    const bool field_row = field_every > 0 && (step_ % field_every == 0 || last);
    if (step_ % scene.history_every == 0 || last || field_row) write_outputs(field_row);
    progress.update(step_, time_, dt_, energy_error(), last);
    const int stop = last ? 0 : dec_->max(stop_signal());
    const auto now = std::chrono::steady_clock::now();
    const std::optional<CheckpointSpec>& every = scene.checkpoint;
    // Rank 0's clock decides for every rank.
    const bool due = every && ((every->every_steps > 0 && step_ % every->every_steps == 0) ||
                               dec_->max(root && every->every_seconds > 0 &&
                                         now - last_checkpoint >= std::chrono::duration<double>(every->every_seconds)));
    if (checkpoints && (due || stop) && !last) {
      save_state(good);
      save_checkpoint(checkpoint, good);
      last_checkpoint = now;
    }
    if (stop) {
      progress.finish();
      const std::string where = checkpoints ? "; continue with --restart " + checkpoint.string()
                                            : "; no checkpoint written (no output folder)";
      throw Error("stopped by signal " + std::to_string(stop) + " after step " + std::to_string(step_) + where);
    }
  }
  progress.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  fields_.reset();
  if (!opt_.out_dir.empty()) {
    const CrackArea crack = fracture_ ? write_fragments() : CrackArea{};
    const DecompositionStats stats = dec_->stats();
    const std::array<long, 3> pairs = contact_ ? contact_->owned_pairs_range() : std::array<long, 3>{};
    const std::pair<std::vector<long>, long> memory{dec_->gather(peak_memory_bytes()), dec_->max(loop_bytes())};
    if (root) write_summary(wall, stats, pairs, crack, memory);
  }
  return step_;
}

CrackArea Simulation::write_fragments() {
  // Each rank sums its owned nodes and elements, exactly; rank 0 adds the ranks' sums.
  Fragments frags = fracture_->fragment_labels();
  std::vector<ExactSum> sums = fragment_sums(model_.mesh, frags, dec_->owned_nodes(), dec_->owned_element_ids(), x_,
                                             v_, model_.mass);
  if (dec_->distributed()) reduce_to_root(sums, dec_->comm());
  if (dec_->rank() != 0) return {};
  set_fragment_stats(frags, sums);
  CsvWriter out(opt_.out_dir / "fragments.csv",
                {"id", "mass", "volume", "cx", "cy", "cz", "vx", "vy", "vz", "elements"});
  for (Index k = 0; k < frags.count(); ++k) {
    const FragmentStats& s = frags.stats[k];
    out << static_cast<long>(k) << s.mass << s.volume << s.centre.x() << s.centre.y() << s.centre.z()
        << s.velocity.x() << s.velocity.y() << s.velocity.z() << static_cast<long>(s.elements);
    out.end_row();
  }
  return fracture_->crack_area(frags);
}

long Simulation::loop_bytes() const {
  auto b = [](const auto& v) { return static_cast<long>(v.capacity() * sizeof(v[0])); };
  return static_cast<long>(model_bytes(model_)) + b(x_) + b(v_) + b(a_) + b(f_int_) + b(f_ext_) + b(inv_mass_) +
         b(bc_nodes_) + b(reaction_) + b(x_prev_) + b(contact_inv_mass_) + b(stress6_);
}

void Simulation::write_summary(double wall, const DecompositionStats& stats, std::array<long, 3> owned_pairs,
                               const CrackArea& crack, const std::pair<std::vector<long>, long>& memory) {
  const Ledger& l = ledger_;
  JsonObject j;
  j.add("name", model_.scene.name);
  j.add("scene", model_.scene.file);
  j.add("ranks", dec_->size());
  j.add("threads", opt_.threads);
  j.add("deterministic", std::string(opt_.deterministic ? "true" : "false"));
  j.add("steps", step_);
  j.add("end_time", time_);
  j.add("wall_time", wall);
  j.add("time_per_step", step_ > 0 ? wall / step_ : 0.0);
  j.add("element_loop_time", element_seconds_);
  // element-steps per second per core spent in the element loop
  j.add("element_updates_per_second",
        element_seconds_ > 0 ? double(dec_->local_elements().size()) * (step_ + 1) / (element_seconds_ * opt_.threads) : 0.0);
  j.add("peak_memory_bytes", peak_memory_bytes());
  j.add("peak_memory_bytes_per_rank", memory.first);
  j.add("model_bytes_per_rank_max", memory.second);
  // Decomposition (docs/parallel.md): balance and bytes per step.
  j.add("owned_elements_min", stats.owned_min);
  j.add("owned_elements_max", stats.owned_max);
  j.add("local_elements_max", stats.local_max);
  j.add("ghost_bytes_per_step_max", stats.ghost_bytes_max);
  j.add("ghost_messages_per_step_max", stats.ghost_messages_max);
  j.add("shared_surface_bytes_per_step", static_cast<long>(surface_nodes_ ? 72 * surface_nodes_->nodes.size() : 0));
  // The ledger's exact sums (update_ledger: 7 node terms, the strain energy, the step's work).
  j.add("reduction_bytes_per_step", static_cast<long>(dec_->distributed() ? Decomposition::sum_bytes(8 + kStepWorks) : 0));
  // The contact stage's exchanges included (contact_exchange_time).
  j.add("communication_time", comm_seconds_ + (contact_ ? contact_->profile().exchange_seconds : 0.0));
  j.add("nodes", static_cast<long>(model_.mesh.num_nodes()));
  j.add("elements", static_cast<long>(model_.mesh.num_elements()));
  j.add("element_order", model_.mesh.order);
  j.add("bodies", static_cast<long>(model_.scene.bodies.size()));
  j.add("kinetic", l.kinetic);
  j.add("strain", l.strain);
  j.add("cohesive_stored", l.cohesive_stored);
  j.add("cohesive_dissipated", l.cohesive_dissipated);
  j.add("contact_dissipated", l.contact_dissipated);
  j.add("external_work", l.external_work);
  j.add("total", l.total());
  j.add("initial_total", total0_);
  j.add("energy_error", energy_error());
  j.add("contacts", l.contacts);
  j.add("cohesive_elements", l.cohesive_elements);
  j.add("fragments", l.fragments);
  j.add("contact_capped_steps", l.contact_capped_steps);
  if (fracture_) {
    j.add("fracture_check_time", fracture_->check_seconds());
    // Cohesive elements between elements of different ranks: cracks across subdomains.
    long across = 0;
    for (Index f : fracture_->cohesive_facets()) {
      const auto& fe = fracture_->topology().facet_elem[f];
      across += dec_->granule_rank(fe[0] / ElementForces::kGranule) != dec_->granule_rank(fe[1] / ElementForces::kGranule);
    }
    j.add("cohesive_elements_across_ranks", across);
    j.add("crack_area_debonded", crack.debonded);
    j.add("crack_area_between_fragments", crack.between_fragments);
    j.add("cohesive_dissipated_debonded", crack.debonded_dissipated);
  }
  if (contact_) {
    j.add("contact_search_time", contact_->search_seconds());
    j.add("contact_searches", contact_->searches());
    j.add("contact_dcr_time", contact_->dcr_seconds());
    j.add("contact_surface_triangles", static_cast<long>(contact_->surface().num_triangles()));
    // The split of the two times above and the work per step (docs/scenes.md).
    const ContactProfile& cp = contact_->profile();
    const double steps = std::max(1L, cp.steps);
    j.add("contact_verlet_time", cp.verlet_seconds);
    j.add("contact_sweep_time", cp.sweep_seconds);
    j.add("contact_candidates_per_step", cp.candidates / steps);
    j.add("contact_pairs_per_step", owned_pairs[2] / steps);
    j.add("contact_detections_per_step", cp.detections / steps);
    j.add("contact_sweeps_per_step", cp.sweeps / steps);
    if (dec_->distributed()) {
      j.add("contact_pairs_per_step_rank_min", owned_pairs[0] / steps);
      j.add("contact_pairs_per_step_rank_max", owned_pairs[1] / steps);
      j.add("contact_exchange_time", cp.exchange_seconds);
      j.add("contact_exchange_bytes_per_step", cp.exchange_bytes / steps);
      j.add("contact_repartitions", cp.repartitions);
    }
  }
  j.write(opt_.out_dir / "summary.json");
}

}  // namespace shatter
