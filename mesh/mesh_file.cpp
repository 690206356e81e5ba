#include "mesh/mesh_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <filesystem>

#include "kernels/error.hpp"
#include "mesh/gmsh_convert.hpp"
#include "mesh/gmsh_model.hpp"

namespace shatter {
namespace {

void require_file(const std::string& path, const std::string& where) {
  if (!std::filesystem::is_regular_file(path))
    throw InputError(where + ": mesh file '" + path + "' does not exist or is not a file");
}

/// The order (1 or 2) of the one kind of tetrahedron among `types` (the
/// scan of `path`); InputError when there is none, two, or one of order > 2.
int tetrahedron_order(std::vector<MshElementType> types, const std::string& path, const std::string& where) {
  std::erase_if(types, [](const MshElementType& t) { return !t.tetrahedron; });
  if (types.empty()) throw InputError(where + ": '" + path + "' holds no tetrahedra (expected 4- or 10-node tets)");
  if (types.size() > 1)
    throw InputError(where + ": '" + path + "' mixes " + std::to_string(types[0].nodes) + "- and " +
                     std::to_string(types[1].nodes) + "-node tetrahedra (elements " +
                     std::to_string(types[0].first_tag) + " and " + std::to_string(types[1].first_tag) +
                     "); expected tetrahedra of one order, 4- or 10-node");
  if (types[0].type != 4 && types[0].type != 11)
    throw InputError(where + ": '" + path + "' holds " + std::to_string(types[0].nodes) +
                     "-node tetrahedra; expected 4- or 10-node tets");
  return types[0].type == 4 ? 1 : 2;
}

/// The tetrahedra of the model Gmsh holds, once the scan of its .msh form
/// has passed.
Mesh tetrahedra_of_model(int order, const std::string& path, const std::string& physical, int body, int material,
                         const std::string& where) {
  const std::vector<int> volumes = selected_volumes(physical, where);
  require_tetrahedra_only(volumes, path, physical, where);
  return model_tetrahedra(volumes, order, body, material, where);
}

/// A temporary file removed when it goes out of scope.
struct TemporaryFile {
  std::filesystem::path path;
  ~TemporaryFile() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
};

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

const std::vector<MeshFileFormat>& mesh_file_formats() {
  static const std::vector<MeshFileFormat> formats = {
      {".msh", "a .msh"},   {".unv", "an I-deas universal"}, {".vtk", "a legacy VTK"},
      {".mesh", "a Medit"}, {".bdf", "a Nastran bulk data"}, {".nas", "a Nastran bulk data"}};
  return formats;
}

namespace {

/// `path` opened by Gmsh in a child process that writes the model as a
/// binary .msh 4.1 (every element, one block per volume and element type);
/// that copy is then scanned and read here, with messages naming the user's
/// file. Gmsh 4.8's readers crash on some malformed files (.unv, .vtk, and
/// binary .msh: tests/fuzz/crashes/); in the child a crash is a refusal.
/// The copy is no cleaner than what Gmsh read: a node it made of memory it
/// read out of bounds is in it (tests/fuzz/crashes/msh/README.md), so the
/// scan runs on the copy too.
Mesh read_through_child(const std::string& path, const char* format, const std::string& physical, int body,
                        int material, const std::string& where, std::vector<PhysicalGroup>* groups) {
  GmshSession session;
  static std::atomic<unsigned> serial{0};
  const TemporaryFile copy{std::filesystem::temp_directory_path() /
                           ("shatter_mesh_" + std::to_string(getpid()) + "_" + std::to_string(serial++) + ".msh")};
  convert_to_msh_in_child(path, format, copy.path.string(), where);
  const int order = tetrahedron_order(scan_msh_elements(copy.path.string(), where, path), path, where);
  open_in_gmsh(copy.path.string(), "a .msh", where, path);
  Mesh mesh = tetrahedra_of_model(order, path, physical, body, material, where);
  if (groups) *groups = model_physical_groups();
  return mesh;
}

}  // namespace

Mesh read_msh(const std::string& path, const std::string& physical, int body, int material, const std::string& where,
              std::vector<PhysicalGroup>* groups) {
  require_file(path, where);
  // Which tetrahedra the file holds, from our own scan first: Gmsh 4.8 lists
  // a volume's tets by the type of its first one, overrunning its buffers
  // when the volume holds two orders (docs/errors.md), so such a file is
  // refused with that reason before Gmsh reads it.
  tetrahedron_order(scan_msh_elements(path, where), path, where);
  return read_through_child(path, "a .msh", physical, body, material, where, groups);
}

Mesh read_mesh_file(const std::string& path, const std::string& physical, int body, int material,
                    const std::string& where, std::vector<PhysicalGroup>* groups) {
  const std::string ext = lower_extension(path);
  if (ext == ".msh") return read_msh(path, physical, body, material, where, groups);
  const auto& formats = mesh_file_formats();
  const auto format =
      std::find_if(formats.begin(), formats.end(), [&](const MeshFileFormat& f) { return ext == f.extension; });
  if (format == formats.end()) {
    std::string list;
    for (const MeshFileFormat& f : formats) list += std::string(list.empty() ? "" : ", ") + f.extension;
    throw InputError(where + ": '" + path + "' is not of a volume mesh format shatter reads (extension '" + ext +
                     "'); expected one of " + list + " (docs/scenes.md, \"Mesh files\")");
  }
  require_file(path, where);
  return read_through_child(path, format->name, physical, body, material, where, groups);
}

}  // namespace shatter
