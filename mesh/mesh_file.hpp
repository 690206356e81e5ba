#pragma once
// Volume mesh files read through the Gmsh API, by extension: Gmsh .msh
// (formats 2.x and 4.1, scanned by us before Gmsh reads them) and the other
// volume mesh formats Gmsh 4.8 reads (docs/scenes.md "Mesh files").
#include <array>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"
#include "mesh/msh_scan.hpp"

namespace shatter {

/// A mesh file format shatter reads: its extension (lower case, with the
/// dot) and what it is, with its article ("an I-deas universal" file).
struct MeshFileFormat {
  const char* extension;
  const char* name;
};

/// A named physical group of a mesh file (points, curves, surfaces or
/// volumes): its nodes and, for a surface, its triangles' corners, by the
/// file's node tags (Mesh::node_gid of the mesh read with it).
struct PhysicalGroup {
  std::string name;
  int dim = 0;                                    ///< 0 points, 1 curves, 2 surfaces, 3 volumes
  std::vector<GlobalId> nodes;                    ///< every node of the group
  std::vector<std::array<GlobalId, 3>> triangles; ///< surfaces: each 3- or 6-node triangle's corners
};

/// The formats, .msh first.
const std::vector<MeshFileFormat>& mesh_file_formats();

/// Read the tetrahedra of a mesh file (all of them, or those of the physical
/// volume named `physical` when it is not empty) as TET4 or TET10; the
/// format is chosen by the extension (any case). A .msh file is read by
/// read_msh. Any other is opened by Gmsh, written by Gmsh to a temporary
/// binary .msh 4.1 file, and that file goes through the same checks as a
/// .msh (scan_msh_elements, then the checks of read_msh), messages naming the
/// user's file. Throws InputError naming `where`, the file and what was
/// expected. `groups` (when not null) receives the file's named physical
/// groups of every dimension.
Mesh read_mesh_file(const std::string& path, const std::string& physical, int body, int material,
                    const std::string& where, std::vector<PhysicalGroup>* groups = nullptr);

/// Read the tetrahedra of a Gmsh .msh file. The file is scanned first
/// (scan_msh_elements) and refused, before Gmsh reads it, when it holds
/// tetrahedra of more than one order; volumes holding other elements than
/// tetrahedra (prisms, hexahedra, pyramids) are refused, naming each kind's
/// count and physical volumes, never dropped.
Mesh read_msh(const std::string& path, const std::string& physical, int body, int material, const std::string& where,
              std::vector<PhysicalGroup>* groups = nullptr);

}  // namespace shatter
