#include "runtime/contact_stage.hpp"

#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <numeric>

#include "contact/candidates.hpp"
#include "kernels/error.hpp"
#include "runtime/contact_partition.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/parallel.hpp"

namespace shatter {

ContactStage::ContactStage(const Model& model, const ContactSpec& spec, const Decomposition* dec) {
  if (dec && dec->distributed()) {
    dec_ = dec;
    partition_ = std::make_unique<ContactPartition>(dec->comm());
  }
  options_.restitution = spec.restitution;
  options_.friction = spec.friction;
  options_.max_sweeps = spec.max_sweeps;
  margin_fraction_ = spec.search_margin;
  options_.placement = spec.placement;
  // A part of the model brings the whole model's surface.
  if (model.is_part()) set_surface(make_contact_surface(model.part.surface), model.mesh);
  else rebuild(model.mesh);
}

void ContactStage::rebuild(const Mesh& mesh) { set_surface(build_contact_surface(mesh), mesh); }

void ContactStage::set_surface(ContactSurface surface, const Mesh& mesh) {
  surface_ = std::move(surface);
  vertex_triangles_ = vertex_triangles(surface_);
  std::vector<double> lengths;
  lengths.reserve(surface_.edges.size());
  for (const auto& [a, b] : surface_.edges) lengths.push_back((mesh.reference[a] - mesh.reference[b]).norm());
  if (!lengths.empty()) {
    std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
    margin_ = margin_fraction_ * lengths[lengths.size() / 2];
  }
  have_candidates_ = false;
  if (!dec_) return;
  triangle_order_.resize(surface_.triangles.size());
  std::iota(triangle_order_.begin(), triangle_order_.end(), 0);
  std::sort(triangle_order_.begin(), triangle_order_.end(), [&](Index a, Index b) {
    return std::pair(surface_.triangles[a], a) < std::pair(surface_.triangles[b], b);
  });
  repartition_ = true;
}

ContactStage::~ContactStage() = default;

bool ContactStage::candidates_valid(std::span<const Vec3> x_old, std::span<const Vec3> x_new) const {
  if (!have_candidates_) return false;
  const auto& vertices = surface_.vertices;
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, vertices.size(), 4096), true,
      [&](const tbb::blocked_range<size_t>& r, bool valid) {
        for (size_t k = r.begin(); k < r.end() && valid; ++k) {
          const Index n = vertices[k];
          valid = (x_new[n] - x_search_[n]).cwiseAbs().maxCoeff() <= margin_ &&
                  (x_old[n] - x_search_[n]).cwiseAbs().maxCoeff() <= margin_;
        }
        return valid;
      },
      [](bool a, bool b) { return a && b; });
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
  ++profile_.searches;
  if (dec_) {
    assign_pairs(x_new);
  } else {
    mine_.resize(pairs_.size());
    std::iota(mine_.begin(), mine_.end(), 0);
  }
}

