#include "runtime/contact_stage.hpp"

#include <algorithm>
#include <chrono>

#include "contact/candidates.hpp"
#include "runtime/coloring.hpp"

namespace shatter {

ContactStage::ContactStage(const Model& model, const ContactSpec& spec) {
  options_.restitution = spec.restitution;
  options_.friction = spec.friction;
  options_.max_sweeps = spec.max_sweeps;
  margin_fraction_ = spec.search_margin;
  options_.mid_step = spec.mid_step;
  rebuild(model.mesh);
}

void ContactStage::rebuild(const Mesh& mesh) {
  surface_ = build_contact_surface(mesh);
  std::vector<double> lengths;
  lengths.reserve(surface_.edges.size());
  for (const auto& [a, b] : surface_.edges) lengths.push_back((mesh.reference[a] - mesh.reference[b]).norm());
  if (!lengths.empty()) {
    std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
    margin_ = margin_fraction_ * lengths[lengths.size() / 2];
  }
  have_candidates_ = false;
}

bool ContactStage::candidates_valid(std::span<const Vec3> x_old, std::span<const Vec3> x_new) const {
  if (!have_candidates_) return false;
  for (Index n : surface_.vertices)
    if ((x_new[n] - x_search_[n]).cwiseAbs().maxCoeff() > margin_ ||
        (x_old[n] - x_search_[n]).cwiseAbs().maxCoeff() > margin_)
      return false;
  return true;
}

void ContactStage::search(std::span<const Vec3> x_old, std::span<const Vec3> x_new) {
  SweptBoxes boxes = swept_boxes(surface_, x_old, x_new);
  for (auto* list : {&boxes.triangles, &boxes.edges, &boxes.vertices})
    for (Box& b : *list) {
      b.lo.array() -= 1.01 * margin_;
      b.hi.array() += 1.01 * margin_;
    }
  pairs_ = find_candidates(surface_, boxes);
  x_search_.assign(x_new.begin(), x_new.end());
  have_candidates_ = true;
  ++searches_;
}

DcrResult ContactStage::apply(std::span<const Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v,
                              std::span<const double> inv_mass, double dt) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  if (!candidates_valid(x_old, x_new)) search(x_old, x_new);
  active_.clear();
  for (const ContactPair& p : pairs_)
    if (pair_boxes_overlap(p, x_old, x_new)) active_.push_back(p);
  const auto t1 = clock::now();
  contact_pair_nodes(active_, pair_offsets_, pair_nodes_);
  const Coloring colors = greedy_coloring(pair_offsets_, pair_nodes_, static_cast<Index>(x_new.size()));
  const DcrResult r = resolve_contacts(active_, x_new, x_old, v, inv_mass, dt, options_, {colors.offsets, colors.items});
  const auto t2 = clock::now();
  search_seconds_ += std::chrono::duration<double>(t1 - t0).count();
  dcr_seconds_ += std::chrono::duration<double>(t2 - t1).count();
  return r;
}

}  // namespace shatter
