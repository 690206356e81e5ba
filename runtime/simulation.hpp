#pragma once
// The time loop (DESIGN.md "The physics, one time step"): central difference
// with lumped mass in velocity-Verlet form, which allows the step to change
// from one step to the next:
//   1. v(n+1/2) = v(n) + dt/2 a(n);  x(n+1) = x(n) + dt v(n+1/2)
//   2. contact (when the scene has a contact block)
//   3. f_int(x(n+1)) from the elements; f_ext = m g + reactions
//   4. a(n+1) = M^-1 (f_ext - f_int);  v(n+1) = v(n+1/2) + dt/2 a(n+1)
//   5. fracture (when a material has a fracture block)
//   6. ledger, output, progress
// Simulation::step() is these stages in order (predict, resolve_contact,
// compute_forces, correct, apply_fracture, update_ledger). Its members live
// in one file per purpose: simulation.cpp (the step and its stages),
// simulation_state.cpp (the state between steps, checkpoints),
// simulation_output.cpp (history, bodies, fields, fragments, summary) and
// simulation_run.cpp (run(): the loop, progress, checkpoints, failures).
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "runtime/element_forces.hpp"
#include "kernels/exact_sum.hpp"
#include "kernels/rigid_body.hpp"
#include "runtime/fracture_stage.hpp"
#include "runtime/ledger.hpp"
#include "runtime/shell_forces.hpp"
#include "runtime/model.hpp"
#include "runtime/step_control.hpp"

namespace shatter {

class FieldWriter;
class FailureChannel;
class CsvWriter;
class ContactStage;
class SurfaceLoads;
class RigidBodies;
class Decomposition;
struct DecompositionStats;
struct ContactBalance;

struct RunOptions {
  std::filesystem::path out_dir;  ///< empty: write no files (tests)
  int threads = 1;
  int ranks = 1;
  bool quiet = false;  ///< no progress line (warnings are printed all the same)
  bool deterministic = false;
  /// Several ranks: the ranks agree through it whether a failed step failed on
  /// every rank (then the last good state is checkpointed) or on this one
  /// alone (then it cannot be, runtime/failure.hpp). Null: every failure is
  /// taken as collective.
  FailureChannel* failures = nullptr;
  /// Called on every rank before each step with the number of the step to
  /// come (null: nothing); what it throws fails the step as the step would
  /// (tests inject failures with it: tests/mpi/fail_alone.cpp).
  std::function<void(long)> before_step = nullptr;
};

/// The complete state of a run between two steps: what a checkpoint holds
/// (runtime/checkpoint.hpp). Per-node arrays [n] in the model's node order
/// (with fracture, n counts the split copies); reaction [b] per node with a
/// prescribed component, in node order.
struct SimulationState {
  long step = 0;
  double time = 0, dt = 0;    ///< s: time reached, length of the last step
  double stable_dt = 0;       ///< s: stable step of this state, without the safety factor
  StepControl step_control;   ///< the adaptive step's controller
  std::vector<Vec3> x, v, a;  ///< positions m, velocities m/s, accelerations m/s^2
  std::vector<Vec3> f_int, f_ext, reaction;  ///< N
  Ledger ledger;
  double total0 = 0, energy_scale = 0;  ///< J: energy_error()'s reference
  std::optional<FractureState> fracture;  ///< scenes with fracture: the mesh after splits, cohesive elements
  std::vector<RigidBodyState> rigid;      ///< the free rigid bodies (RigidBodies), in body order
  /// The model as built, before fracture changed its mesh: model_fingerprint()
  /// and node count, by which a checkpoint names its model.
  std::uint64_t model_fingerprint = 0;
  long model_nodes = 0;
};

class Simulation {
 public:
  /// A step collapse: the stable step below this fraction of the initial
  /// state's (issue 21; a prescribed velocity that crushes a body took the
  /// step down 5 orders of magnitude, and the run crawled without a word).
  static constexpr double kStepCollapse = 1e-3;
  /// An energy overflow: an energy term of the ledger beyond this, J (issue
  /// 21; E = 1e308 ran into a strain energy of 5e284 J without a word). No
  /// scene of solids holds 1e100 J (the Sun's binding energy is 7e41 J).
  static constexpr double kEnergyOverflow = 1e100;

  Simulation(Model& model, RunOptions options);
  ~Simulation();

  /// Advance one step.
  void step();
  /// Run to scene.end_time with outputs and progress; returns the number of steps.
  long run();

  const Ledger& ledger() const { return ledger_; }
  /// (total - initial total) / (largest kinetic + strain + stored + |external work| so far).
  double energy_error() const { return (ledger_.total() - total0_) / energy_scale_; }
  double time() const { return time_; }
  double dt() const { return dt_; }
  long steps() const { return step_; }
  /// Stable step of the current configuration times the scene's safety factor, s.
  double stable_dt() const { return model_.scene.safety * stable_dt_; }
  std::span<const Vec3> positions() const { return x_; }
  std::span<const Vec3> velocities() const { return v_; }
  std::span<const Vec3> internal_forces() const { return f_int_; }
  const Model& model() const { return model_; }
  double element_loop_seconds() const { return element_seconds_; }
  const ContactStage* contact() const { return contact_.get(); }
  const FractureStage* fracture() const { return fracture_.get(); }
  const Decomposition& decomposition() const { return *dec_; }

