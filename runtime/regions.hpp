#pragma once
// Regions of a body that boundary conditions and loads act on (scene key
// `region`, docs/scenes.md "Regions"): a box of reference coordinates, a
// named physical group of the body's .msh file, or a named face of a
// primitive shape. Resolved once, on the whole model's mesh, before it is cut
// into parts.
#include <string>
#include <vector>

#include "mesh/gmsh_input.hpp"
#include "mesh/mesh.hpp"
#include "mesh/mesh_file.hpp"

namespace shatter {

struct RegionSpec {
  enum class Kind { box, physical, face };
  Kind kind = Kind::box;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  ///< box corners, m (reference coordinates, inclusive)
  std::string name;                           ///< physical group or face name
  /// A box region holds X when X is inside it, bounds included.
  bool box_holds(const Vec3& X) const { return (X.array() >= lo.array()).all() && (X.array() <= hi.array()).all(); }
};

/// The face names of a primitive shape: box xmin..zmax; cylinder top, bottom,
/// side; tube top, bottom, side, inner, outer; sphere surface (and inner
/// when hollow).
std::vector<std::string> shape_face_names(const ShapeSpec& shape);

/// A boundary face of the mesh: its element and local face (kTetFaces row).
struct BoundaryFace {
  Index element = 0;
  int face = 0;
  friend bool operator==(const BoundaryFace&, const BoundaryFace&) = default;
};

/// What selects a region of body `body` of `mesh`: the body's shape (shape
/// bodies) or its file's physical groups (mesh-file bodies; node ids are the
/// mesh's node_gid), and `where` ("file: key.region") and the body's name for
/// messages.
struct RegionContext {
  const Mesh& mesh;
  int body = 0;
  const ShapeSpec* shape = nullptr;                  ///< null: a mesh-file body
  const std::vector<PhysicalGroup>* groups = nullptr;  ///< mesh-file bodies
  std::string where, body_name;
};

/// The nodes of the region, ascending. InputError naming `where` when it
/// selects none, or names a group or face the body does not have.
std::vector<Index> region_nodes(const RegionContext& c, const RegionSpec& region);

/// The body's boundary faces in the region (all corners in a box, on a named
/// face, or triangles of a physical surface), by element then local face.
/// InputError naming `where` when it selects none.
std::vector<BoundaryFace> region_faces(const RegionContext& c, const RegionSpec& region);

}  // namespace shatter
