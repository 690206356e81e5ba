#pragma once
// Step 2 of the time loop (DESIGN.md): contact search over the step's motion
// and the DCR response, for scenes with a contact block. Owns the contact
// surface; fracture rebuilds it with the crack faces it opens.
//
// Candidate reuse (a Verlet list): the search runs on swept boxes inflated by
// a margin (1.01 delta; delta = contact.search_margin, default 0.1, times the
// median surface edge) and its candidates serve the following steps for as
// long as every surface node stays within delta (max norm) of where it was at
// that search, at the start and at the end of the step. A primitive's swept
// box over such a step then lies inside its inflated box of the search (the
// 1 % covers the relative growth kBoxInflation of a larger box), so filtering
// the list with the step's own box test (pair_boxes_overlap) gives exactly
// the pairs a fresh search would: DCR sees the same list, in the same order,
// whatever the reuse schedule (restarts stay bitwise).
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
                  std::span<const double> inv_mass, double dt);

  /// Rebuild the surface after fracture split nodes: crack faces whose sides
  /// no longer share nodes join it, and older triangles get the new node ids.
  void rebuild(const Mesh& mesh);

  const ContactSurface& surface() const { return surface_; }
  /// The pairs DCR checked in the last apply() (equal to a fresh search's).
  const ContactPairs& active_pairs() const { return active_; }
  /// Seconds spent in the search and in DCR so far; number of searches run.
  double search_seconds() const { return search_seconds_; }
  double dcr_seconds() const { return dcr_seconds_; }
  long searches() const { return searches_; }
  /// The reuse margin delta, m: contact.search_margin (default a tenth) times the
  /// median surface edge length.
  double margin() const { return margin_; }

 private:
  bool candidates_valid(std::span<const Vec3> x_old, std::span<const Vec3> x_new) const;
  void search(std::span<const Vec3> x_old, std::span<const Vec3> x_new);

  ContactSurface surface_;
  DcrOptions options_;
  double margin_fraction_ = 0.1;  ///< delta / median surface edge
  double margin_ = 0;
  bool have_candidates_ = false;
  ContactPairs pairs_;   ///< candidates of the last search (inflated boxes)
  ContactPairs active_;  ///< this step's pairs: pairs_ whose swept boxes overlap
  std::vector<Vec3> x_search_;  ///< x_new of the last search, per mesh node
  std::vector<Index> pair_offsets_, pair_nodes_;
  double search_seconds_ = 0, dcr_seconds_ = 0;
  long searches_ = 0;
};

}  // namespace shatter
