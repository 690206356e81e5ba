// Fuzz entry for the checkpoint reader (issue 21): any bytes as the file of
// `shatter run --restart`, read by read_checkpoint against two models built
// once from the scenes below, without and with fracture (the seeds in
// seeds/checkpoint/ are checkpoints of these scenes, so mutations reach the
// state and /fracture datasets). The only acceptable failure is
// shatter::InputError, and a refused file must leave no HDF5 object open;
// anything else aborts. Built as a libFuzzer binary by the fuzz preset and
// as a replay test of the seeds and crashes in every build (replay_main.cpp,
// ctest label fuzz).
#include <hdf5.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "checkpoint_seed_scenes.hpp"

#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/model.hpp"
#include "runtime/scene.hpp"

namespace {


std::vector<shatter::Model>& models() {
  static std::vector<shatter::Model> m = [] {
    std::vector<shatter::Model> out;
    for (const char* text : shatter::test::kCheckpointSeedScenes) out.push_back(shatter::build_model(shatter::parse_scene(text, "fuzz_checkpoint.yaml")));
    return out;
  }();
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("shatter_fuzz_" + std::to_string(getpid()) + ".h5")).string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  for (const shatter::Model& model : models()) {
    try {
      shatter::read_checkpoint(path, model);
    } catch (const shatter::InputError&) {
    }
    if (H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL) != 0) {
      std::fprintf(stderr, "fuzz_checkpoint: read_checkpoint left HDF5 objects open\n");
      std::abort();
    }
  }
  std::filesystem::remove(path);
  return 0;
}
