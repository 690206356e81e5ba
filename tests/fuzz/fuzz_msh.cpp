// Fuzz entry for the Gmsh file reader (issue 8, "Hardening"): any bytes as a
// .msh file, read as a scene's mesh.file is (read_msh, then validate_mesh,
// both as runtime/model.cpp calls them). The only acceptable failure is
// shatter::InputError; any other exception escapes and aborts, and the
// sanitizers catch memory errors in our code. Built as a libFuzzer binary by
// the fuzz preset and as a replay test of the seeds and crashes in every
// build (replay_main.cpp, ctest label fuzz).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "kernels/error.hpp"
#include "mesh/gmsh_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // One file per process: Gmsh reads by path (and picks the format by the
  // .msh extension).
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("shatter_fuzz_" + std::to_string(getpid()) + ".msh")).string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  for (const char* physical : {"", "body"}) {
    try {
      const shatter::Mesh mesh = shatter::read_msh(path, physical, 0, 0, "fuzz.yaml: bodies[0].mesh");
      shatter::validate_mesh(mesh, "fuzz.yaml: bodies[0].mesh");
    } catch (const shatter::InputError&) {
    }
  }
  std::filesystem::remove(path);
  return 0;
}
