#include "runtime/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "kernels/drift.hpp"
#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/contact_stage.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/diagnosis.hpp"
#include "runtime/field_output.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/key_positions.hpp"
#include "runtime/model_part.hpp"
#include "runtime/loads.hpp"
#include "runtime/parallel.hpp"
#include "runtime/report.hpp"
#include "runtime/rigid_bodies.hpp"
#include "runtime/sort_unique.hpp"
#include "runtime/timed.hpp"

namespace shatter {

template <int K, class Term>
std::array<ExactSum, K> Simulation::granule_sums(Term term) const {
  return exact_sums<K>(static_cast<Index>(dec_->owned_granules().size()), [&](Index k, std::array<ExactSum, K>& sums) {
    std::array<double, K> partial{};
    for (Index i : dec_->home_nodes(k)) term(i, partial);
    for (int c = 0; c < K; ++c) sums[c] += partial[c];
  });
}

Simulation::Simulation(Model& model, RunOptions options)
    : model_(model),
      opt_(std::move(options)),
      dec_(std::make_unique<Decomposition>(model, opt_.ranks > 1 ? MPI_COMM_WORLD : MPI_COMM_SELF)),
      elements_(model) {
  const Mesh& mesh = model_.mesh;
  if (!model_.shells.empty()) shells_ = std::make_unique<ShellForces>(model_);
  model_fingerprint_ = whole_fingerprint(model_);
  if (dec_->distributed()) {
    // The ranks' models must be one: the CLI builds them from rank 0's mesh
    // (build_model on the world); a caller that meshed on every rank may not.
    std::uint64_t fp[2] = {model_fingerprint_, ~model_fingerprint_};
    MPI_Allreduce(MPI_IN_PLACE, fp, 2, MPI_UINT64_T, MPI_MAX, dec_->comm());
    if (fp[0] != ~fp[1])
      throw Error(model_.scene.file + ": the MPI ranks built different models from the scene (meshing differs "
                  "between processes)");
  }
  const Index n = mesh.num_nodes();
  model_nodes_ = model_.whole_nodes();
  x_ = mesh.reference;
  v_ = model_.initial_velocity;
  a_.assign(n, Vec3::Zero());
  f_int_.assign(n, Vec3::Zero());
  f_ext_.assign(n, Vec3::Zero());
  if (std::any_of(model_.scene.bodies.begin(), model_.scene.bodies.end(),
                  [](const BodySpec& b) { return b.has_rigid_state(); })) {
    rigid_ = std::make_unique<RigidBodies>(model_, *dec_);
    rigid_->place_nodes(x_, v_);
  }
  if (model_.scene.contact) {
    contact_ = std::make_unique<ContactStage>(model_, *model_.scene.contact, dec_.get());
    count_contact_vertices();
  }
  node_arrays_from_model();
  reaction_.assign(bc_nodes_.size(), Vec3::Zero());
  if (!model_.load_faces.empty()) loads_ = std::make_unique<SurfaceLoads>(model_);
  if (model_.scene.fracture_enabled()) {
    fracture_ = std::make_unique<FractureStage>(model_, *dec_);
    stress6_.resize(6 * static_cast<size_t>(model_.mesh.num_elements()));
  }
  ledger_.fragments = static_cast<long>(model_.scene.bodies.size());
  share_plans();
  compute_forces(0, 0.0);
  update_ledger();
  check_ledger();
  total0_ = ledger_.total();
  stable_dt0_ = stable_dt_;
  energy_scale_ = std::max(ledger_.kinetic + ledger_.strain, 1e-300);
  // Warnings are not progress: --quiet does not hide them (README, "Command line").
  if (model_.scene.fixed_dt && *model_.scene.fixed_dt > stable_dt_ && dec_->rank() == 0)
    std::fprintf(stderr, "warning: %s: time.dt = %.3e s is above the stable step %.3e s; the run may blow up\n",
                 model_.scene.file.c_str(), *model_.scene.fixed_dt, stable_dt_);
  if (fracture_)
    for (const std::string& w : fracture_->cohesive_zone_warnings())
      if (dec_->rank() == 0) std::fprintf(stderr, "%s\n", w.c_str());
}

Simulation::~Simulation() = default;

double Simulation::next_dt() {
  const double dt = model_.scene.fixed_dt ? *model_.scene.fixed_dt
                                          : step_control_.next(model_.scene.safety * stable_dt_);
  const double remaining = model_.scene.end_time - time_;
  // Land on end_time exactly, without a sliver of a last step.
  return remaining < 1.5 * dt && remaining > dt ? 0.5 * remaining : std::min(dt, remaining);
}

void Simulation::compute_forces(long step, double time, const std::function<void()>& between) {
  // `between` (the end of the ghost update) is timed as communication.
  const double comm_before = comm_seconds_;
  timed(element_seconds_, [&] {
    last_elements_ = elements_.compute(x_, f_int_, stress6_, between);
    if (shells_) last_shells_ = shells_->compute(x_, f_int_);
  });
  element_seconds_ -= comm_seconds_ - comm_before;
  // The cohesive elements' nodes are held here and current (the ghost update
  // brings them: Decomposition::rebuild_nodes' groups); update_ledger sums
  // their energies over the ranks.
  if (fracture_) cohesive_energy_ = fracture_->add_forces(x_, f_int_);
  // With cohesive elements the stable step also bounds their stiffness:
  // 2 / sqrt(omega_e^2 + lambda_c), both over the whole model.
  double dt_bound[2] = {std::min(last_elements_.stable_dt, last_shells_.stable_dt), fracture_ ? -fracture_->eigenvalue_bound(model_.mass) : 0.0};
  if (dec_->distributed()) {
    // With the bounds' minima, the worst element over all ranks (NaN first, then the
    // smallest det F, then the smallest index, as on one rank), by the whole model's
    // element index (a part's local ones differ): one message.
    constexpr long kNone = std::numeric_limits<int>::max();
    std::pair<double, long> worst{
        std::isnan(last_elements_.min_jacobian) ? -HUGE_VAL : last_elements_.min_jacobian,
        last_elements_.worst_element < 0 ? kNone : static_cast<long>(model_.whole_element(last_elements_.worst_element))};
    dec_->min(dt_bound, worst);
    last_elements_.min_jacobian = worst.first == -HUGE_VAL ? std::nan("") : worst.first;
    last_elements_.worst_element = worst.second == kNone ? -1 : static_cast<Index>(worst.second);
  }
  const double omega_e = 2.0 / dt_bound[0];
  stable_dt_ = fracture_ && fracture_->cohesive_count() > 0 ? 2.0 / std::sqrt(omega_e * omega_e - dt_bound[1])
                                                           : dt_bound[0];
  if (!(last_elements_.min_jacobian > 0)) {
    const double J = last_elements_.min_jacobian;
    // Its owner has its current positions, its id and body.
    const std::string where = from_owner(last_elements_.worst_element, [&](Index e) {
      Vec3 centre = Vec3::Zero();
      for (int a = 0; a < 4; ++a) centre += 0.25 * x_[model_.mesh.element(e)[a]];
      std::ostringstream os;
      os << "element " << model_.mesh.elem_gid[e] << " (body '" << model_.scene.bodies[model_.mesh.elem_body[e]].name
         << "') " << (std::isnan(J) ? "has NaN coordinates" : "is inverted") << " (det F = " << J << ") near ("
         << centre.x() << ", " << centre.y() << ", " << centre.z() << ")";
      return os.str();
    });
    std::ostringstream os;
    os << "step " << step << ", t = " << time << " s: " << where << "; try a smaller time.safety or a finer mesh";
    throw Error(os.str());
  }
  check_step_collapse(step, time);
  const Vec3 g = model_.scene.gravity;
  const Index n = model_.mesh.num_nodes();
  dec_->for_touched(n, [&](Index i) {
    f_ext_[i] = model_.mass[i] * g;
    a_[i] = inv_mass_[i] * (f_ext_[i] - f_int_[i]);
  });
  if (loads_) {
    loads_->compute(x_, time);
    for (size_t k = 0; k < loads_->nodes().size(); ++k) {
      const Index i = loads_->nodes()[k];
      f_ext_[i] += loads_->force()[k];
      a_[i] = inv_mass_[i] * (f_ext_[i] - f_int_[i]);
    }
  }
  // Prescribed components: no acceleration; the reaction here is the force that holds them
  // against the others (its inertial part, m a, is booked by its work in correct()).
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
  if (rigid_) rigid_->gather_forces(x_, loads_.get());
}

void Simulation::step() {
  if (opt_.before_step) opt_.before_step(step_ + 1);
  dt_ = next_dt();
  const std::vector<Vec3> reaction_old = reaction_;
  bc_v_old_.resize(bc_nodes_.size());
  for (size_t b = 0; b < bc_nodes_.size(); ++b) bc_v_old_[b] = v_[bc_nodes_[b]];
  predict();
  if (contact_) resolve_contact();
  // The ghost-only positions travel while the elements that do not read them
  // are computed (ElementForces::restrict_to).
  timed(comm_seconds_, [&] { dec_->begin_ghost_update(x_); });
  book_gravity_work();
  compute_forces(step_ + 1, time_ + dt_, [&] { timed(comm_seconds_, [&] { dec_->end_ghost_update(x_); }); });
  if (contact_) book_contact_work();
  if (loads_) {
    // The loads' work by the trapezoidal rule, W += (F(n) + F(n+1))/2 . (x(n+1) - x(n)).
    for (size_t k = 0; k < loads_->nodes().size(); ++k) {
      const Index i = loads_->nodes()[k];
      if (dec_->owns_node(i))
        step_work_[kLoadWork] += 0.5 * (load_force_old_[k] + loads_->force()[k]).dot(x_[i] - load_x_old_[k]);
    }
  }
  correct(reaction_old);
  time_ += dt_;
  ++step_;
  if (fracture_ && step_ % model_.scene.fracture_check_every == 0) apply_fracture();
  update_ledger();
  check_ledger();
}

template <class Then>
void Simulation::half_kick(bool predicting, Then then) {
  const double half = 0.5 * dt_, end = time_ + dt_;
  const std::vector<BoundaryConditionSpec>& conditions = model_.scene.boundary_conditions;
  bc_factor_.resize(conditions.size());
  for (size_t k = 0; k < conditions.size(); ++k) {
    const Amplitude& a = conditions[k].amplitude;
    bc_factor_[k] = conditions[k].displacement ? (predicting ? a.value(end) : a.rate(end))
                                               : a.value(predicting ? time_ + half : end);
  }
  dec_->for_touched(model_.mesh.num_nodes(), [&](Index i) {
    v_[i] += half * a_[i];
    if (model_.bc_mask[i])
      for (int c = 0; c < 3; ++c)
        if (model_.bc_mask[i] & (1u << c)) {
          const int k = model_.bc_condition[i][c];
          const double value = model_.bc_velocity[i][c] * bc_factor_[k];
          // A displacement is reached at the end of the step from x(n).
          v_[i][c] = predicting && conditions[k].displacement
                         ? (model_.mesh.reference[i][c] + value - x_[i][c]) / dt_
                         : value;
        }
    then(i);
  });
}

void Simulation::predict() {
  if (loads_) {
    load_x_old_.resize(loads_->nodes().size());
    for (size_t k = 0; k < load_x_old_.size(); ++k) load_x_old_[k] = x_[loads_->nodes()[k]];
    load_force_old_ = loads_->force();
  }
  // x(n) for contact: on one rank the pass below keeps it; on several, every node held here.
  const bool keep = contact_ && !dec_->distributed();
  if (keep) x_prev_.resize(x_.size());
  else if (contact_) x_prev_ = x_;
  // The kick and the drift in one pass over the nodes.
  half_kick(true, [&](Index i) {
    if (keep) x_prev_[i] = x_[i];
    x_[i] = drift(x_[i], dt_, v_[i]);
  });
  bc_dx_.resize(bc_nodes_.size());
  for (size_t b = 0; b < bc_nodes_.size(); ++b) bc_dx_[b] = dt_ * v_[bc_nodes_[b]];
  if (rigid_) {
    rigid_->predict(dt_, x_, v_);
    // A spinning prescribed body's nodes: their conditions hold the translation, the
    // displacement (for the reactions' work) is the body's.
    for (size_t b = 0; b < bc_nodes_.size(); ++b)
      if (rigid_->placed(bc_nodes_[b])) bc_dx_[b] = dt_ * v_[bc_nodes_[b]];
  }
}

void Simulation::resolve_contact() {
  // On several ranks the contact stage brings its patch's states from their owners.
  const std::vector<Index>& vertices = contact_vertices_;
  contact_dx_.resize(vertices.size());
  contact_dv_.resize(vertices.size());
  const auto count = static_cast<Index>(vertices.size());
  parallel_for_each(count, [&](Index k) { contact_dx_[k] = x_[vertices[k]], contact_dv_[k] = v_[vertices[k]]; });
  const DcrResult r =
      contact_->apply(x_prev_, x_, v_, inv_mass_, dt_, model_.bc_mask, rigid_ ? &rigid_->for_contact() : nullptr);
  if (rigid_) rigid_->apply_contact(r.rigid, dt_, x_, v_);
  parallel_for_each(count, [&](Index k) {
    contact_dx_[k] = x_[vertices[k]] - contact_dx_[k];
    contact_dv_[k] = v_[vertices[k]] - contact_dv_[k];
  });
  step_work_[kContactDissipated] += r.dissipated;
  step_work_[kSupportWork] += r.support_work;
  step_work_[kContactWork] += r.work;
  step_work_[kContactsResolved] += static_cast<double>(r.contacts);
  if (r.capped) {
    if (model_.scene.contact->sweep_cap_fatal)
      throw Error(sweep_cap_diagnosis(model_, contact_->unresolved(), step_ + 1, time_ + dt_));
    if (ledger_.contact_capped_steps == 0 && dec_->rank() == 0)
      std::fprintf(stderr,
                   "\nwarning: step %ld: DCR sweeps reached the cap (%d) with penetrations left; "
                   "counted in history.csv column contact_capped_steps\n",
                   step_ + 1, model_.scene.contact->max_sweeps);
    ++ledger_.contact_capped_steps;
  }
}

void Simulation::book_gravity_work() {
  // Gravity's work over the step's displacement (the projection's included).
  const Vec3 g = model_.scene.gravity;
  if (g.squaredNorm() == 0) return;
  step_work_[kGravityWork] += granule_sums<1>([&](Index i, std::array<double, 1>& w) {
    w[0] += model_.mass[i] * g.dot(contact_ ? Vec3(x_[i] - x_prev_[i]) : Vec3(dt_ * v_[i]));
  })[0];
}

void Simulation::book_contact_work() {
  // What the contact's changes dx of x(n+1) and dv of v(n+1/2) did to the central-difference
  // energy besides the impulses' kinetic-energy loss, to first order: -f(n+1) . (dx - dt/2 dv)
  // (docs/contact.md, "The ledger with e < 1"); booked as contact_work, whatever the law.
  const double half = 0.5 * dt_;
  const std::vector<Index>& vertices = contact_vertices_;
  step_work_[kContactWork] += exact_sums<1>(static_cast<Index>(vertices.size()), [&](Index k, std::array<ExactSum, 1>& w) {
    const Index i = vertices[k];
    if (contact_dx_[k] != Vec3::Zero() || contact_dv_[k] != Vec3::Zero())
      w[0] += (f_ext_[i] - f_int_[i]).dot(contact_dx_[k] - half * contact_dv_[k]);
  })[0];
}

void Simulation::correct(const std::vector<Vec3>& reaction_old) {
  half_kick(false, [](Index) {});
  if (rigid_) rigid_->correct(dt_, x_, v_);
  // The reactions' work. Their part f_int - f_ext (reaction_) by the
  // trapezoidal rule, W += (R(n) + R(n+1))/2 . dx; their inertial part m a,
  // which changes the prescribed components' velocities, did exactly the
  // change of those components' kinetic energy, 1/2 m (v(n+1)^2 - v(n)^2).
  for (size_t b = 0; b < bc_nodes_.size(); ++b) {
    const Index i = bc_nodes_[b];
    if (!dec_->owns_node(i)) continue;
    step_work_[kReactionWork] += 0.5 * (reaction_old[b] + reaction_[b]).dot(bc_dx_[b]);
    for (int c = 0; c < 3; ++c)
      if (model_.bc_mask[i] & (1u << c))
        step_work_[kReactionWork] += 0.5 * model_.mass[i] * (v_[i][c] * v_[i][c] - bc_v_old_[b][c] * bc_v_old_[b][c]);
  }
}

void Simulation::apply_fracture() {
  // A cohesive element is freed by its owner, which computes it; a facet is
  // checked by the owner of its smaller element, which holds both elements'
  // stresses. Each sends its lists (by facet global id) to the ranks around
  // it, every one of which frees and inserts the facets it holds; the
  // cohesive elements are numbered by their positions among all the ranks'
  // critical facets (key_positions), with no list of the whole model's.
  const std::vector<GlobalId> debonded = fracture_->gids(fracture_->debonded());
  Index freed = 0;
  std::vector<GlobalId> freed_here;
  timed(comm_seconds_, [&] {
    freed = static_cast<Index>(dec_->sum(std::vector<long>{static_cast<long>(debonded.size())})[0]);
    freed_here = dec_->share_with_neighbours(debonded);
  });
  fracture_->release(freed_here, freed);
  const std::vector<GlobalId> found =
      fracture_->gids(dec_->distributed() ? fracture_->check(x_, stress6_, dec_->local_elements(), dec_->owned_element_ids())
                                          : fracture_->check(x_, stress6_));
  std::vector<GlobalId> critical;
  KeyPositions numbers;
  timed(comm_seconds_, [&] {
    critical = dec_->share_with_neighbours(found);
    sort_unique(critical);
    numbers = key_positions(found, critical, *dec_);
  });
  const Index before = fracture_->cohesive_count();
  // Insertion is timed without the gather of the new nodes' names (communication).
  Insertion ins;
  const std::uint64_t revision = model_.mesh.revision;
  timed(insert_seconds_, insert_cpu_seconds_, [&] {
    ins = fracture_->insert(critical, numbers);
    if (!ins.new_nodes.empty()) grow_nodes(ins.new_nodes);
  });
  ledger_.cohesive_elements = fracture_->cohesive_count();
  if (ledger_.cohesive_elements == before) {
    // Freed facets' faces join the contact surface.
    if (contact_ && freed > 0) rebuild_contact_surface();
    return;
  }
  // On parts a rank may split nodes that others do not hold (every rank holding
  // one splits it alike): the whole model's count decides the forces' update.
  const auto here = static_cast<Index>(ins.new_nodes.size());
  Index created = here;
  if (model_.holds_two_layers())
    timed(comm_seconds_, [&] { created = number_split_nodes(model_, model_.mesh.num_nodes() - here, revision, *dec_); });
  timed(insert_seconds_, insert_cpu_seconds_, [&] {
    dec_->update_nodes(ins.changed_nodes(), fracture_->side_nodes(), kCohesiveSlots, ins.first_cohesive,
                       [&](Index n, std::vector<Index>& out) { fracture_->cohesive_around(n, out); });
    // After the node lists: the contact patch asks who owns the new nodes. Every rank
    // rebuilds (the whole model's counts decide): the re-partition that follows is collective.
    if (contact_ && (freed > 0 || created > 0)) rebuild_contact_surface();
    share_plans(&ins);
  });
  // The split nodes' masses and forces changed: recompute the accelerations
  // that the next half step uses (the velocities were copied, so momentum is
  // unchanged).
  if (created > 0) compute_forces(step_, time_);
}

void Simulation::rebuild_contact_surface() {
  // The faces of bonded cohesive facets stay out, and the nodes they join count as
  // one for the pairs: their compression penalty keeps them apart
  // (kernels/cohesive.hpp), and with DCR on the coincident faces and the edges of
  // the crack mouth too the two fought (the sweep cap reached).
  contact_->rebuild(model_.mesh, fracture_->bonded_faces(), fracture_->bonded_twins());
  count_contact_vertices();
}

void Simulation::count_contact_vertices() {
  contact_vertices_.clear();
  for (const Index i : contact_->surface_nodes())
    if (i >= 0 && dec_->owns_node(i)) contact_vertices_.push_back(i);
}

void Simulation::share_plans(const Insertion* after) {
  if (fracture_ && after) fracture_->share(*after);
  else if (fracture_) fracture_->share();
  if (!dec_->distributed()) return;
  elements_.restrict_to(dec_->local_elements(), dec_->held_nodes(), dec_->ghost_only_nodes());
  if (shells_) shells_->restrict_to(dec_->touched_nodes(), [&](Index n) { return dec_->owns_node(n); });
}

void Simulation::grow_nodes(const std::vector<std::array<Index, 2>>& new_nodes) {
  const Index n = model_.mesh.num_nodes();
  for (auto* a : {&x_, &v_, &a_, &f_int_, &f_ext_, &model_.bc_velocity, &model_.initial_velocity}) a->resize(n);
  model_.bc_mask.resize(n);
  model_.bc_condition.resize(n);
  model_.mass.resize(n);
  inv_mass_.resize(n);
  std::vector<Index> touched;
  for (const auto& [child, parent] : new_nodes) {
    x_[child] = x_[parent];
    v_[child] = v_[parent];
    model_.bc_mask[child] = model_.bc_mask[parent];
    model_.bc_velocity[child] = model_.bc_velocity[parent];
    model_.bc_condition[child] = model_.bc_condition[parent];
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
  for (Index i : touched) inv_mass_[i] = 1.0 / model_.mass[i];
  if (loads_) loads_->rebuild();
  if (rigid_) rigid_->grow(n);
}

void Simulation::node_arrays_from_model() {
  const Index n = model_.mesh.num_nodes();
  inv_mass_.resize(n);
  if (rigid_) rigid_->grow(n);
  bc_nodes_.clear();
  for (Index i = 0; i < n; ++i) {
    inv_mass_[i] = 1.0 / model_.mass[i];
    if (model_.bc_mask[i]) bc_nodes_.push_back(i);
  }
}

void Simulation::update_ledger() {
  // Per owned granule over its home nodes, exact over the granules, the
  // step's work, then over the ranks: the same bits for any decomposition
  // and thread count.
  constexpr int kKinetic = 0, kP = 1, kL = 4, kStrain = 7, kStored = 8, kDissipated = 9, kLocal = 10,
                kSums = kLocal + int{kStepWorks};
  static_assert(kSums == kLedgerSums);
  const std::array<ExactSum, kStrain> nodes = granule_sums<kStrain>([&](Index i, std::array<double, kStrain>& s) {
    const Vec3 p = model_.mass[i] * v_[i], L = x_[i].cross(p);
    s[kKinetic] += 0.5 * p.dot(v_[i]);
    for (int c = 0; c < 3; ++c) s[kP + c] += p[c], s[kL + c] += L[c];
  });
  std::array<ExactSum, kSums> t;
  std::copy(nodes.begin(), nodes.end(), t.begin());
  for (Index gr : dec_->owned_granules()) t[kStrain] += elements_.granule_energy(gr);
  t[kStrain] += last_shells_.strain_energy;
  t[kStored] = cohesive_energy_.stored;
  t[kDissipated] = cohesive_energy_.dissipated;
  std::copy(step_work_.begin(), step_work_.end(), t.begin() + kLocal);
  step_work_ = {};
  std::array<long, kLedgerMaxima> most{stop_signal()};
  timed(comm_seconds_, [&] { dec_->sum(t, most); });
  stop_ = static_cast<int>(most[0]);
  ledger_.kinetic = t[kKinetic].value();
  ledger_.momentum = Vec3(t[kP].value(), t[kP + 1].value(), t[kP + 2].value());
  ledger_.angular_momentum = Vec3(t[kL].value(), t[kL + 1].value(), t[kL + 2].value());
  ledger_.strain = t[kStrain].value();
  ledger_.cohesive_stored = t[kStored].value();
  ledger_.cohesive_dissipated = t[kDissipated].value();
  ledger_.external_work += t[kLocal + kGravityWork].value() + t[kLocal + kReactionWork].value() +
                           t[kLocal + kLoadWork].value() + t[kLocal + kSupportWork].value();
  ledger_.contact_work += t[kLocal + kContactWork].value();
  if (contact_) {
    ledger_.contact_dissipated += t[kLocal + kContactDissipated].value();
    ledger_.contacts = static_cast<long>(t[kLocal + kContactsResolved].value());
  }
  // Energy errors are relative to the largest energy the model has held.
  energy_scale_ = std::max(energy_scale_, ledger_.kinetic + ledger_.strain + ledger_.cohesive_stored +
                                              std::abs(ledger_.external_work));
}

}  // namespace shatter
