#pragma once
// The Gmsh API's one global model, as the mesh readers use it: a session
// that serialises and resets it, a file opened into it, the tetrahedra
// taken out of it, and structured curves. Internal to shatter::mesh
// (gmsh_input.cpp, mesh_file.cpp, shell_gmsh.cpp) and its tests.
#include <mutex>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"
#include "mesh/mesh_file.hpp"

namespace shatter {

/// Exclusive use of the Gmsh model, cleared on entry and exit. Gmsh 4.8
/// reads nothing more after a failed open or meshing (every later file
/// comes out empty) until it is initialised again, so a session in which
/// Gmsh reported an error (its last error, which gmsh::clear() resets)
/// finalises Gmsh and the next one initialises it. A session left by our
/// own refusal, Gmsh having reported nothing, only clears the model: each
/// finalise and initialise keeps ~25 kB in Gmsh 4.8 (~80 kB under
/// AddressSanitizer; tests/fuzz/README.md, fuzz_msh run 5).
class GmshSession {
 public:
  GmshSession();
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  std::unique_lock<std::mutex> lock_;
};

/// Open a mesh file into the model (Gmsh picks the reader by extension).
/// A file Gmsh cannot read throws InputError naming `where`, the file, the
/// format it was read as (`format`, with its article: "a .msh") and Gmsh's last error;
/// `copy_of` (when not empty): `path` is Gmsh's own copy of that user's file,
/// and the message names the user's file.
void open_in_gmsh(const std::string& path, const std::string& format, const std::string& where,
                  const std::string& copy_of = "");

/// The volumes (3D entity tags) of the physical volume named `physical`, or
/// every volume when it is empty. InputError when no physical volume has
/// that name.
std::vector<int> selected_volumes(const std::string& physical, const std::string& where);

/// Refuse volumes that hold elements other than tetrahedra (hexahedra,
/// prisms, pyramids, ...): an InputError naming the file, each kind's count
/// and the physical volumes holding it. Counts come from Gmsh's per-family
/// sizes (preallocateElementsByType), which read no element's nodes.
void require_tetrahedra_only(const std::vector<int>& volumes, const std::string& path, const std::string& physical,
                             const std::string& where);

/// The tetrahedra of `order` (1: 4-node, 2: 10-node) in `volumes`, as a Mesh
/// whose nodes are renumbered densely in order of first use; ids are Gmsh's
/// tags. InputError when there are none.
Mesh model_tetrahedra(const std::vector<int>& volumes, int order, int body, int material, const std::string& where);

/// Make every curve of the model transfinite with round(length / size) + 1
/// nodes (at least 2), length its bounding box's largest side (straight
/// curves): structured meshes of transfinite surfaces and volumes.
void transfinite_curves(double size);

/// The named physical groups of the model, of every dimension (unnamed ones
/// are left out: a scene names its regions).
std::vector<PhysicalGroup> model_physical_groups();

}  // namespace shatter
