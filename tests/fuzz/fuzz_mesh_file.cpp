// Fuzz entry for mesh files of the formats other than .msh (docs/scenes.md
// "Mesh files"): the first byte picks the format (u .unv, v .vtk, m .mesh,
// b .bdf, n .nas; any other byte by its value mod 5), the rest is the file,
// read as a scene's mesh.file is (read_mesh_file, then validate_mesh). The
// only acceptable failure is shatter::InputError, as for fuzz_msh.cpp.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "kernels/error.hpp"
#include "mesh/mesh_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[5] = {".unv", ".vtk", ".mesh", ".bdf", ".nas"};
  static const char kLetters[] = "uvmbn";
  const char* pick = data[0] ? std::strchr(kLetters, data[0]) : nullptr;
  const int format = pick ? int(pick - kLetters) : data[0] % 5;
  // One file per process and format: Gmsh reads by path and picks the
  // reader by the extension.
  const std::string path =
      (std::filesystem::temp_directory_path() / ("shatter_fuzz_" + std::to_string(getpid()) + kExtensions[format]))
          .string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    const shatter::Mesh mesh = shatter::read_mesh_file(path, "", 0, 0, "fuzz.yaml: bodies[0].mesh");
    shatter::validate_mesh(mesh, "fuzz.yaml: bodies[0].mesh");
  } catch (const shatter::InputError&) {
  }
  std::filesystem::remove(path);
  return 0;
}