// Ownership rule: a candidate belongs to the rank of its face (vertex-face) or of
// its first edge (edge-edge). A primitive's weight is its number of candidates
// (the filter's work, and a bound on DCR's), plus 1 % so that RCB also spreads
// the surface away from the contact. The primitives are re-partitioned at a
// search (i.e. when the surface moved past the reuse margin) if the surface was
// rebuilt or the candidates per rank under the current partition are out of
// balance by more than 10 % (largest over mean).
void ContactStage::assign_pairs(std::span<const Vec3> x) {
  const auto nt = static_cast<Index>(surface_.triangles.size());
  std::vector<Index> primitive(pairs_.size());
  parallel_for_each(static_cast<Index>(pairs_.size()), [&](Index k) {
    const ContactPair& p = pairs_[k];
    if (p.kind == ContactPair::VertexFace) {
      const std::array<Index, 3> face{p.nodes[1], p.nodes[2], p.nodes[3]};
      const auto it = std::lower_bound(triangle_order_.begin(), triangle_order_.end(), face,
                                       [&](Index t, const std::array<Index, 3>& f) { return surface_.triangles[t] < f; });
      SHATTER_ASSERT(it != triangle_order_.end() && surface_.triangles[*it] == face);
      primitive[k] = *it;
    } else {
      const std::array<Index, 2> edge{p.nodes[0], p.nodes[1]};
      const auto it = std::lower_bound(surface_.edges.begin(), surface_.edges.end(), edge);
      SHATTER_ASSERT(it != surface_.edges.end() && *it == edge);
      primitive[k] = nt + static_cast<Index>(it - surface_.edges.begin());
    }
  });
  const int ranks = dec_->size();
  bool balanced = !repartition_;
  if (balanced) {
    std::vector<long> per_rank(ranks, 0);
    for (const Index q : primitive) ++per_rank[primitive_rank_[q]];
    const long most = *std::max_element(per_rank.begin(), per_rank.end());
    balanced = most * ranks <= 1.1 * static_cast<double>(pairs_.size());
  }
  if (!balanced) {
    const size_t n = surface_.triangles.size() + surface_.edges.size();
    std::vector<float> weight(n, 0.01f);
    for (const Index q : primitive) weight[q] += 1.0f;
    std::vector<Vec3> point(n);
    parallel_for_each(static_cast<Index>(n), [&](Index q) {
      if (q < nt) {
        const auto& t = surface_.triangles[q];
        point[q] = (x[t[0]] + x[t[1]] + x[t[2]]) / 3.0;
      } else {
        const auto& e = surface_.edges[q - nt];
        point[q] = 0.5 * (x[e[0]] + x[e[1]]);
      }
    });
    primitive_rank_ = partition_->partition(point, weight);
    repartition_ = false;
    ++profile_.repartitions;
  }
  mine_.clear();
  for (size_t k = 0; k < pairs_.size(); ++k)
    if (primitive_rank_[primitive[k]] == dec_->rank()) mine_.push_back(static_cast<Index>(k));
}

std::array<long, 3> ContactStage::owned_pairs_range() const {
  long v[2] = {-profile_.owned_pairs, profile_.owned_pairs}, sum = profile_.owned_pairs;
  if (dec_) {
    MPI_Allreduce(MPI_IN_PLACE, v, 2, MPI_LONG, MPI_MAX, dec_->comm());
    MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_LONG, MPI_SUM, dec_->comm());
  }
  return {-v[0], v[1], sum};
}

ContactPairs ContactStage::active_pairs() const {
  const std::vector<Index>& kept = scratch_.overlapping;
  ContactPairs out(kept.size());
  for (size_t k = 0; k < kept.size(); ++k) out[k] = pairs_[kept[k]];
  return out;
}

DcrResult ContactStage::apply(std::span<const Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v,
                              std::span<const double> inv_mass, double dt, std::span<const std::uint8_t> held) {
  using clock = std::chrono::steady_clock;
  // Each phase's wall time, less the exchanges within it (counted apart).
  auto lap = [this, last = clock::now(), exchanged = profile_.exchange_seconds](double& seconds) mutable {
    const auto now = clock::now();
    seconds += std::chrono::duration<double>(now - last).count() - (profile_.exchange_seconds - exchanged);
    last = now;
    exchanged = profile_.exchange_seconds;
  };
  const bool valid = candidates_valid(x_old, x_new);
  lap(profile_.verlet_seconds);
  if (!valid) search(x_old, x_new);
  lap(profile_.search_seconds);
  DcrGather gather;
  if (dec_)
    gather = [&](std::vector<Index>& found) {
      const auto t0 = clock::now();
      profile_.exchange_bytes += static_cast<long>(sizeof(Index) * found.size() * (dec_->size() - 1));
      found = dec_->allgather(found);
      std::sort(found.begin(), found.end());
      profile_.exchange_seconds += std::chrono::duration<double>(clock::now() - t0).count();
    };
  const DcrResult r = resolve_contacts(pairs_, mine_, x_new, x_old, v, inv_mass, dt, options_,
                                       {&surface_, &vertex_triangles_}, scratch_, gather, held);
  lap(profile_.sweep_seconds);
  ++profile_.steps;
  profile_.candidates += static_cast<long>(pairs_.size());
  profile_.owned_pairs += static_cast<long>(scratch_.overlapping.size());
  profile_.detections += r.detected;
  profile_.sweeps += r.sweeps;
  return r;
}

}  // namespace shatter