  /// Copies the state between two steps into `state` (reusing its storage).
  void save_state(SimulationState& state) const;
  /// Continues from `state` (of this model; on a part of the model, the
  /// part's rows, as read_checkpoint gives them): the next
  /// step() is the one the saved run would have taken, bitwise, and run()
  /// appends to the outputs in opt.out_dir (checkpoint.hpp). Throws Error when
  /// the array sizes do not match the model.
  void restore_state(const SimulationState& state);

 private:
  // The stages of step(), in order.
  /// v += dt/2 a on the touched nodes, prescribed components set: at the
  /// mid step (`predicting`: a velocity times its amplitude there, or the
  /// velocity that reaches a displacement times its amplitude at the end of
  /// the step) or at the end (a velocity, or a displacement's rate, there).
  /// then(i) runs on each node after its kick, in the same pass.
  template <class Then>
  void half_kick(bool predicting, Then then);
  /// half_kick, then x(n+1) = x(n) + dt v(n+1/2); keeps x(n) for contact and
  /// the prescribed nodes' displacements for the reactions' work.
  void predict();
  /// DCR on x(n) -> x(n+1) (contact scenes).
  void resolve_contact();
  /// Gravity's work over the step, on the owned nodes.
  void book_gravity_work();
  /// The contact's first-order work (Ledger::contact_work), on the owned contact vertices.
  void book_contact_work();
  /// v(n+1) = v(n+1/2) + dt/2 a(n+1); the reactions' work over the step.
  void correct(const std::vector<Vec3>& reaction_old);
  /// Forces and accelerations at x_; `step` and `time` (of the configuration
  /// x_) name it when an element is inverted. `between` goes to
  /// ElementForces::compute: it completes the ghost-only positions.
  void compute_forces(long step, double time, const std::function<void()>& between = {});
  void update_ledger();
  /// A stable step below kStepCollapse of the initial one (stable_dt0_)
  /// throws Error naming the element that sets it, where it is and the likely
  /// cause (simulation_checks.cpp): the run would crawl without end.
  void check_step_collapse(long step, double time);
  /// what(e) on the owner of the whole model's element `whole` (e: its local
  /// index there), on every rank (collective); "" for whole < 0.
  std::string from_owner(Index whole, const std::function<std::string(Index)>& what) const;
  /// An energy term not finite or beyond kEnergyOverflow throws Error naming
  /// the terms and a node (simulation_checks.cpp); in the initial state
  /// (step 0) it is bad input, InputError.
  void check_ledger();
  /// K sums over this rank's owned nodes of term(node, partial), each owned
  /// granule's home nodes added in plain double in node order, the granules'
  /// partial sums exactly (any thread split gives the same bits; a node costs
  /// K double additions, the exact ones are per granule).
  template <int K, class Term>
  std::array<ExactSum, K> granule_sums(Term term) const;
  void write_outputs(bool fields);
  /// What the summary says of fracture, over the ranks.
  struct FractureSummary {
    CrackArea crack;              ///< the crack surface at the end (write_fragments)
    long across_ranks = 0;        ///< FractureStage::across_ranks
    double check_cpu_max = 0, insert_cpu_max = 0;  ///< the largest rank's thread CPU time, s
    long owned_min = 0, owned_max = 0;  ///< cohesive elements a rank owns, fewest and most
  };
  /// `memory`: peak_memory_bytes_per_rank (rank order) and model_bytes_per_rank_max;
  /// `shell`: shell elements owned per rank (fewest, most) and computed per rank (most).
  void write_summary(double wall_seconds, const DecompositionStats& stats, const ContactBalance& contact_balance,
                     const FractureSummary& fracture, const std::pair<std::vector<long>, long>& memory,
                     const std::array<long, 3>& shell);
  /// Bytes of the arrays this rank holds in the loop: the model's and the
  /// time loop's own (nodal state, stresses); the contact and fracture
  /// stages' are not counted.
  long loop_bytes() const;
  /// Writes `s` (this rank's copy of the state, completed from the owners on
  /// several ranks) to `path` from rank 0; collective; throws Error on every
  /// rank when the write fails.
  void save_checkpoint(const std::filesystem::path& path, SimulationState& s, const std::string& reason = "");
  /// restore_state's step, time, controller and ledger.
  void restore_scalars(const SimulationState& s);
  /// The step to take next: time.dt, or the step controller's; shortened to land on time.end.
  double next_dt();

