#pragma once
// Step 2 of the time loop (DESIGN.md): contact search over the step's motion
// and the DCR response, for scenes with a contact block. Owns the contact
// surface; fracture extends it with the crack faces it opens.
#include <span>
#include <vector>

#include "contact/dcr.hpp"
#include "contact/surface.hpp"
#include "runtime/model.hpp"

namespace shatter {

class ContactStage {
 public:
  ContactStage(const Model& model, const ContactSpec& spec);

  /// Find the pairs penetrating during the motion x_old -> x_new and resolve
  /// them: x_new is projected back, v (the mid-step velocity) gets the DCR
  /// impulses. inv_mass: inverse lumped masses, 0 for nodes DCR must not move.
  DcrResult apply(std::span<const Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v,
                  std::span<const double> inv_mass);

  /// Rebuild the surface after fracture split nodes: crack faces whose sides
  /// no longer share nodes join it, and older triangles get the new node ids.
  void rebuild(const Mesh& mesh) { surface_ = build_contact_surface(mesh); }

  const ContactSurface& surface() const { return surface_; }
  /// Seconds spent in the search and in DCR so far.
  double search_seconds() const { return search_seconds_; }
  double dcr_seconds() const { return dcr_seconds_; }

 private:
  ContactSurface surface_;
  DcrOptions options_;
  std::vector<Index> pair_offsets_, pair_nodes_;
  double search_seconds_ = 0, dcr_seconds_ = 0;
};

}  // namespace shatter
