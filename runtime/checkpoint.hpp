#pragma once
// Checkpoint and restart (SCENE.md "checkpoint:", DESIGN.md "Inputs and
// outputs"): the complete state of a run between two steps in one HDF5 file,
// written atomically, read back into a Simulation of the same model so that
// the continued run is bitwise the run that was never stopped.
//
// Layout of checkpoint.h5 (n = nodes now, with fracture's split copies;
// b = nodes with a prescribed component,
// in the order of Model::bc_mask; file format "latest", so every object header
// carries the HDF5 metadata checksum):
//   /  attributes
//       format        string "shatter-checkpoint"
//       version       int64 7 (6: each dataset's fnv1a64 the FNV-1a of its
//                     bytes in order, still read, by a part block by block
//                     over the whole dataset;
//                     5: without free rigid bodies, refused with them;
//                     4: /fracture's facets by index, refused with
//                     fracture; 3: without the ledger's contact_work; 2: without
//                     physics, scene_fingerprint and history_every, read without
//                     the physics check; 1: before the step controller, refused)
//       scene         string, Scene::name
//       nodes         int64, nodes of the model as built (before fracture)
//       elements      int64
//       order         int64, 1 = TET4, 2 = TET10
//       fingerprint   uint64, model_fingerprint() of the model as built
//       step          int64, steps done
//       time, dt      float64, s: time reached, length of the last step
//       stable_dt     float64, s: stable step of the state, no safety factor
//       control_dt, control_window_min   float64, s; control_window_steps
//                     int64: the step controller's state (StepControl,
//                     simulation.hpp)
//       total0, energy_scale   float64, J: Simulation::energy_error() reference
//       failure       string: empty, or the error that stopped the run one
//                     step after this (good) state
//       physics       string: physics_keys() of the scene (scene_keys.hpp),
//                     "key.path=value" lines; a restart names the first key
//                     that differs
//       scene_fingerprint  uint64: FNV-1a of the physics text
//       history_every int64: output.history_every of the run, by which a
//                     restart knows which rows history.csv must hold
//       state_fnv1a64 uint64, written last: the sum over every other
//                     attribute of the file (all groups, the datasets'
//                     fnv1a64 included) of FNV-1a(name, value); a file spliced
//                     from two checkpoints, each part passing its own hashes,
//                     fails it
//   /state/positions, velocities, accelerations, internal_forces,
//          external_forces      n x 3 float64 (m, m/s, m/s^2, N, N)
//   /state/reactions            b x 3 float64, N
//   /state/rigid_bodies         only with rigid bodies that have a state (free ones, and
//       prescribed ones that spin: BodySpec::has_rigid_state): 10 rows x 3 float64 per
//       body, in body order (RigidBodyState): (mass kg, 0, 0), principal moments kg m^2,
//       centre m, velocity m/s, the orientation's three columns, angular momentum
//       kg m^2/s, force N, torque N m (a prescribed body: moments 1 and L = omega)
//       each dataset has attribute fnv1a64 (uint64): the sum (mod 2^64) over
//       its rows r (0, 1, ...) of FNV-1a of the row's bytes (little-endian, as
//       stored) seeded with FNV-1a of r as a uint64, so a flipped byte in the raw
//       data, or a row moved, is found too; each rank hashes the rows it writes
//       or owns at a restart, and the sums are added over the ranks
//
// Written collectively (MPI-IO) by every rank of a run, each its own rows
// (a node's: the smallest rank touching it; an element's and a cohesive
// element's: their owners'), moved to contiguous blocks (row_blocks.hpp) in
// the whole model's order: the file is the same for any number of ranks.
//   /ledger  attributes: the Ledger fields by their history.csv names
//       (float64 kinetic ... external_work, px py pz, Lx Ly Lz; int64 contacts,
//       cohesive_elements, fragments, contact_capped_steps)
//
//   /fracture  only for scenes with fracture (FractureState, fracture_stage.hpp);
//       attributes nodes (n), facets (f: the interior facets that are not
//       intact), cohesive_elements (c), mesh_revision;
//       datasets, each with fnv1a64 like /state's:
//       reference n x 3, node_gid n (int64), node_body n (int32),
//       conn e x k (int32), mass n, bc_mask n (uint8), bc_velocity n x 3, bc_condition n x 3 (int32),
//       initial_velocity n x 3, facet_gid f (int64: Topology::facet_gid,
//       ascending), facet_state f (uint8: 1 cohesive, 2 free),
//       cohesive_facet c (int64: facet gid), cohesive_side_local c x 12 (int8),
//       cohesive_side_nodes c x 12 (int32), cohesive_area c, cohesive_normal
//       c x 3, cohesive_delta_max c x 3 (m)
//
// Contact needs nothing more: its surface is rebuilt from the mesh and its
// pair lists are filtered to a fresh search's every step.
#include <mpi.h>

