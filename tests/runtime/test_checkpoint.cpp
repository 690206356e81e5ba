// Checkpoint and restart (runtime/checkpoint.hpp):
//   - N steps, checkpoint, a fresh Simulation restored from it, M more steps:
//     positions, velocities and ledger bitwise equal to N + M steps without a
//     stop (a free body with boundary conditions and gravity; a contact scene);
//     and a fragmenting ring with contact, checkpointed after cracks opened;
//   - truncated, byte-corrupted, other-scene and other-mesh checkpoints, and
//     a fracture state that does not match the scene, are refused with a
//     message naming the reason;
//   - a write that fails leaves the previous checkpoint intact;
//   - the binary: SIGTERM mid-run exits 1 and leaves a checkpoint, --restart
//     from it gives the history.csv and bodies.csv of a run never stopped; a
//     run that fails (inverted elements) leaves the last good state.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "checkpoint_failure.hpp"
#include "scene_text.hpp"
#include "shatter_cli.hpp"

using namespace shatter;
using shatter::test::Child;
using shatter::test::failure_attribute;
using shatter::test::finish;
using shatter::test::start_shatter;
using shatter::test::scene_from_text;
using shatter::test::write_scene;
namespace fs = std::filesystem;

namespace {

const std::string kMaterials =
    "materials:\n"
    "  steel: {model: neo_hookean, density: 7850, youngs_modulus: 210.0e9, poisson_ratio: 0.3}\n";

/// A spinning, stretching block, one face held in z, under gravity: every
/// part of the state (reactions, external work) is in play.
std::string free_scene(const std::string& name, const std::string& element_size = "0.004") {
  return "name: " + name + "\ntime: {end: 1.0}\n" + kMaterials +
         "bodies:\n"
         "  - name: b\n"
         "    material: steel\n"
         "    mesh: {shape: box, size: [0.02, 0.01, 0.01], element_size: " +
         element_size +
         "}\n"
         "    initial_velocity: [3, -1, 2]\n"
         "    angular_velocity: [200, 500, -300]\n"
         "    velocity_gradient: [[30, 5, 0], [0, -20, 8], [1, 0, 10]]\n"
         "boundary_conditions:\n"
         "  - {body: b, region: {box: [[-1, -1, -1], [1, 1, -0.004999]]}, velocity: [null, null, "
         "1.0]}\n"
         "gravity: [0, 0, -9.81]\n";
}

/// A block thrown onto a held plate with friction.
std::string contact_scene(const std::string& name) {
  return "name: " + name + "\ntime: {end: 1.0}\n" + kMaterials +
         "bodies:\n"
         "  - {name: plate, material: steel, mesh: {shape: box, size: [0.06, 0.03, 0.01], center: "
         "[0, 0, -0.005], "
         "element_size: 0.006}}\n"
         "  - {name: block, material: steel, mesh: {shape: box, size: [0.01, 0.01, 0.01], center: "
         "[0, 0, 0.005001], "
         "element_size: 0.005}, initial_velocity: [5, 0, -5]}\n"
         "boundary_conditions:\n"
         "  - {body: plate, region: {box: [[-1, -1, -1], [1, 1, -0.00999]]}, velocity: [0, 0, 0]}\n"
         "gravity: [0, 0, -9.81]\n"
         "contact: {friction: 0.3, restitution: 0.5}\n";
}

fs::path test_dir(const std::string& name) {
  const fs::path dir = fs::path(SHATTER_BINARY_DIR "/test_scratch") / "shatter_test_checkpoint" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

bool bitwise_equal(std::span<const Vec3> a, std::span<const Vec3> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

void expect_same_ledger(const Ledger& a, const Ledger& b) {
  EXPECT_EQ(a.kinetic, b.kinetic);
  EXPECT_EQ(a.strain, b.strain);
  EXPECT_EQ(a.cohesive_stored, b.cohesive_stored);
  EXPECT_EQ(a.cohesive_dissipated, b.cohesive_dissipated);
  EXPECT_EQ(a.contact_dissipated, b.contact_dissipated);
  EXPECT_EQ(a.contact_work, b.contact_work);
  EXPECT_EQ(a.external_work, b.external_work);
  EXPECT_TRUE(a.momentum == b.momentum);
  EXPECT_TRUE(a.angular_momentum == b.angular_momentum);
  EXPECT_EQ(a.contacts, b.contacts);
  EXPECT_EQ(a.cohesive_elements, b.cohesive_elements);
  EXPECT_EQ(a.fragments, b.fragments);
  EXPECT_EQ(a.contact_capped_steps, b.contact_capped_steps);
}

/// A ring (1 mm thick, 10 mm across) expanding at 2e4 /s: it cracks and
/// breaks into fragments (test_fracture_runs). Without contact: with a
/// contact block the crack faces keep DCR at its sweep cap, and the run is
/// too slow for a test.
std::string ring_scene(const std::string& name) {
  return "name: " + name +
         "\ntime: {end: 1.0}\n"
         "materials:\n"
         "  alu: {model: neo_hookean, density: 2750, youngs_modulus: 275.0e9, poisson_ratio: 0.3,\n"
         "        fracture: {strength: 300.0e6, energy: 100.0, beta: 1.0}}\n"
         "bodies:\n"
         "  - name: ring\n"
         "    material: alu\n"
         "    mesh: {shape: tube, inner_radius: 4.5e-3, outer_radius: 5.5e-3, length: 1.0e-3, "
         "element_size: 5.0e-4}\n"
         "    velocity_gradient: [[2.0e4, 0, 0], [0, 2.0e4, 0], [0, 0, 0]]\n";
}
constexpr int kRingCheckpointStep = 240, kRingMoreSteps = 160;

struct FractureProgress {
  long cohesive = 0, fragments = 0;
  Index nodes0 = 0, nodes = 0;
};

FractureProgress fracture_progress(const Simulation& sim, Index nodes0) {
  FractureProgress p;
  p.cohesive = sim.ledger().cohesive_elements;
  p.nodes0 = nodes0;
  p.nodes = sim.model().mesh.num_nodes();
  p.fragments = sim.fracture()->fragments(sim.positions(), sim.velocities(), sim.model().mass).count();
  return p;
}

/// N steps, checkpoint to a file, restore into a fresh model and Simulation,
/// M more steps; against N + M steps without a stop.
void expect_bitwise_continuation(const std::string& name, const std::string& yaml, int n, int m,
                                 long* contacts_seen = nullptr, FractureProgress* at_checkpoint = nullptr,
                                 FractureProgress* at_end = nullptr) {
  const Scene scene = scene_from_text(name, yaml);
  Model whole_model = build_model(scene);
  Simulation whole(whole_model, {});
  long contacts = 0;
  for (int s = 0; s < n + m; ++s) {
    whole.step();
    contacts = std::max(contacts, whole.ledger().contacts);
  }
  if (contacts_seen) *contacts_seen = contacts;

  const fs::path file = test_dir(name) / "checkpoint.h5";
  {
    Model first_model = build_model(scene);
    Simulation first(first_model, {});
    const Index nodes0 = first_model.mesh.num_nodes();
    for (int s = 0; s < n; ++s) first.step();
    if (at_checkpoint) *at_checkpoint = fracture_progress(first, nodes0);
    SimulationState state;
    first.save_state(state);
    write_checkpoint(file, first_model, state);
  }
  Model second_model = build_model(scene);
  const Index nodes0 = second_model.mesh.num_nodes();
  Simulation second(second_model, {});
  second.restore_state(read_checkpoint(file, second_model));
  EXPECT_EQ(second.steps(), n);
  for (int s = 0; s < m; ++s) second.step();

  EXPECT_EQ(second.steps(), whole.steps());
  EXPECT_EQ(second.time(), whole.time());
  EXPECT_EQ(second.dt(), whole.dt());
  EXPECT_EQ(second.stable_dt(), whole.stable_dt());
  EXPECT_EQ(second.energy_error(), whole.energy_error());
  EXPECT_TRUE(bitwise_equal(second.positions(), whole.positions()));
  EXPECT_TRUE(bitwise_equal(second.velocities(), whole.velocities()));
  EXPECT_TRUE(bitwise_equal(second.internal_forces(), whole.internal_forces()));
  expect_same_ledger(second.ledger(), whole.ledger());
  if (at_end) {
    *at_end = fracture_progress(second, nodes0);
    const Mesh &a = second.model().mesh, &b = whole.model().mesh;
    EXPECT_TRUE(a.conn == b.conn && a.node_gid == b.node_gid && a.node_body == b.node_body);
    EXPECT_TRUE(second.model().mass == whole.model().mass);
    EXPECT_EQ(at_end->fragments, fracture_progress(whole, nodes0).fragments);
  }
}

/// A checkpoint of `yaml` after `steps` steps, written to `file`.
void checkpoint_after(const std::string& name, const std::string& yaml, int steps,
                      const fs::path& file) {
  Model model = build_model(scene_from_text(name, yaml));
  Simulation sim(model, {});
  for (int s = 0; s < steps; ++s) sim.step();
  SimulationState state;
  sim.save_state(state);
  write_checkpoint(file, model, state);
}

/// The message of the InputError read_checkpoint throws, or "" when it loads.
std::string refusal(const fs::path& file, const Model& model) {
  try {
    read_checkpoint(file, model);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

long count_lines(const fs::path& p) {
  std::ifstream in(p);
  long n = 0;
  std::string line;
  while (std::getline(in, line)) ++n;
  return n;
}

}  // namespace

TEST(Checkpoint, RestoredRunIsBitwiseTheUninterruptedOne) {
  expect_bitwise_continuation("ckpt_free", free_scene("ckpt_free"), 37, 41);
}

TEST(Checkpoint, RestoredContactRunIsBitwiseTheUninterruptedOne) {
  long contacts = 0;
  expect_bitwise_continuation("ckpt_contact", contact_scene("ckpt_contact"), 60, 80, &contacts);
  EXPECT_GT(contacts, 0) << "the scene must be in contact after the checkpoint";
}

// A free rigid block, spinning, sliding onto the clamped plate under gravity: its state
// (centre, velocity, orientation, angular momentum, force, torque) is in the checkpoint.
TEST(Checkpoint, RestoredRigidBodyRunIsBitwiseTheUninterruptedOne) {
  std::string yaml = contact_scene("ckpt_rigid");
  const std::string block = "initial_velocity: [5, 0, -5]}";
  yaml.replace(yaml.find(block), block.size(), "initial_velocity: [5, 0, -5], rigid: free, angular_velocity: [0, 300, 100]}");
  long contacts = 0;
  expect_bitwise_continuation("ckpt_rigid", yaml, 60, 80, &contacts);
  EXPECT_GT(contacts, 0) << "the scene must be in contact after the checkpoint";
}

// The step controller's state (StepControl: the step held, its window) is part
// of the checkpoint, so a restarted run changes its step where the uninterrupted
// one does.
TEST(Checkpoint, StepControllerStateIsKept) {
  const std::string yaml = free_scene("ckpt_control");
  Model model = build_model(scene_from_text("ckpt_control", yaml));
  Simulation sim(model, {});
  for (int s = 0; s < 7; ++s) sim.step();
  SimulationState state;
  sim.save_state(state);
  ASSERT_GT(state.step_control.window_steps, 0);
  ASSERT_TRUE(std::isfinite(state.step_control.window_min));
  const fs::path file = test_dir("control") / "checkpoint.h5";
  write_checkpoint(file, model, state);
  const SimulationState back = read_checkpoint(file, model);
  EXPECT_EQ(back.step_control.dt, state.step_control.dt);
  EXPECT_EQ(back.step_control.window_min, state.step_control.window_min);
  EXPECT_EQ(back.step_control.window_steps, state.step_control.window_steps);
}

TEST(Checkpoint, TruncatedFileIsRefused) {
  const fs::path dir = test_dir("truncated");
  const fs::path good = dir / "checkpoint.h5", cut = dir / "cut.h5";
  checkpoint_after("ckpt_trunc", free_scene("ckpt_trunc"), 5, good);
  const std::string bytes = slurp(good);
  Model model = build_model(scene_from_text("ckpt_trunc", free_scene("ckpt_trunc")));
  for (double keep : {0.0, 0.3, 0.9, 0.999}) {
    std::ofstream(cut, std::ios::binary)
        << bytes.substr(0, static_cast<size_t>(keep * bytes.size()));
    const std::string why = refusal(cut, model);
    EXPECT_NE(why.find("--restart " + cut.string()), std::string::npos) << why;
    EXPECT_NE(why.find("corrupted"), std::string::npos) << "kept " << keep << ": " << why;
  }
}

// A flipped byte in the raw data fails the dataset hash; a flipped byte
// anywhere is either refused or leaves the state read unchanged (unused bytes).
TEST(Checkpoint, CorruptedBytesAreRefusedOrHarmless) {
  const fs::path dir = test_dir("corrupted");
  const fs::path good = dir / "checkpoint.h5", bad = dir / "bad.h5";
  checkpoint_after("ckpt_corrupt", free_scene("ckpt_corrupt"), 5, good);
  Model model = build_model(scene_from_text("ckpt_corrupt", free_scene("ckpt_corrupt")));
  const SimulationState ref = read_checkpoint(good, model);
  const std::string bytes = slurp(good);

  haddr_t velocity_offset = HADDR_UNDEF;
  {
    const hid_t f = H5Fopen(good.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const hid_t d = H5Dopen2(f, "/state/velocities", H5P_DEFAULT);
    velocity_offset = H5Dget_offset(d);
    H5Dclose(d);
    H5Fclose(f);
  }
  ASSERT_NE(velocity_offset, HADDR_UNDEF);
  std::string flipped = bytes;
  flipped[velocity_offset + 8 * 7 + 3] ^= 0x10;
  std::ofstream(bad, std::ios::binary) << flipped;
  const std::string why = refusal(bad, model);
  EXPECT_NE(why.find("velocities fails its hash check"), std::string::npos) << why;

  int refused = 0, harmless = 0;
  for (size_t at = 0; at < bytes.size(); at += 61) {
    flipped = bytes;
    flipped[at] ^= 0x5a;
    std::ofstream(bad, std::ios::binary | std::ios::trunc) << flipped;
    try {
      const SimulationState s = read_checkpoint(bad, model);
      ++harmless;
      EXPECT_EQ(s.step, ref.step) << "byte " << at;
      EXPECT_EQ(s.time, ref.time) << "byte " << at;
      EXPECT_EQ(s.dt, ref.dt) << "byte " << at;
      EXPECT_EQ(s.stable_dt, ref.stable_dt) << "byte " << at;
      EXPECT_EQ(s.step_control.dt, ref.step_control.dt) << "byte " << at;
      EXPECT_EQ(s.step_control.window_min, ref.step_control.window_min) << "byte " << at;
      EXPECT_EQ(s.step_control.window_steps, ref.step_control.window_steps) << "byte " << at;
      EXPECT_EQ(s.ledger.kinetic, ref.ledger.kinetic) << "byte " << at;
      EXPECT_EQ(s.ledger.external_work, ref.ledger.external_work) << "byte " << at;
      EXPECT_TRUE(bitwise_equal(s.x, ref.x) && bitwise_equal(s.v, ref.v) &&
                  bitwise_equal(s.a, ref.a) && bitwise_equal(s.reaction, ref.reaction))
          << "byte " << at;
    } catch (const InputError&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0)
      << "a refused file left HDF5 objects open";
  std::printf("flipped bytes: %d refused, %d harmless\n", refused, harmless);
}

TEST(Checkpoint, CheckpointOfAnotherModelIsRefused) {
  const fs::path file = test_dir("other") / "checkpoint.h5";
  checkpoint_after("ckpt_other", free_scene("ckpt_other"), 3, file);

  Model renamed = build_model(scene_from_text("ckpt_renamed", free_scene("ckpt_renamed")));
  EXPECT_NE(refusal(file, renamed).find("of scene 'ckpt_other', not of 'ckpt_renamed'"),
            std::string::npos)
      << refusal(file, renamed);

  // A changed physics key is named, with both values (physics_keys, scene_keys.hpp).
  Model finer = build_model(scene_from_text("ckpt_other", free_scene("ckpt_other", "0.003")));
  EXPECT_NE(refusal(file, finer).find("bodies[0].mesh.element_size is 0.004 in the checkpoint's scene and 0.003"),
            std::string::npos)
      << refusal(file, finer);

  std::string yaml = free_scene("ckpt_other");
  yaml.replace(yaml.find("density: 7850"), 13, "density: 7851");
  Model heavier = build_model(scene_from_text("ckpt_other", yaml));
  EXPECT_NE(refusal(file, heavier).find("materials.steel.density is 7850 in the checkpoint's scene and 7851"),
            std::string::npos)
      << refusal(file, heavier);

  // Young's modulus and gravity change neither the mesh nor the masses (the
  // model fingerprint): the physics keys find them.
  yaml = free_scene("ckpt_other");
  yaml.replace(yaml.find("youngs_modulus: 210.0e9"), 23, "youngs_modulus: 100.0e9");
  Model softer = build_model(scene_from_text("ckpt_other", yaml));
  EXPECT_NE(refusal(file, softer).find("materials.steel.youngs_modulus is 210000000000 in the checkpoint's scene "
                                       "and 100000000000"),
            std::string::npos)
      << refusal(file, softer);
  yaml = free_scene("ckpt_other");
  yaml.replace(yaml.find("gravity: [0, 0, -9.81]"), 22, "gravity: [0, 0, -1.62]");
  Model moon = build_model(scene_from_text("ckpt_other", yaml));
  EXPECT_NE(refusal(file, moon).find("gravity[2] is -9.81 in the checkpoint's scene and -1.62"), std::string::npos)
      << refusal(file, moon);

  // time.safety and time.end may change at a restart.
  yaml = free_scene("ckpt_other");
  yaml.replace(yaml.find("time: {end: 1.0}"), 16, "time: {end: 2.0, safety: 0.3}");
  Model safer = build_model(scene_from_text("ckpt_other", yaml));
  EXPECT_EQ(refusal(file, safer), "");

  EXPECT_NE(refusal(file.parent_path() / "missing.h5", safer).find("no such file"),
            std::string::npos);
}

// A checkpoint without a fracture state does not restart a scene with
// fracture (same mesh and masses: the model fingerprint alone would accept
// it; the physics keys name the fracture block).
TEST(Checkpoint, FractureStateMustMatchTheScene) {
  const fs::path file = test_dir("fracture") / "checkpoint.h5";
  checkpoint_after("ckpt_fracture", free_scene("ckpt_fracture"), 3, file);
  std::string yaml = free_scene("ckpt_fracture");
  yaml.replace(yaml.find("poisson_ratio: 0.3}"), 19,
               "poisson_ratio: 0.3, fracture: {strength: 1.0e9, energy: 1.0e4}}");
  Model model = build_model(scene_from_text("ckpt_fracture", yaml));
  const std::string why = refusal(file, model);
  EXPECT_NE(why.find("materials.steel.fracture.strength is (none) in the checkpoint's scene and 1000000000"),
            std::string::npos)
      << why;

  checkpoint_after("ckpt_fracture", yaml, 3, file);
  Model plain = build_model(scene_from_text("ckpt_fracture", free_scene("ckpt_fracture")));
  EXPECT_NE(refusal(file, plain).find("materials.steel.fracture.strength is 1000000000 in the checkpoint's scene "
                                      "and (none)"),
            std::string::npos)
      << refusal(file, plain);
}

// A fragmenting ring: checkpoint after nodes were split and cohesive
// elements inserted; the restored run goes on cracking (more insertions, more
// splits) bitwise as the run never stopped.
TEST(Checkpoint, RestoredFracturingRunIsBitwiseTheUninterruptedOne) {
  const std::string yaml = ring_scene("ckpt_ring");
  FractureProgress at_checkpoint, at_end;
  expect_bitwise_continuation("ckpt_ring", yaml, kRingCheckpointStep, kRingMoreSteps, nullptr, &at_checkpoint,
                              &at_end);
  EXPECT_GT(at_checkpoint.cohesive, 0) << "no crack before the checkpoint: move it later";
  EXPECT_GT(at_checkpoint.nodes, at_checkpoint.nodes0) << "no node split before the checkpoint: move it later";
  EXPECT_GT(at_end.cohesive, at_checkpoint.cohesive) << "no crack after the checkpoint: run longer";
  EXPECT_GT(at_end.nodes, at_checkpoint.nodes) << "no split after the checkpoint: run longer";
  EXPECT_GT(at_end.fragments, 1);
}

// The same ring with Weibull strength scatter (issue 19): the strengths are
// drawn again from the facet ids when the restored run builds its model, so
// it continues bitwise with nothing more in the checkpoint.
TEST(Checkpoint, RestoredFracturingRunWithWeibullScatterIsBitwiseTheUninterruptedOne) {
  std::string yaml = ring_scene("ckpt_ring_weibull");
  const std::string law = "beta: 1.0}";
  yaml.replace(yaml.find(law), law.size(), "beta: 1.0, scatter: {distribution: weibull, modulus: 6, seed: 2}}");
  FractureProgress at_checkpoint, at_end;
  expect_bitwise_continuation("ckpt_ring_weibull", yaml, kRingCheckpointStep, kRingMoreSteps, nullptr,
                              &at_checkpoint, &at_end);
  EXPECT_GT(at_checkpoint.cohesive, 0) << "no crack before the checkpoint: move it later";
  EXPECT_GT(at_end.cohesive, at_checkpoint.cohesive) << "no crack after the checkpoint: run longer";
}

/// A small brittle pellet (2 mm cube of 100 tets, glass-like, sigma_c = 50
/// MPa) thrown at `speed` m/s onto a held steel plate (1 um apart). At 20 m/s
/// it hits in step 3, cracks from step 5 while in contact, the crack faces
/// join the contact surface, and it breaks into pieces from step 18; at 200
/// m/s it cracks within 30 steps and breaks into ~100 pieces by step 50.
/// A cap of 20 DCR rounds keeps the tests fast and puts a capped step (the
/// 200 m/s impact's first) in the state too.
std::string pellet_scene(const std::string& name, const std::string& speed) {
  return "name: " + name + "\ntime: {end: 1.0}\n" + kMaterials +
         "  glass: {model: neo_hookean, density: 2500, youngs_modulus: 70.0e9,\n"
         "          poisson_ratio: 0.22, fracture: {strength: 50.0e6, energy: 20.0, beta: 1.0}}\n"
         "bodies:\n"
         "  - {name: plate, material: steel, mesh: {shape: box, size: [0.008, 0.008, 0.002],\n"
         "     center: [0, 0, -0.001], element_size: 0.002}}\n"
         "  - {name: pellet, material: glass, mesh: {shape: box, size: [0.002, 0.002, 0.002],\n"
         "     center: [0, 0, 0.001001], element_size: 0.001}, initial_velocity: [0, 0, -" +
         speed +
         "]}\n"
         "boundary_conditions:\n"
         "  - {body: plate, region: {box: [[-1, -1, -1], [1, 1, -0.00199]]}, velocity: [0, 0, 0]}\n"
         "contact: {max_sweeps: 20}\n";
}

// Fracture and contact together: checkpointed while the cracked pellet is in
// contact with the plate (nodes split, crack faces in the contact surface),
// the restored run goes on cracking and colliding bitwise as the run never
// stopped.
TEST(Checkpoint, RestoredFracturingContactRunIsBitwiseTheUninterruptedOne) {
  FractureProgress at_checkpoint, at_end;
  long contacts = 0;
  expect_bitwise_continuation("ckpt_pellet", pellet_scene("ckpt_pellet", "20"), 12, 18, &contacts,
                              &at_checkpoint, &at_end);
  EXPECT_GT(contacts, 0) << "the pellet must hit the plate";
  EXPECT_GT(at_checkpoint.cohesive, 0) << "no crack before the checkpoint: move it later";
  EXPECT_GT(at_checkpoint.nodes, at_checkpoint.nodes0)
      << "no node split before the checkpoint: move it later";
  EXPECT_GT(at_end.cohesive, at_checkpoint.cohesive) << "no crack after the checkpoint: run longer";
  EXPECT_GT(at_end.nodes, at_checkpoint.nodes) << "no split after the checkpoint: run longer";
}

// Cohesive elements freed after the checkpoint (the pieces separate, no new
// crack): the restored run takes the same steps. Until the cohesive stiffness
// bound of the stable step was cached by (cohesive elements, nodes, releases),
// a release left the uninterrupted run with the bound of before while the
// restored run computed it afresh, and the two took different steps (this
// scene with the default sweep cap, 60 + 60 steps: stable step 1.777e-8 s
// restored, 1.402e-8 s uninterrupted).
TEST(Checkpoint, RestoredRunWithReleasesAfterTheCheckpointIsBitwiseTheUninterruptedOne) {
  FractureProgress at_checkpoint, at_end;
  expect_bitwise_continuation("ckpt_pellet_fast", pellet_scene("ckpt_pellet_fast", "200"), 30, 30,
                              nullptr, &at_checkpoint, &at_end);
  EXPECT_GT(at_checkpoint.nodes, at_checkpoint.nodes0)
      << "no node split before the checkpoint: move it later";
  EXPECT_GT(at_end.fragments, at_checkpoint.fragments)
      << "no piece separated after the checkpoint: run longer";
}

// The run saves its state before every step into one SimulationState (the
// last good state of a failure), and lists the broken facets again only when
// a facet changed state since (FractureStage's facet stamp): the reused state
// holds, at every step, the lists a fresh one gets, through insertions and
// releases.
TEST(Checkpoint, ReusedStateListsTheBrokenFacetsOfAFreshOne) {
  const Scene scene = scene_from_text("reused_state", pellet_scene("reused_state", "200"));
  Model model = build_model(scene);
  Simulation sim(model, {});
  SimulationState reused;
  bool freed = false;
  for (int s = 0; s < 60; ++s) {
    sim.save_state(reused);
    SimulationState fresh;
    sim.save_state(fresh);
    ASSERT_TRUE(reused.fracture && fresh.fracture);
    EXPECT_EQ(reused.fracture->facet_gid, fresh.fracture->facet_gid) << "step " << s;
    EXPECT_EQ(reused.fracture->facet_state, fresh.fracture->facet_state) << "step " << s;
    EXPECT_EQ(reused.fracture->cohesive_facet_gid, fresh.fracture->cohesive_facet_gid) << "step " << s;
    freed = freed || std::count(fresh.fracture->facet_state.begin(), fresh.fracture->facet_state.end(),
                                FacetState::free) > 0;
    sim.step();
  }
  EXPECT_GT(sim.ledger().cohesive_elements, 0) << "no crack: the test saw no insertion";
  EXPECT_TRUE(freed) << "no facet freed: the test saw no release";
}

// A write that fails (here: the temporary file cannot be created) throws and
// leaves the previous checkpoint as it was.
TEST(Checkpoint, FailedWriteLeavesThePreviousCheckpoint) {
  const fs::path dir = test_dir("failed_write");
  const fs::path file = dir / "checkpoint.h5";
  checkpoint_after("ckpt_failed", free_scene("ckpt_failed"), 4, file);
  const std::string before = slurp(file);

  Model model = build_model(scene_from_text("ckpt_failed", free_scene("ckpt_failed")));
  Simulation sim(model, {});
  for (int s = 0; s < 9; ++s) sim.step();
  SimulationState state;
  sim.save_state(state);
  fs::create_directories(dir / "checkpoint.h5.tmp");  // blocks the temporary file
  EXPECT_THROW(write_checkpoint(file, model, state), Error);
  EXPECT_EQ(slurp(file), before);
  EXPECT_EQ(read_checkpoint(file, model).step, 4);

  // A stale temporary file from a crash is simply replaced by the next write.
  fs::remove_all(dir / "checkpoint.h5.tmp");
  std::ofstream(dir / "checkpoint.h5.tmp") << "half a checkpoint";
  write_checkpoint(file, model, state);
  EXPECT_EQ(read_checkpoint(file, model).step, 9);
  EXPECT_FALSE(fs::exists(dir / "checkpoint.h5.tmp"));
}

TEST(Checkpoint, TruncateRowsAfterKeepsRowsUpToTheStep) {
  const fs::path csv = test_dir("rows") / "history.csv";
  std::ofstream(csv) << "step,time\n0,0\n5,1\n10,2\n15,3\n20,4";  // the last row cut by a kill
  truncate_rows_after(csv, 10);
  EXPECT_EQ(slurp(csv), "step,time\n0,0\n5,1\n10,2\n");
}

namespace {

// The binary: SIGTERM or SIGKILL mid-run, --restart, and the same rows as a
// run never stopped. `yaml` has checkpoint.every_steps: `every`.
void expect_stopped_run_restarts_to_the_same_history(const std::string& name, const std::string& yaml,
                                                     long every) {
  const fs::path dir = test_dir(name);
  const std::string scene = write_scene(name, yaml);
  const fs::path whole = dir / "whole";
  const Child reference = start_shatter(
      {"run", scene, "--out", whole.string(), "--threads", "1", "--quiet"}, dir / "whole.log");
  ASSERT_EQ(finish(reference), 0) << slurp(dir / "whole.log");
  const long rows = count_lines(whole / "history.csv");
  ASSERT_GT(rows, 100);

  // SIGTERM: the run checkpoints and exits 1. SIGKILL (a crash): the periodic
  // checkpoint remains, and the rows written after it are dropped at the restart.
  for (const int sig : {SIGTERM, SIGKILL}) {
    const fs::path stopped = dir / ("stopped_" + std::to_string(sig));
    const fs::path log_file = dir / ("stopped_" + std::to_string(sig) + ".log");
    const Child run = start_shatter(
        {"run", scene, "--out", stopped.string(), "--threads", "1", "--quiet"}, log_file);
    const auto t0 = std::chrono::steady_clock::now();
    while (count_lines(stopped / "history.csv") < rows / 2 &&
           std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    kill(run.pid, sig);
    const int status = finish(run);
    const std::string log = slurp(log_file);
    if (sig == SIGTERM) {
      EXPECT_EQ(status, 1) << log;
      EXPECT_NE(log.find("stopped by signal " + std::to_string(SIGTERM)), std::string::npos) << log;
    } else {
      EXPECT_EQ(status, -1) << log;
    }
    ASSERT_TRUE(fs::exists(stopped / "checkpoint.h5")) << log;
    EXPECT_LT(count_lines(stopped / "history.csv"), rows)
        << "the signal came after the end; make the scene longer";
    Model model = build_model(load_scene(scene));
    const long step = read_checkpoint(stopped / "checkpoint.h5", model).step;
    EXPECT_GT(step, 0);
    if (sig == SIGKILL) {
      EXPECT_EQ(step % every, 0);
    }

    const fs::path again_log = dir / ("again_" + std::to_string(sig) + ".log");
    const Child again =
        start_shatter({"run", scene, "--restart", (stopped / "checkpoint.h5").string(), "--threads",
                       "2", "--quiet"},
                      again_log);
    ASSERT_EQ(finish(again), 0) << slurp(again_log);
    EXPECT_EQ(slurp(stopped / "history.csv"), slurp(whole / "history.csv")) << "signal " << sig;
    EXPECT_EQ(slurp(stopped / "bodies.csv"), slurp(whole / "bodies.csv")) << "signal " << sig;
    if (fs::exists(whole / "fragments.csv")) {
      EXPECT_EQ(slurp(stopped / "fragments.csv"), slurp(whole / "fragments.csv")) << "signal " << sig;
    }
    EXPECT_TRUE(fs::exists(stopped / ("restart_" + std::to_string(step)) / "fields.h5"));
  }
}

}  // namespace

TEST(CheckpointRun, StoppedThenRestartedRunGivesTheUninterruptedHistory) {
  expect_stopped_run_restarts_to_the_same_history(
      "ckpt_sigterm",
      "name: ckpt_sigterm\ntime: {end: 4.0e-5}\n" + kMaterials +
          "output: {every: 200, history_every: 3}\n"
          "bodies:\n"
          "  - {name: b, material: steel, mesh: {shape: box, size: [0.02, 0.01, 0.01], "
          "element_size: 0.0015}, initial_velocity: [1, 0, 0], angular_velocity: [0, 0, 300]}\n"
          "boundary_conditions:\n"
          "  - {body: b, region: {box: [[-1, -1, -1], [1, 1, -0.004999]]}, velocity: [null, null, "
          "0.5]}\n"
          "checkpoint: {every_steps: 40}\n",
      40);
}

// The same for a ring that cracks and fragments while it runs.
TEST(CheckpointRun, StoppedThenRestartedFracturingRunGivesTheUninterruptedHistory) {
  std::string yaml = ring_scene("ckpt_ring_run");
  yaml.replace(yaml.find("time: {end: 1.0}"), 16, "time: {end: 1.5e-6}\noutput: {every: 100, history_every: 2}");
  expect_stopped_run_restarts_to_the_same_history("ckpt_ring_run", yaml + "checkpoint: {every_steps: 25}\n", 25);
}

TEST(CheckpointRun, RestartOfAnotherSceneExitsTwo) {
  const fs::path dir = test_dir("restart_other");
  const std::string scene = write_scene("ckpt_cli_other", free_scene("ckpt_cli_other"));
  checkpoint_after("ckpt_cli_source", free_scene("ckpt_cli_source"), 2, dir / "checkpoint.h5");
  const Child c = start_shatter(
      {"run", scene, "--restart", (dir / "checkpoint.h5").string(), "--quiet"}, dir / "log");
  EXPECT_EQ(finish(c), 2);
  EXPECT_NE(slurp(dir / "log").find("of scene 'ckpt_cli_source'"), std::string::npos)
      << slurp(dir / "log");
}

// A time step far above the stable one inverts elements: exit 1, and the
// checkpoint holds the last good state with the error.
TEST(CheckpointRun, FailedRunLeavesTheLastGoodState) {
  const fs::path dir = test_dir("failure");
  const std::string yaml =
      "name: ckpt_blowup\ntime: {end: 1.0e-3, dt: 2.0e-6}\n" + kMaterials +
      "output: {every: 0}\n"
      "bodies:\n"
      "  - {name: b, material: steel, mesh: {shape: box, size: [0.01, 0.01, 0.01], "
      "element_size: 0.005}, velocity_gradient: [[100, 0, 0], [0, 0, 0], [0, 0, 0]]}\n";
  const std::string scene = write_scene("ckpt_blowup", yaml);
  const Child c = start_shatter({"run", scene, "--out", dir.string(), "--threads", "1", "--quiet"},
                                dir / "log");
  EXPECT_EQ(finish(c), 1);
  const std::string log = slurp(dir / "log");
  EXPECT_NE(log.find("the last good state (step "), std::string::npos) << log;
  Model model = build_model(load_scene(scene));
  const SimulationState s = read_checkpoint(dir / "checkpoint.h5", model);
  // The history's last row is the checkpoint's step: the failing step wrote nothing.
  std::ifstream in(dir / "history.csv");
  std::string line, last_row;
  while (std::getline(in, line)) last_row = line;
  EXPECT_EQ(std::stol(last_row.substr(0, last_row.find(','))), s.step) << log;
  EXPECT_NE(log.find("step " + std::to_string(s.step + 1) + ", t = "), std::string::npos) << log;
  EXPECT_NE(log.find("is inverted"), std::string::npos) << log;
  for (const Vec3& x : s.x) EXPECT_TRUE(x.allFinite());
}

// Fatal conditions of SCENE.md / issue 8 (docs/errors.md "During a run"):
// each writes the last good state with the error in attribute `failure`,
// names what, where and the step, and run() throws Error (exit 1).
namespace {

/// Runs a restored `sim` with outputs in `dir` (a restart appends to the
/// history files, so they must exist; no fields: this test runs without
/// MPI); returns the Error's message ("" if none).
std::string failure_of(Simulation& sim, const fs::path& dir) {
  for (const char* csv : {"history.csv", "bodies.csv"}) std::ofstream(dir / csv) << "step,time\n";
  try {
    sim.run();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// A velocity that is NaN reaches the positions within the step: the element
// check names the element, its body and where it is.
TEST(FatalCondition, NanVelocityStopsWithACheckpointNamingTheElement) {
  const fs::path dir = test_dir("fatal_nan");
  Model model = build_model(scene_from_text("fatal_nan", free_scene("fatal_nan") + "output: {every: 0}\n"));
  Simulation sim(model, {.out_dir = dir, .quiet = true});
  for (int s = 0; s < 5; ++s) sim.step();
  SimulationState state;
  sim.save_state(state);
  state.v[7] = Vec3(std::nan(""), 0, 0);
  sim.restore_state(state);
  const std::string why = failure_of(sim, dir);
  EXPECT_NE(why.find("step 6, t = "), std::string::npos) << why;
  EXPECT_NE(why.find("has NaN coordinates"), std::string::npos) << why;
  EXPECT_NE(why.find("body 'b'"), std::string::npos) << why;
  EXPECT_NE(why.find("the last good state (step 5)"), std::string::npos) << why;
  const SimulationState saved = read_checkpoint(dir / "checkpoint.h5", model);
  EXPECT_EQ(saved.step, 5);
  EXPECT_NE(failure_attribute(dir / "checkpoint.h5").find("has NaN coordinates"), std::string::npos);
}

// A NaN that reaches only the ledger (here a boundary reaction, which enters
// the external work) is found at the end of its step, before it is saved as
// a good state.
TEST(FatalCondition, NonFiniteLedgerStopsAtTheEndOfItsStep) {
  const fs::path dir = test_dir("fatal_ledger");
  Model model = build_model(scene_from_text("fatal_ledger", free_scene("fatal_ledger") + "output: {every: 0}\n"));
  Simulation sim(model, {.out_dir = dir, .quiet = true});
  for (int s = 0; s < 3; ++s) sim.step();
  SimulationState state;
  sim.save_state(state);
  ASSERT_FALSE(state.reaction.empty());
  state.reaction[0] = Vec3(0, 0, std::nan(""));
  sim.restore_state(state);
  const std::string why = failure_of(sim, dir);
  EXPECT_NE(why.find("step 4, "), std::string::npos) << why;
  EXPECT_NE(why.find("the energy ledger is not finite"), std::string::npos) << why;
  EXPECT_NE(why.find("external work nan"), std::string::npos) << why;
  EXPECT_EQ(read_checkpoint(dir / "checkpoint.h5", model).step, 3);
}

// contact.on_sweep_cap: fail with a cap of one sweep: the first impact stops
// the binary with exit 1, a diagnosis naming the pair and where, and the
// checkpoint of the step before; the history ends at that step.
namespace {

/// The contact scene to 20 us with contact.max_sweeps: 1 and `more` contact
/// keys, run by the binary with --quiet into test_dir(name).
struct CappedRun {
  std::string scene;
  fs::path dir;
  int status = -1;
  std::string log;
};
CappedRun run_capped_contact(const std::string& name, const std::string& more) {
  CappedRun r;
  r.dir = test_dir(name);
  std::string yaml = contact_scene(name);
  yaml.replace(yaml.find("time: {end: 1.0}"), 16, "time: {end: 2.0e-5}\noutput: {every: 0}");
  yaml.replace(yaml.find("restitution: 0.5}"), 17, "restitution: 0.5, max_sweeps: 1" + more + "}");
  r.scene = write_scene(name, yaml);
  const Child c = start_shatter({"run", r.scene, "--out", r.dir.string(), "--threads", "1", "--quiet"}, r.dir / "log");
  r.status = finish(c);
  r.log = slurp(r.dir / "log");
  return r;
}

}  // namespace

TEST(FatalCondition, SweepCapDeclaredFatalStopsTheRun) {
  const CappedRun r = run_capped_contact("fatal_sweeps", ", on_sweep_cap: fail");
  const fs::path& dir = r.dir;
  const std::string& log = r.log;
  const std::string& scene = r.scene;
  EXPECT_EQ(r.status, 1);
  for (const char* part : {"DCR sweeps reached the cap (contact.max_sweeps = 1)", "still penetrating: ",
                           "pair of nodes", "('block')", "('plate')", " near (", "the last good state (step "})
    EXPECT_NE(log.find(part), std::string::npos) << part << "\n" << log;
  Model model = build_model(load_scene(scene));
  const SimulationState s = read_checkpoint(dir / "checkpoint.h5", model);
  EXPECT_NE(log.find("step " + std::to_string(s.step + 1) + ", t = "), std::string::npos) << log;
  std::ifstream in(dir / "history.csv");
  std::string line, last_row;
  while (std::getline(in, line)) last_row = line;
  EXPECT_EQ(std::stol(last_row.substr(0, last_row.find(','))), s.step) << log;
  EXPECT_NE(failure_attribute(dir / "checkpoint.h5").find("DCR sweeps reached the cap"), std::string::npos);
}

// With contact.on_sweep_cap: warn (the default), the capped step's warning is
// printed under --quiet too: --quiet hides progress, not warnings (README).
TEST(FatalCondition, SweepCapWarningIsPrintedUnderQuiet) {
  const CappedRun r = run_capped_contact("warn_sweeps", "");
  const std::string& log = r.log;
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(log.find("warning: step "), std::string::npos) << log;
  EXPECT_NE(log.find(": DCR sweeps reached the cap (1) with penetrations left"), std::string::npos) << log;
  EXPECT_EQ(log.find("done:"), std::string::npos) << log;
}
