#pragma once
// A mesh file of another format than .msh converted by Gmsh to a binary
// .msh 4.1 file, in a child process. Internal to shatter::mesh.
#include <string>

namespace shatter {

/// Gmsh 4.8's readers of other formats crash on some malformed files (the
/// .unv reader dereferences elements it never made: tests/fuzz/README.md),
/// and such files cannot be checked before Gmsh reads them without a
/// parser of our own. So a forked child opens `path` with Gmsh and writes
/// its model to `copy` (binary .msh 4.1, every element: Mesh.SaveAll), then
/// ends with _exit; the caller reads `copy` as a user's .msh. A child that
/// Gmsh crashes, or that cannot read the file, throws InputError naming
/// `where`, the file and its `format`; one that cannot write `copy` throws
/// Error. The caller holds a GmshSession (the child uses its model).
void convert_to_msh_in_child(const std::string& path, const std::string& format, const std::string& copy,
                             const std::string& where);

}  // namespace shatter
