#pragma once
// The scene's surface loads (loads[i]: pressure or traction on a region's
// boundary faces, times an amplitude) as nodal forces on this rank's model.
// Every face held here is evaluated (kernels/surface_load.hpp) and its nodal
// forces are added per node in the faces' order, which is the whole model's
// (Model::load_faces): every rank touching a node holds all of its loaded
// faces (they belong to elements of its star) and gets the same bits, so no
// force is summed over ranks.
#include <span>
#include <vector>

#include "runtime/model.hpp"

namespace shatter {

/// The load faces of the held elements `element_index` (a part's, ascending
/// whole-model indices), with local element indices, in the same order.
std::vector<Model::LoadFace> held_load_faces(const std::vector<Model::LoadFace>& whole,
                                             std::span<const Index> element_index);

class SurfaceLoads {
 public:
  explicit SurfaceLoads(const Model& model);

  /// The faces' nodes read again from the mesh (after node splitting).
  void rebuild();
  /// The loaded nodes, ascending.
  const std::vector<Index>& nodes() const { return nodes_; }
  /// The nodal forces at positions x (m) and time t (s): force()[k] acts on nodes()[k], N.
  void compute(std::span<const Vec3> x, double t);
  const std::vector<Vec3>& force() const { return force_; }

 private:
  const Model& model_;
  int face_nodes_ = 3;               ///< 3 (TET4) or 6 (TET10)
  std::vector<Index> nodes_;
  std::vector<Index> slot_;          ///< [f * face_nodes_ + a]: the position in nodes_ of face f's node a
  std::vector<Vec3> force_;
};

}  // namespace shatter
