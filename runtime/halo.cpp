#include "runtime/halo.hpp"

#include <algorithm>
#include <utility>

#include "kernels/error.hpp"

namespace shatter {
namespace {
constexpr int kSumTag = 601;
constexpr int kUpdateTag = 602;
static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 arrays are read as node-major doubles");

std::span<double> as_doubles(std::span<Vec3> v) {
  return {v.empty() ? nullptr : v.data()->data(), 3 * v.size()};
}
std::span<const double> as_doubles(std::span<const Vec3> v) {
  return {v.empty() ? nullptr : v.data()->data(), 3 * v.size()};
}
}  // namespace

Halo::Halo(const LocalMesh& local, MPI_Comm comm)
    : num_nodes_(local.mesh.num_nodes()),
      shared_(local.shared),
      send_(local.ghost_send),
      recv_(local.ghost_recv),
      only_send_(local.ghost_only_send),
      only_recv_(local.ghost_only_recv) {
  MPI_Comm_dup(comm, &comm_);
  std::vector<std::pair<Index, std::pair<int, Index>>> entries;  // (node, (rank, source))
  for (int i = 0; i < shared_.num_ranks(); ++i)
    for (Index p = shared_.offsets[i]; p < shared_.offsets[i + 1]; ++p)
      entries.push_back({shared_.nodes[p], {shared_.ranks[i], p}});
  for (Index n : shared_.nodes) entries.push_back({n, {local.rank, -1}});
  std::sort(entries.begin(), entries.end());
  entries.erase(std::unique(entries.begin(), entries.end()),
                entries.end());  // own entry once per node
  for (const auto& [node, source] : entries) {
    if (combine_node_.empty() || combine_node_.back() != node) {
      combine_node_.push_back(node);
      combine_offsets_.push_back(static_cast<Index>(combine_source_.size()));
    }
    combine_source_.push_back(source.second);
  }
  combine_offsets_.push_back(static_cast<Index>(combine_source_.size()));
}

Halo::Halo(Index num_nodes, const NodeExchange& send, const NodeExchange& receive, MPI_Comm comm)
    : num_nodes_(num_nodes), send_(send), recv_(receive), only_send_(send), only_recv_(receive) {
  MPI_Comm_dup(comm, &comm_);
  combine_offsets_.push_back(0);
}

Halo::~Halo() {
  if (pending_ != Pending::none) wait();
  MPI_Comm_free(&comm_);
}

void Halo::check(std::span<const double> values, int components, Pending expected) const {
  SHATTER_REQUIRE(components >= 1 && values.size() == static_cast<size_t>(num_nodes_) * components,
                  "Halo: nodal array of " << values.size() << " doubles for " << num_nodes_
                                          << " nodes x " << components << " components");
  SHATTER_REQUIRE(pending_ == expected, "Halo: begin/end calls out of order");
}

void Halo::post(const NodeExchange& out, const NodeExchange& in, std::span<const double> values,
                int components, int tag) {
  const size_t c = components;
  send_buffer_.resize(out.nodes.size() * c);
  recv_buffer_.resize(in.nodes.size() * c);
  for (size_t p = 0; p < out.nodes.size(); ++p)
    std::copy_n(values.data() + out.nodes[p] * c, c, send_buffer_.data() + p * c);
  requests_.resize(out.ranks.size() + in.ranks.size());
  for (int i = 0; i < in.num_ranks(); ++i)
    MPI_Irecv(recv_buffer_.data() + in.offsets[i] * c,
              static_cast<int>((in.offsets[i + 1] - in.offsets[i]) * c), MPI_DOUBLE, in.ranks[i],
              tag, comm_, &requests_[i]);
  for (int i = 0; i < out.num_ranks(); ++i)
    MPI_Isend(send_buffer_.data() + out.offsets[i] * c,
              static_cast<int>((out.offsets[i + 1] - out.offsets[i]) * c), MPI_DOUBLE, out.ranks[i],
              tag, comm_, &requests_[in.ranks.size() + i]);
}

void Halo::wait() {
  MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE);
  pending_ = Pending::none;
}

void Halo::begin_sum(std::span<const double> values, int components) {
  check(values, components, Pending::none);
  post(shared_, shared_, values, components, kSumTag);
  pending_ = Pending::sum;
}

void Halo::end_sum(std::span<double> values, int components) {
  check(values, components, Pending::sum);
  wait();
  const size_t c = components;
  for (size_t j = 0; j < combine_node_.size(); ++j) {
    double* v = values.data() + combine_node_[j] * c;
    for (size_t d = 0; d < c; ++d) {
      double acc = 0.0;
      for (Index s = combine_offsets_[j]; s < combine_offsets_[j + 1]; ++s) {
        const Index src = combine_source_[s];
        acc += src < 0 ? v[d] : recv_buffer_[src * c + d];
      }
      v[d] = acc;
    }
  }
}

void Halo::sum_nodal(std::span<double> values, int components) {
  begin_sum(values, components);
  end_sum(values, components);
}

void Halo::sum_nodal(std::span<Vec3> values) {
  sum_nodal(as_doubles(values), 3);
}

void Halo::begin_update(std::span<const double> values, int components, GhostCopies copies) {
  check(values, components, Pending::none);
  post(sends(copies), receives(copies), values, components, kUpdateTag);
  pending_ = Pending::update;
  pending_copies_ = copies;
}

void Halo::end_update(std::span<double> values, int components) {
  check(values, components, Pending::update);
  wait();
  const size_t c = components;
  const NodeExchange& in = receives(pending_copies_);
  for (size_t p = 0; p < in.nodes.size(); ++p)
    std::copy_n(recv_buffer_.data() + p * c, c, values.data() + in.nodes[p] * c);
}

void Halo::update_ghosts(std::span<double> values, int components, GhostCopies copies) {
  begin_update(values, components, copies);
  end_update(values, components);
}

void Halo::begin_update(std::span<const Vec3> values, GhostCopies copies) {
  begin_update(as_doubles(values), 3, copies);
}

void Halo::end_update(std::span<Vec3> values) {
  end_update(as_doubles(values), 3);
}

void Halo::update_ghosts(std::span<Vec3> values, GhostCopies copies) {
  update_ghosts(as_doubles(values), 3, copies);
}

}  // namespace shatter
