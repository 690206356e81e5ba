#pragma once
// Our own scan of a Gmsh .msh file's element types, run before Gmsh reads
// the file (why: docs/errors.md, "Files mixing tetrahedra of two orders").
#include <cstddef>
#include <string>
#include <vector>

namespace shatter {

/// One element type of a .msh file's $Elements sections.
struct MshElementType {
  int type = 0;               ///< Gmsh element type (4 = TET4, 11 = TET10, ...)
  int nodes = 0;              ///< nodes per element
  bool tetrahedron = false;   ///< a tetrahedron of any order
  std::size_t count = 0;      ///< elements of this type in the file
  std::size_t first_tag = 0;  ///< tag of the first one
};

/// The element types of a Gmsh .msh file, read by our own scan of its
/// $Elements sections, not by Gmsh (Gmsh 4.8 corrupts its heap on a volume
/// holding tetrahedra of two orders, docs/errors.md): formats 2.x and 4.1,
/// ASCII and binary (either byte order), sections walked as Gmsh walks them.
/// Types in order of first appearance. Throws InputError naming `where` and
/// the file (as `named`, or `path` when empty) when it is not a .msh file of
/// those formats, its sections are cut short or malformed, or an element
/// names a node tag outside 1..2^31-1 (Gmsh 4.8 reads out of bounds).
std::vector<MshElementType> scan_msh_elements(const std::string& path, const std::string& where,
                                              const std::string& named = "");

}  // namespace shatter
