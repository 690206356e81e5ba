// Issue 21: corrupted checkpoints are refused with an InputError naming the
// file, never read as a state and never a crash. Deterministic corruptions
// (the fuzz target tests/fuzz/fuzz_checkpoint.cpp tries random ones):
// truncations, flipped bytes in the header (superblock) and in the data,
// and files spliced from two checkpoints of the same run.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <vector>

#include "fuzz/checkpoint_seed_scenes.hpp"
#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/fnv1a.hpp"
#include "runtime/model.hpp"
#include "runtime/simulation.hpp"
#include "scene_text.hpp"
#include "shatter_cli.hpp"

namespace fs = std::filesystem;
using namespace shatter;
using shatter::test::file_bytes;
using shatter::test::run_shatter;
using shatter::test::scratch_dir;

namespace {

const std::string kScene = test::steel_box_scene(
    "corrupt", "0.004", "    initial_velocity: [3, -1, 2]\n    angular_velocity: [200, 500, -300]\n");

struct Checkpoints {
  fs::path dir;
  std::string a, b;  ///< bytes of the checkpoints after 3 and 6 steps
  Model model;
};

Checkpoints& checkpoints() {
  static Checkpoints c = [] {
    // One folder per process: ctest runs each test of this file in its own.
    Checkpoints k{scratch_dir("checkpoint_corruption_" + std::to_string(getpid())), "", "",
                  build_model(test::scene_from_text("corrupt_" + std::to_string(getpid()), kScene))};
    Model model = build_model(k.model.scene);
    Simulation sim(model, {});
    for (int s = 1; s <= 6; ++s) {
      sim.step();
      if (s % 3 != 0) continue;
      SimulationState state;
      sim.save_state(state);
      const fs::path file = k.dir / ("step" + std::to_string(s) + ".h5");
      write_checkpoint(file, model, state);
      (s == 3 ? k.a : k.b) = file_bytes(file);
    }
    return k;
  }();
  return c;
}

/// "" when `bytes` load as a checkpoint of the model, else the refusal; fails
/// the test on any other exception or on HDF5 objects left open.
std::string refusal(const std::string& bytes, const std::string& what) {
  Checkpoints& c = checkpoints();
  const fs::path file = c.dir / "bad.h5";
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  std::string why;
  try {
    read_checkpoint(file, c.model);
  } catch (const InputError& e) {
    why = e.what();
    EXPECT_EQ(why.rfind("--restart " + file.string() + ": ", 0), 0u) << what << ": " << why;
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": not an InputError: " << e.what();
  }
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0) << what << ": HDF5 objects left open";
  return why;
}

haddr_t dataset_offset(const std::string& bytes, const char* name) {
  const fs::path file = checkpoints().dir / "probe.h5";
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
  const haddr_t at = H5Dget_offset(d);
  H5Dclose(d);
  H5Fclose(f);
  return at;
}


/// Writes `version` into the root attribute of the checkpoint `file`.
void set_version(const fs::path& file, std::int64_t version) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t root = H5Gopen2(f, "/", H5P_DEFAULT);
  const hid_t a = H5Aopen(root, "version", H5P_DEFAULT);
  EXPECT_GE(H5Awrite(a, H5T_NATIVE_INT64, &version), 0);
  H5Aclose(a);
  H5Gclose(root);
  H5Fclose(f);
}

/// Rewrites the hash of each dataset of /state of the checkpoint `file` as
/// format versions up to 6 computed it: FNV-1a of its bytes in order.
void hash_in_order(const fs::path& file) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t state = H5Gopen2(f, "/state", H5P_DEFAULT);
  for (const char* name : {"positions", "velocities", "accelerations", "internal_forces", "external_forces", "reactions"}) {
    const hid_t d = H5Dopen2(state, name, H5P_DEFAULT);
    const hid_t space = H5Dget_space(d);
    std::vector<double> values(static_cast<size_t>(H5Sget_simple_extent_npoints(space)));
    EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0) << name;
    const std::uint64_t h = fnv1a(values.data(), values.size() * sizeof(double));
    const hid_t a = H5Aopen(d, "fnv1a64", H5P_DEFAULT);
    EXPECT_GE(H5Awrite(a, H5T_NATIVE_UINT64, &h), 0) << name;
    H5Aclose(a);
    H5Sclose(space);
    H5Dclose(d);
  }
  H5Gclose(state);
  H5Fclose(f);
}

}  // namespace

TEST(CheckpointCorruption, TheTwoCheckpointsLoad) {
  EXPECT_EQ(refusal(checkpoints().a, "step 3"), "");
  EXPECT_EQ(refusal(checkpoints().b, "step 6"), "");
  ASSERT_EQ(checkpoints().a.size(), checkpoints().b.size());
}

TEST(CheckpointCorruption, TruncatedFilesAreRefused) {
  const std::string& a = checkpoints().a;
  for (std::size_t keep : {std::size_t(0), std::size_t(1), std::size_t(8), std::size_t(48), a.size() / 3,
                           a.size() / 2, a.size() - 100, a.size() - 1})
    EXPECT_NE(refusal(a.substr(0, keep), "kept " + std::to_string(keep)), "") << "kept " << keep;
}

TEST(CheckpointCorruption, FlippedHeaderBytesAreRefused) {
  // The superblock (signature, versions, addresses, checksum): every byte matters.
  const std::string& a = checkpoints().a;
  for (std::size_t at = 0; at < 48; ++at) {
    std::string bad = a;
    bad[at] ^= 0x01;
    EXPECT_NE(refusal(bad, "header byte " + std::to_string(at)), "") << "header byte " << at;
  }
}