#include <cstdint>
#include <filesystem>
#include <vector>
#include <string>

#include "runtime/model.hpp"
#include "runtime/simulation.hpp"

namespace shatter {

/// FNV-1a hash over what fixes the answer of a model besides its scene
/// name: reference coordinates, connectivity, lumped masses, prescribed
/// velocities and their masks. Scene keys that do not change the model
/// (time.safety, time.end, output, checkpoint) may differ at a restart.
std::uint64_t model_fingerprint(const Model& model);
/// model_fingerprint() of the whole model (a part carries it, Model::Part).
std::uint64_t whole_fingerprint(const Model& model);

/// The rows of a checkpoint that one rank writes, as local indices ascending
/// in the whole model's order: `nodes` of the state's and the fracture
/// state's node arrays, `elements` of the fracture state's conn, `cohesive`
/// of its cohesive elements (and their facets). Over the ranks of `comm`,
/// every row of the whole model once (its owner's).
struct CheckpointRows {
  MPI_Comm comm = MPI_COMM_SELF;
  std::vector<Index> nodes, elements, cohesive;
};
/// Every row of `state`, a whole model's (one rank).
CheckpointRows all_rows(const Model& model, const SimulationState& state);

/// Writes `state` (from Simulation::save_state) of a run of `model` to `path` atomically: `path`.tmp is
/// written, flushed and fsync'ed, then renamed over `path` (and the folder
/// fsync'ed), so `path` is always either the previous checkpoint or this one.
/// `failure`: empty, or the message of the error the step after `state` threw.
/// `rows`: null for the whole state of one rank; else this rank's rows, and
/// every rank of rows->comm calls this together (the file is written
/// collectively through MPI-IO, each rank its own rows; no rank holds a
/// whole-model array). Throws shatter::Error naming the path when HDF5 or the
/// file system fails on any rank, the same on every rank; `path` is then untouched.
void write_checkpoint(const std::filesystem::path& path, const Model& model, const SimulationState& state,
                      const std::string& failure = "", const CheckpointRows* rows = nullptr);

/// Reads a checkpoint of `model` written by write_checkpoint. Throws
/// InputError naming the path and the reason when the file is missing,
/// truncated or corrupted (HDF5 or hash check), of another scene or model
/// (name, counts, fingerprint), or has a fracture state exactly when the
/// scene has no fracture.
/// Also refuses a scene whose physics (physics_keys(): materials, bodies,
/// boundary conditions, contact, gravity, ...) differs from the checkpoint's,
/// naming the first key that differs. `run`, when given, receives what the
/// checkpoint says of the run that wrote it. A part of the model
/// (Model::is_part) gets its own nodes' rows and reactions and reads only
/// those (version 7), every rank of `comm` together: each hashes the rows it
/// is the owner of, the sums are added over the ranks and checked, and any
/// rank's refusal is every rank's (the same message). The whole state is never
/// in a rank's memory.
struct CheckpointRun {
  long history_every = 0;  ///< output.history_every of that run; 0: not recorded (version 2)
};
SimulationState read_checkpoint(const std::filesystem::path& path, const Model& model,
                                CheckpointRun* run = nullptr, MPI_Comm comm = MPI_COMM_WORLD);

/// Removes the rows of a CSV file whose first column (step) is above `step`,
/// so that a restarted run appends its rows to it without duplicating any.
/// Throws InputError when the file is missing or has no header.
void truncate_rows_after(const std::filesystem::path& csv, long step);

/// Installs handlers for SIGINT and SIGTERM that only record the signal (the
/// time loop checkpoints and stops after the current step); a second signal of
/// the same kind gets the default action (ends the process at once).
void install_stop_handlers();

/// The signal received since install_stop_handlers(), or 0.
int stop_signal();

}  // namespace shatter
