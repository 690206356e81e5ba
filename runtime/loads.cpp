#include "runtime/loads.hpp"

#include <algorithm>

#include "kernels/surface_load.hpp"
#include "mesh/topology.hpp"

namespace shatter {

std::vector<Model::LoadFace> held_load_faces(const std::vector<Model::LoadFace>& whole,
                                             std::span<const Index> element_index) {
  std::vector<Model::LoadFace> out;
  for (Model::LoadFace f : whole) {
    const auto it = std::lower_bound(element_index.begin(), element_index.end(), f.element);
    if (it == element_index.end() || *it != f.element) continue;
    f.element = static_cast<Index>(it - element_index.begin());
    out.push_back(f);
  }
  return out;
}

SurfaceLoads::SurfaceLoads(const Model& model) : model_(model), face_nodes_(model.mesh.order == 1 ? 3 : 6) {
  rebuild();
}

void SurfaceLoads::rebuild() {
  const Mesh& mesh = model_.mesh;
  nodes_.clear();
  for (const Model::LoadFace& f : model_.load_faces)
    for (int a = 0; a < face_nodes_; ++a) nodes_.push_back(mesh.element(f.element)[kTetFaces[f.face][a]]);
  std::sort(nodes_.begin(), nodes_.end());
  nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
  slot_.clear();
  for (const Model::LoadFace& f : model_.load_faces)
    for (int a = 0; a < face_nodes_; ++a) {
      const Index n = mesh.element(f.element)[kTetFaces[f.face][a]];
      slot_.push_back(static_cast<Index>(std::lower_bound(nodes_.begin(), nodes_.end(), n) - nodes_.begin()));
    }
  force_.assign(nodes_.size(), Vec3::Zero());
}

void SurfaceLoads::compute(std::span<const Vec3> x, double t) {
  const Mesh& mesh = model_.mesh;
  std::fill(force_.begin(), force_.end(), Vec3::Zero());
  for (std::size_t k = 0; k < model_.load_faces.size(); ++k) {
    const Model::LoadFace& f = model_.load_faces[k];
    const LoadSpec& load = model_.scene.loads[f.load];
    const double factor = load.amplitude.value(t);
    if (factor == 0.0) continue;
    const Index* element = mesh.element(f.element);
    Vec3 at[6], nodal[6];
    for (int a = 0; a < face_nodes_; ++a) {
      const Index n = element[kTetFaces[f.face][a]];
      at[a] = load.pressure ? x[n] : mesh.reference[n];
    }
    if (load.pressure) pressure_forces(at, face_nodes_, factor * *load.pressure, nodal);
    else traction_forces(at, face_nodes_, factor * *load.traction, nodal);
    for (int a = 0; a < face_nodes_; ++a) force_[slot_[k * face_nodes_ + a]] += nodal[a];
  }
}

}  // namespace shatter