TEST(CheckpointCorruption, FlippedDataBytesFailTheirHash) {
  const std::string& a = checkpoints().a;
  for (const char* name : {"/state/positions", "/state/velocities", "/state/accelerations", "/state/internal_forces"}) {
    const haddr_t at = dataset_offset(a, name);
    ASSERT_NE(at, HADDR_UNDEF) << name;
    for (std::size_t byte : {std::size_t(0), std::size_t(13), std::size_t(8 * 3 * 2 + 7)}) {
      std::string bad = a;
      bad[at + byte] ^= 0x40;
      const std::string why = refusal(bad, std::string(name) + " byte " + std::to_string(byte));
      EXPECT_NE(why.find(std::string("dataset ") + (std::strrchr(name, '/') + 1) + " fails its hash check"),
                std::string::npos)
          << why;
    }
  }
}

// Files made of the first part of one checkpoint and the rest of another are
// refused or are exactly one of the two (the cut in bytes they share): never
// a mixture of two states.
TEST(CheckpointCorruption, SplicedCheckpointsAreRefusedOrOneOfTheTwo) {
  const std::string &a = checkpoints().a, &b = checkpoints().b;
  const haddr_t v = dataset_offset(a, "/state/velocities");
  ASSERT_EQ(v, dataset_offset(b, "/state/velocities"));
  // Cut inside the velocities: half of one state, half of the other.
  EXPECT_NE(refusal(a.substr(0, v + 40) + b.substr(v + 40), "cut in the velocities").find("fails its hash check"),
            std::string::npos);
  int refused = 0;
  for (std::size_t cut = 0; cut < a.size(); cut += 97) {
    for (const auto& [first, second] : {std::pair{&a, &b}, std::pair{&b, &a}}) {
      const std::string spliced = first->substr(0, cut) + second->substr(cut);
      if (spliced == a || spliced == b) continue;
      EXPECT_NE(refusal(spliced, "cut at " + std::to_string(cut)), "") << "cut at " << cut;
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
}

// Through the binary: one line, exit 2, no HDF5 diagnostics.
TEST(CheckpointCorruption, BinaryRefusesWithOneLine) {
  Checkpoints& c = checkpoints();
  std::string bad = c.a;
  bad[dataset_offset(c.a, "/state/velocities") + 5] ^= 0x10;
  std::ofstream(c.dir / "bad.h5", std::ios::binary | std::ios::trunc) << bad;
  const std::string scene = test::write_scene("corrupt_binary", kScene);
  const auto r = run_shatter("run " + scene + " --quiet --out " + (c.dir / "out").string() + " --restart " +
                             (c.dir / "bad.h5").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(r.output, "error: --restart " + (c.dir / "bad.h5").string() +
                          ": dataset velocities fails its hash check (corrupted checkpoint)\n");
}

// A checkpoint of format version 2 (before the physics keys and the
// whole-file hash, the ledger's contact_work of version 4 and the row hashes
// of version 7) is still read, without those checks, its datasets' hashes
// checked as version 2 computed them.
TEST(CheckpointCorruption, VersionTwoIsReadWithoutThePhysicsCheck) {
  Checkpoints& c = checkpoints();
  const fs::path file = c.dir / "version2.h5";
  std::ofstream(file, std::ios::binary | std::ios::trunc) << c.a;
  {
    set_version(file, 2);
    hash_in_order(file);
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t root = H5Gopen2(f, "/", H5P_DEFAULT);
    for (const char* name : {"physics", "scene_fingerprint", "history_every", "state_fnv1a64"})
      EXPECT_GE(H5Adelete(root, name), 0) << name;
    const hid_t ledger = H5Gopen2(root, "ledger", H5P_DEFAULT);
    EXPECT_GE(H5Adelete(ledger, "contact_work"), 0) << "contact_work (version 4)";
    H5Gclose(ledger);
    H5Gclose(root);
    H5Fclose(f);
  }
  std::string softer = kScene;
  softer.replace(softer.find("youngs_modulus: 210.0e9"), 23, "youngs_modulus: 100.0e9");
  const Model model = build_model(test::scene_from_text("corrupt_v2_" + std::to_string(getpid()), softer));
  CheckpointRun run;
  run.history_every = -1;
  const SimulationState s = read_checkpoint(file, model, &run);
  EXPECT_EQ(s.step, 3);
  EXPECT_EQ(s.ledger.contact_work, 0.0) << "before version 4: not recorded, continues from 0";
  EXPECT_EQ(run.history_every, 0) << "not recorded in version 2";
  // Version 3 refuses the same scene.
  std::ofstream(file, std::ios::binary | std::ios::trunc) << c.a;
  EXPECT_THROW(read_checkpoint(file, model), InputError);
}

// A fracture state of format version 4 named its facets by their index in one
// rank's facet list: refused with the version named (the fuzz seed of the
// fracture scene, a version 5 file, is read; relabelled version 4, refused).
TEST(CheckpointCorruption, OldFractureStateIsRefused) {
  const fs::path seed = fs::path(SHATTER_SOURCE_DIR) / "tests" / "fuzz" / "seeds" / "checkpoint" / "fracture.h5";
  const Model model = build_model(parse_scene(test::kCheckpointSeedScenes[1], "fuzz_checkpoint.yaml"));
  const SimulationState s = read_checkpoint(seed, model);
  ASSERT_TRUE(s.fracture.has_value());
  EXPECT_GT(s.fracture->cohesive_facet_gid.size(), 0u);
  const fs::path file = checkpoints().dir / "version4_fracture.h5";
  fs::copy_file(seed, file, fs::copy_options::overwrite_existing);
  set_version(file, 4);
  try {
    read_checkpoint(file, model);
    ADD_FAILURE() << "a version 4 fracture state was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the fracture state is of format version 4 (facets by index)"),
              std::string::npos)
        << e.what();
  }
}

