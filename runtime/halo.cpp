#include "runtime/halo.hpp"

#include <algorithm>

#include "kernels/error.hpp"

namespace shatter {
namespace {
static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 arrays are read as node-major doubles");

std::span<double> as_doubles(std::span<Vec3> v) {
  return {v.empty() ? nullptr : v.data()->data(), 3 * v.size()};
}
std::span<const double> as_doubles(std::span<const Vec3> v) {
  return {v.empty() ? nullptr : v.data()->data(), 3 * v.size()};
}
}  // namespace

Halo::Halo(Index num_nodes, const NodeExchange& send, const NodeExchange& receive, MPI_Comm comm, int tag)
    : Halo(num_nodes, num_nodes, send, receive, comm, tag) {}

Halo::Halo(Index send_nodes, Index receive_nodes, const NodeExchange& send, const NodeExchange& receive,
           MPI_Comm comm, int tag)
    : comm_(comm), tag_(tag), num_nodes_(send_nodes), num_receive_nodes_(receive_nodes), send_(send),
      recv_(receive) {}

Halo::~Halo() {
  if (pending_) wait();
}

void Halo::check_size(size_t size, Index nodes, int components) {
  SHATTER_REQUIRE(components >= 1 && size == static_cast<size_t>(nodes) * components,
                  "Halo: nodal array of " << size << " doubles for " << nodes << " nodes x " << components
                                          << " components");
}

void Halo::check(std::span<const double> values, int components, bool expect_pending) const {
  SHATTER_REQUIRE(num_nodes_ == num_receive_nodes_, "Halo: an update in place on a plan between two numberings");
  check_size(values.size(), num_nodes_, components);
  SHATTER_REQUIRE(pending_ == expect_pending, "Halo: " << (pending_ ? "begin_update while an update is pending"
                                                                    : "end_update without a begin_update"));
}

void Halo::wait() {
  MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE);
  pending_ = false;
}

void Halo::begin_update(std::span<const double> values, int components) {
  check(values, components, false);
  const size_t c = components;
  send_buffer_.resize(send_.nodes.size() * c);
  for (size_t p = 0; p < send_.nodes.size(); ++p)
    std::copy_n(values.data() + send_.nodes[p] * c, c, send_buffer_.data() + p * c);
  post(components);
}

void Halo::post(int components) {
  const size_t c = components;
  recv_buffer_.resize(recv_.nodes.size() * c);
  requests_.resize(send_.ranks.size() + recv_.ranks.size());
  for (int i = 0; i < recv_.num_ranks(); ++i)
    MPI_Irecv(recv_buffer_.data() + recv_.offsets[i] * c,
              static_cast<int>((recv_.offsets[i + 1] - recv_.offsets[i]) * c), MPI_DOUBLE, recv_.ranks[i], tag_,
              comm_, &requests_[i]);
  for (int i = 0; i < send_.num_ranks(); ++i)
    MPI_Isend(send_buffer_.data() + send_.offsets[i] * c,
              static_cast<int>((send_.offsets[i + 1] - send_.offsets[i]) * c), MPI_DOUBLE, send_.ranks[i], tag_,
              comm_, &requests_[recv_.ranks.size() + i]);
  pending_ = true;
}

void Halo::end_update(std::span<double> values, int components) {
  check(values, components, true);
  wait();
  const size_t c = components;
  for (size_t p = 0; p < recv_.nodes.size(); ++p)
    std::copy_n(recv_buffer_.data() + p * c, c, values.data() + recv_.nodes[p] * c);
}

void Halo::update_ghosts(std::span<double> values, int components) {
  begin_update(values, components);
  end_update(values, components);
}

void Halo::begin_update(std::span<const Vec3> values) {
  begin_update(as_doubles(values), 3);
}

void Halo::end_update(std::span<Vec3> values) {
  end_update(as_doubles(values), 3);
}

void Halo::update_ghosts(std::span<Vec3> values) {
  update_ghosts(as_doubles(values), 3);
}

void Halo::update_ghosts(std::span<const std::span<Vec3>> arrays) {
  std::vector<std::span<const Vec3>> from(arrays.begin(), arrays.end());
  update(from, arrays);
}

void Halo::update(std::span<const std::span<const Vec3>> from, std::span<const std::span<Vec3>> to) {
  SHATTER_REQUIRE(from.size() == to.size() && !pending_, "Halo: " << from.size() << " arrays into " << to.size()
                                                                  << (pending_ ? " while an update is pending" : ""));
  for (const auto& a : from) check_size(3 * a.size(), num_nodes_, 3);
  for (const auto& a : to) check_size(3 * a.size(), num_receive_nodes_, 3);
  const size_t c = 3 * from.size();
  send_buffer_.resize(send_.nodes.size() * c);
  for (size_t p = 0; p < send_.nodes.size(); ++p)
    for (size_t k = 0; k < from.size(); ++k) std::copy_n(from[k][send_.nodes[p]].data(), 3, &send_buffer_[p * c + 3 * k]);
  post(static_cast<int>(c));
  wait();
  for (size_t p = 0; p < recv_.nodes.size(); ++p)
    for (size_t k = 0; k < to.size(); ++k) std::copy_n(&recv_buffer_[p * c + 3 * k], 3, to[k][recv_.nodes[p]].data());
}

void Halo::update_stacked(std::span<const std::span<const Vec3>> from, std::span<const std::span<Vec3>> to) {
  SHATTER_REQUIRE(!pending_, "Halo: an update while an update is pending");
  // Entry e of a stack: its array and the place in it.
  const auto at = [](auto arrays, Index e) {
    size_t k = 0;
    while (static_cast<size_t>(e) >= arrays[k].size()) e -= static_cast<Index>(arrays[k++].size());
    return arrays[k].data() + e;
  };
  const auto size = [](auto arrays) {
    size_t n = 0;
    for (const auto& a : arrays) n += a.size();
    return n;
  };
  check_size(3 * size(from), num_nodes_, 3);
  check_size(3 * size(to), num_receive_nodes_, 3);
  send_buffer_.resize(3 * send_.nodes.size());
  for (size_t p = 0; p < send_.nodes.size(); ++p) std::copy_n(at(from, send_.nodes[p])->data(), 3, &send_buffer_[3 * p]);
  post(3);
  wait();
  for (size_t p = 0; p < recv_.nodes.size(); ++p) std::copy_n(&recv_buffer_[3 * p], 3, at(to, recv_.nodes[p])->data());
}

}  // namespace shatter