  /// The step's terms, exact sums over this rank's owned nodes and pairs, summed
  /// over the ranks by update_ledger: gravity's work, the reactions' work, the
  /// contact's f(n+1) . (dx - dt/2 dv) (Ledger::contact_work), the loads' work,
  /// and DCR's dissipation, supports' work and number of pairs resolved.
  enum StepWork {
    kGravityWork,
    kReactionWork,
    kContactWork,
    kLoadWork,
    kContactDissipated,
    kSupportWork,
    kContactsResolved,
    kStepWorks
  };
  /// Accumulators of update_ledger's one reduction per step: kinetic energy,
  /// momentum (3), angular momentum (3), strain, cohesive stored and
  /// dissipated, and the step's works.
  static constexpr int kLedgerSums = 10 + kStepWorks;
  /// Maxima in the same message: the stop signal (run() reads it after the step).
  static constexpr int kLedgerMaxima = 1;

  Model& model_;
  RunOptions opt_;
  std::unique_ptr<Decomposition> dec_;
  ElementForces elements_;
  std::array<ExactSum, kStepWorks> step_work_;  ///< since the last update_ledger(), this rank's part
  /// After a topology change on several ranks: restrict the element loop to
  /// the local elements, renew the plans of the shared nodes; `after`: the
  /// insertion that changed it, if any (the cohesive elements are then shared
  /// again only around it).
  void share_plans(const Insertion* after = nullptr);
  /// The contact surface of the cracked mesh, without the bonded cohesive facets' faces.
  void rebuild_contact_surface();
  /// contact_vertices_ from the surface and the node ownership.
  void count_contact_vertices();
  std::vector<Vec3> x_, v_, a_, f_int_, f_ext_;
  std::vector<double> inv_mass_;
  std::vector<Index> bc_nodes_;        ///< nodes with a prescribed component
  std::vector<Vec3> reaction_;         ///< per bc node: reaction force at the last evaluation, N
  std::vector<Vec3> bc_dx_;            ///< per bc node: its displacement over the step under way, m
  std::vector<Vec3> bc_v_old_;         ///< per bc node: its velocity at the start of the step under way, m/s
  std::vector<double> bc_factor_;      ///< per boundary condition: its values' factor at the half step under way
  std::unique_ptr<SurfaceLoads> loads_;  ///< null without loads
  std::unique_ptr<RigidBodies> rigid_;   ///< null without free rigid bodies
  std::vector<Vec3> load_x_old_, load_force_old_;  ///< per loaded node: x(n) and its load at x(n), for the work
  double time_ = 0, dt_ = 0, stable_dt_ = 0;
  StepControl step_control_;
  long step_ = 0;
  Ledger ledger_;
  int stop_ = 0;  ///< the largest stop signal any rank had at the last update_ledger()
  ElementLoopResult last_elements_;
  std::unique_ptr<ShellForces> shells_;  ///< null without shell bodies
  ShellLoopResult last_shells_;
  double element_seconds_ = 0;
  double comm_seconds_ = 0;  ///< in MPI exchanges of the step (ghosts, shared nodes, granule sums)
  double checkpoint_seconds_ = 0;  ///< writing periodic and stop checkpoints (wall, every rank takes part)
  /// inserting cohesive elements (splits, numbering, node lists): wall and thread CPU time
  double insert_seconds_ = 0, insert_cpu_seconds_ = 0;
  double total0_ = 0, energy_scale_ = 0;
  std::unique_ptr<ContactStage> contact_;   ///< null without a contact block
  std::vector<Vec3> x_prev_;                ///< x(n) during a step (contact only)
  std::vector<Index> contact_vertices_;  ///< the contact surface's vertices this rank owns (owns_node)
  std::vector<Vec3> contact_dx_,
      contact_dv_;  ///< per contact_vertices_: the step's contact change of x(n+1), v(n+1/2)
  std::unique_ptr<FractureStage> fracture_;  ///< null without a fracture block
  std::vector<double> stress6_;             ///< per element Cauchy stress for the facet check (fracture only)
  CohesiveEnergy cohesive_energy_;          ///< of the cohesive elements owned here, at the last forces
  std::unique_ptr<FieldWriter> fields_;
  std::unique_ptr<CsvWriter> history_, bodies_;
  double stable_dt0_ = 0;  ///< stable step of the initial state (sets the default field interval)
  bool restored_ = false;  ///< restore_state() was called: run() continues the outputs
  std::uint64_t model_fingerprint_ = 0;  ///< of the model as built (SimulationState::model_fingerprint)
  long model_nodes_ = 0;
  void apply_fracture();
  void grow_nodes(const std::vector<std::array<Index, 2>>& new_nodes);
  void node_arrays_from_model();
  /// Writes fragments.csv from rank 0 (collective); returns the crack surface
  /// between those fragments on rank 0, zeros elsewhere.
  CrackArea write_fragments();
  /// A field frame, written collectively: each rank sends its owned nodes' and
  /// elements' rows to its block of the global order (row_blocks.hpp).
  /// `elem_fragment`: fragment ids per element (fracture; empty otherwise).
  void write_fields(std::span<const Index> elem_fragment);
};

}  // namespace shatter
