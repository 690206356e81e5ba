#include "runtime/contact_stage.hpp"

#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <numeric>

#include "contact/candidates.hpp"
#include "kernels/error.hpp"
#include "runtime/coloring.hpp"
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
  rebuild(model.mesh);
}

void ContactStage::rebuild(const Mesh& mesh) {
  surface_ = build_contact_surface(mesh);
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
  if (dec_) assign_pairs(x_new);
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
  pair_rank_.resize(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) pair_rank_[k] = primitive_rank_[primitive[k]];
}

void ContactStage::gather_active(std::span<const Vec3> x_old, std::span<const Vec3> x_new) {
  const int rank = dec_->rank();
  const std::vector<Index> kept = parallel_select(static_cast<Index>(pairs_.size()), [&](Index i) {
    return pair_rank_[i] == rank && pair_boxes_overlap(pairs_[i], x_old, x_new);
  });
  // Each rank's list is ascending: sorted, the concatenation is the canonical order.
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Index> all = dec_->allgather(kept);
  profile_.exchange_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::sort(all.begin(), all.end());
  profile_.exchange_bytes += static_cast<long>(sizeof(Index) * kept.size() * (dec_->size() - 1));
  active_.resize(all.size());
  active_rank_.resize(all.size());
  for (size_t k = 0; k < all.size(); ++k) {
    active_[k] = pairs_[all[k]];
    active_rank_[k] = pair_rank_[all[k]];
  }
  profile_.owned_pairs += static_cast<long>(kept.size());
}

std::array<long, 2> ContactStage::owned_pairs_range() const {
  long v[2] = {-profile_.owned_pairs, profile_.owned_pairs};
  if (dec_) MPI_Allreduce(MPI_IN_PLACE, v, 2, MPI_LONG, MPI_MAX, dec_->comm());
  return {-v[0], v[1]};
}

DcrResult ContactStage::apply(std::span<const Vec3> x_old, std::span<Vec3> x_new, std::span<Vec3> v,
                              std::span<const double> inv_mass, double dt) {
  using clock = std::chrono::steady_clock;
  // Each phase's wall time, less the exchanges within it (counted apart).
  auto lap = [this, last = clock::now(), exchanged = profile_.exchange_seconds](double& seconds) mutable {
    const auto now = clock::now();
    seconds += std::chrono::duration<double>(now - last).count() - (profile_.exchange_seconds - exchanged);
    last = now;
    exchanged = profile_.exchange_seconds;
  };
  auto timed_exchange = [this](auto f) {
    const auto t0 = clock::now();
    f();
    profile_.exchange_seconds += std::chrono::duration<double>(clock::now() - t0).count();
  };
  const bool valid = candidates_valid(x_old, x_new);
  lap(profile_.verlet_seconds);
  if (!valid) search(x_old, x_new);
  lap(profile_.search_seconds);
  if (dec_) {
    gather_active(x_old, x_new);
  } else {
    const std::vector<Index> kept = parallel_select(static_cast<Index>(pairs_.size()), [&](Index i) {
      return pair_boxes_overlap(pairs_[i], x_old, x_new);
    });
    active_.resize(kept.size());
    for (size_t k = 0; k < kept.size(); ++k) active_[k] = pairs_[kept[k]];
  }
  lap(profile_.filter_seconds);
  node_slot_.resize(x_new.size(), -1);
  const Index slots = contact_pair_nodes(active_, pair_offsets_, pair_slots_, node_slot_);
  const Coloring colors = greedy_coloring(pair_offsets_, pair_slots_, slots);
  const std::vector<Vec3> normals =
      contact_pair_normals(active_, surface_, vertex_triangles_, x_old);
  lap(profile_.coloring_seconds);
  const DcrPairColors dcr_colors{colors.offsets, colors.items, pair_slots_, slots, normals};
  DcrResult r;
  if (!dec_) {
    r = resolve_contacts(active_, x_new, x_old, v, inv_mass, dt, options_, dcr_colors);
  } else {
    // A moved pair travels as its index, its dissipation and its four nodes' x_new and v.
    constexpr int kRecord = 26;
    const int ranks = dec_->size();
    std::vector<int> counts(ranks), displs(ranks, 0);
    DcrRemote remote{active_rank_, dec_->rank(), [&](const DcrRemote::Moves& here, DcrRemote::Moves& there) {
                       send_.clear();
                       for (size_t k = 0; k < here.pairs.size(); ++k) {
                         const Index i = here.pairs[k];
                         send_.push_back(i);
                         send_.push_back(here.dissipated[k]);
                         for (const Index n : active_[i].nodes)
                           for (int c = 0; c < 3; ++c) send_.push_back(x_new[n][c]);
                         for (const Index n : active_[i].nodes)
                           for (int c = 0; c < 3; ++c) send_.push_back(v[n][c]);
                       }
                       const int mine = static_cast<int>(send_.size());
                       timed_exchange([&] {
                         MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, dec_->comm());
                         for (int q = 1; q < ranks; ++q) displs[q] = displs[q - 1] + counts[q - 1];
                         receive_.resize(displs[ranks - 1] + counts[ranks - 1]);
                         MPI_Allgatherv(send_.data(), mine, MPI_DOUBLE, receive_.data(), counts.data(),
                                        displs.data(), MPI_DOUBLE, dec_->comm());
                       });
                       profile_.exchange_bytes += static_cast<long>(sizeof(double)) * mine * (ranks - 1);
                       for (int q = 0; q < ranks; ++q) {
                         if (q == dec_->rank()) continue;
                         for (int at = displs[q]; at < displs[q] + counts[q]; at += kRecord) {
                           const double* rec = receive_.data() + at;
                           const auto i = static_cast<Index>(rec[0]);
                           there.pairs.push_back(i);
                           there.dissipated.push_back(rec[1]);
                           for (int k = 0; k < 4; ++k) {
                             const Index n = active_[i].nodes[k];
                             x_new[n] = Vec3(rec[2 + 3 * k], rec[3 + 3 * k], rec[4 + 3 * k]);
                             v[n] = Vec3(rec[14 + 3 * k], rec[15 + 3 * k], rec[16 + 3 * k]);
                           }
                         }
                       }
                     }};
    r = resolve_contacts(active_, x_new, x_old, v, inv_mass, dt, options_, dcr_colors, &remote);
  }
  lap(profile_.sweep_seconds);
  ++profile_.steps;
  profile_.candidates += static_cast<long>(pairs_.size());
  profile_.active_pairs += static_cast<long>(active_.size());
  profile_.colors += colors.num_colors();
  profile_.sweeps += r.sweeps;
  profile_.exchanges += r.exchanges;
  return r;
}

}  // namespace shatter
