#include "runtime/contact_stage.hpp"

#include <chrono>

#include "contact/candidates.hpp"
#include "runtime/coloring.hpp"

namespace shatter {

ContactStage::ContactStage(const Model& model, const ContactSpec& spec) : surface_(build_contact_surface(model.mesh)) {
  options_.restitution = spec.restitution;
  options_.friction = spec.friction;
}

DcrResult ContactStage::apply(std::span<const Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v,
                              std::span<const double> inv_mass) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const ContactPairs pairs = find_candidates(surface_, x_old, x_new);
  const auto t1 = clock::now();
  contact_pair_nodes(pairs, pair_offsets_, pair_nodes_);
  const Coloring colors = greedy_coloring(pair_offsets_, pair_nodes_, static_cast<Index>(x_new.size()));
  const DcrResult r = resolve_contacts(pairs, x_new, x_old, v, inv_mass, options_, {colors.offsets, colors.items});
  const auto t2 = clock::now();
  search_seconds_ += std::chrono::duration<double>(t1 - t0).count();
  dcr_seconds_ += std::chrono::duration<double>(t2 - t1).count();
  return r;
}

}  // namespace shatter
