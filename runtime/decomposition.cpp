#include "runtime/decomposition.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <string>

#include "kernels/error.hpp"
#include "mesh/partition.hpp"
#include "mesh/reorder.hpp"
#include "runtime/allgather_list.hpp"
#include "runtime/alltoall_lists.hpp"
#include "runtime/comm_place.hpp"
#include "runtime/global_sum.hpp"
#include "runtime/halo.hpp"
#include "runtime/shell_model.hpp"

namespace shatter {
namespace {

/// The position of each point along the Morton curve of their bounding cube
/// (ties in index order).
std::vector<Index> morton_positions(std::span<const Vec3> points) {
  const auto [lo, hi] = bounding_cube(points);
  const auto n = static_cast<Index>(points.size());
  const std::vector<Index> order = morton_order(n, [&](Index i) { return points[i]; }, lo, hi);
  std::vector<Index> position(n);
  for (Index k = 0; k < n; ++k) position[order[k]] = k;
  return position;
}

}  // namespace

Decomposition::Decomposition(const Model& model, MPI_Comm comm) : model_(model) {
  const CommPlace place = comm_place(comm);
  if (place.mpi) comm_ = comm;
  rank_ = place.rank;
  size_ = place.size;
  const Mesh& mesh = model.mesh;
  if (model.is_part()) {
    granule_rank_ = model.part.granule_rank;
  } else {
    check_ranks(model, size_);
    // A model of shells alone has no element granules.
    if (mesh.num_elements() > 0) granule_rank_ = partition_granules(mesh, ElementForces::kGranule, size_);
  }
  // Shell control vertices: granules of kShellGranule vertices of their own,
  // past the elements', partitioned by their patches (docs/parallel.md
  // "Shells on ranks").
  first_shell_granule_ = num_granules();
  if (!model.shells.empty()) {
    shell_patches_ = shell_patch_nodes(model.shells);
    first_shell_node_ = model.shells.front().first_node;
    shell_nodes_ = shell_vertices(model.shells);
    shell_position_ = morton_positions(std::span<const Vec3>(mesh.reference).subspan(first_shell_node_, shell_nodes_));
    std::vector<Index> items = shell_patches_.nodes;
    for (Index& n : items)
      if (n >= 0) n = shell_position_[n - first_shell_node_];
    const std::vector<int> part =
        partition_item_granules(shell_nodes_, items, shell_patches_.width, kShellGranule, size_);
    granule_rank_.insert(granule_rank_.end(), part.begin(), part.end());
  }
  for (Index g = 0; g < num_granules(); ++g)
    if (granule_rank_[g] == rank_) owned_granules_.push_back(g);
  for (Index e = 0; e < mesh.num_elements(); ++e)
    if (owns_element(e)) owned_element_ids_.push_back(e);
  owned_elements_ = static_cast<Index>(owned_element_ids_.size());
  if (size_ > 1) {
    std::vector<char> owner(size_, 0);
    for (Index e = 0; e < mesh.num_elements(); ++e) owner[element_rank(e)] = 1;
    for (int r = 0; r < size_; ++r)
      if (owner[r] && r != rank_) neighbours_.push_back(r);
  }
  rebuild_nodes();
}

Decomposition::~Decomposition() = default;

void check_ranks(const Model& model, int ranks) {
  const Index ne = model.whole_elements(), ng = (ne + ElementForces::kGranule - 1) / ElementForces::kGranule;
  if (ranks > 1 && ne > 0 && ranks > ng)
    throw InputError(model.scene.file + ": the mesh has " + std::to_string(ne) + " elements, " +
                     std::to_string(ng) + (ng == 1 ? " granule of " : " granules of ") + std::to_string(ElementForces::kGranule) +
                     "; it cannot be shared by " + std::to_string(ranks) + " MPI ranks (use at most " +
                     std::to_string(ng) + ")");
  const Index nv = shell_vertices(model.shells), nsg = (nv + kShellGranule - 1) / kShellGranule;
  if (ranks > 1 && nv > 0 && ranks > nsg)
    throw InputError(model.scene.file + ": the shells have " + std::to_string(nv) + " control vertices, " +
                     std::to_string(nsg) + (nsg == 1 ? " granule of " : " granules of ") + std::to_string(kShellGranule) +
                     "; they cannot be shared by " + std::to_string(ranks) + " MPI ranks (use at most " +
                     std::to_string(nsg) + ")");
}

NodeRanks granule_touching_ranks(const Mesh& mesh, std::span<const int> granule_rank,
                                 std::span<const Index> whole_element) {
  std::vector<int> elem_part(mesh.num_elements());
  for (Index e = 0; e < mesh.num_elements(); ++e)
    elem_part[e] = granule_rank[(whole_element.empty() ? e : whole_element[e]) / ElementForces::kGranule];
  return touching_ranks(mesh, elem_part);
}

Index Decomposition::home_granule_of(Index n) const {
  const Mesh& mesh = model_.mesh;
  if (is_shell_node(n)) return first_shell_granule_ + shell_position_[n - first_shell_node_] / kShellGranule;
  if (mesh.node_elem_offsets[n] == mesh.node_elem_offsets[n + 1]) return -1;
  return model_.whole_element(mesh.node_elem[mesh.node_elem_offsets[n]]) / ElementForces::kGranule;
}

void Decomposition::rebuild_nodes(std::span<const Index> groups, int group_width) {
  const Mesh& mesh = model_.mesh;
  const Index ne = mesh.num_elements(), nn = mesh.num_nodes();
  const int k = mesh.nodes_per_element();

  // Home granule of each node: the granule of the first element of its star;
  // the home nodes of each owned granule, ascending.
  home_granule_.resize(nn);
  // On a part, a ghost-only node's star may not be whole here, but none of
  // it is owned here, so neither is the granule computed; a contact-surface
  // node outside the part's elements has no star and no home granule (-1).
  for (Index n = 0; n < nn; ++n) home_granule_[n] = home_granule_of(n);
  {
    std::vector<Index> slot(num_granules(), -1);
    for (size_t k = 0; k < owned_granules_.size(); ++k) slot[owned_granules_[k]] = static_cast<Index>(k);
    // The index k of node n's home granule among the owned ones, -1 if not owned.
    auto home_slot = [&](Index n) { return home_granule_[n] < 0 ? -1 : slot[home_granule_[n]]; };
    home_offsets_.assign(owned_granules_.size() + 1, 0);
    for (Index n = 0; n < nn; ++n)
      if (home_slot(n) >= 0) ++home_offsets_[home_slot(n) + 1];
    for (size_t k = 0; k < owned_granules_.size(); ++k) home_offsets_[k + 1] += home_offsets_[k];
    home_nodes_.resize(home_offsets_.back());
    owned_nodes_.clear();
    std::vector<Index> fill(home_offsets_.begin(), home_offsets_.end() - 1);
    for (Index n = 0; n < nn; ++n)
      if (home_slot(n) >= 0) {
        home_nodes_[fill[home_slot(n)]++] = n;
        owned_nodes_.push_back(n);
      }
  }

  if (size_ == 1) {
    // One rank touches, holds and owns everything.
    touched_nodes_.resize(nn);
    std::iota(touched_nodes_.begin(), touched_nodes_.end(), 0);
    held_nodes_ = touched_nodes_;
    local_elements_.resize(ne);
    std::iota(local_elements_.begin(), local_elements_.end(), 0);
    return;
  }
  if (model_.is_part() && !model_.holds_two_layers()) {
    // A ghost-only node's star is not whole here: its ranks come from the start-up rank.
    node_rank_offsets_ = model_.part.node_rank_offsets;
    node_ranks_ = model_.part.node_ranks;
  } else {
    // From the stars: with two layers, every node of a held element is whole
    // here, so its ranks are right (after splits too); the outer layer's own
    // nodes get only some of theirs, and are never read.
    NodeRanks touch = granule_touching_ranks(mesh, granule_rank_, model_.part.element_index);
    node_rank_offsets_ = std::move(touch.offsets);
    node_ranks_ = std::move(touch.ranks);
  }
  if (shell_nodes_ > 0) {
    // A shell node (in no element) is touched by the owner of its granule alone.
    std::vector<Index> offsets(nn + 1, 0);
    std::vector<int> ranks;
    for (Index n = 0; n < nn; ++n) {
      if (is_shell_node(n)) ranks.push_back(granule_rank_[home_granule_[n]]);
      else ranks.insert(ranks.end(), node_ranks_.begin() + node_rank_offsets_[n], node_ranks_.begin() + node_rank_offsets_[n + 1]);
      offsets[n + 1] = static_cast<Index>(ranks.size());
    }
    node_rank_offsets_ = std::move(offsets);
    node_ranks_ = std::move(ranks);
  }

  touched_nodes_.clear();
  local_elements_.clear();
  held_nodes_.clear();
  std::vector<char> held(nn, 0);
  for (Index n = 0; n < nn; ++n)
    if (touches(n, rank_)) touched_nodes_.push_back(n);
  for (Index e = 0; e < ne; ++e) {
    bool local = false;
    for (int a = 0; a < k && !local; ++a) local = touches(mesh.element(e)[a], rank_);
    if (!local) continue;
    local_elements_.push_back(e);
    for (int a = 0; a < k; ++a) held[mesh.element(e)[a]] = 1;
  }
  // The shell patches are groups too: a rank computes every patch with a
  // node it touches, and holds (receives) the patch's other nodes.
  std::vector<Index> all_groups;
  if (shell_patches_.patches() > 0) {
    const int width = std::max(group_width, shell_patches_.width);
    all_groups.assign((groups.size() / group_width + shell_patches_.patches()) * width, -1);
    Index g = 0;
    for (size_t i = 0; i < groups.size(); i += group_width, ++g)
      std::copy_n(groups.begin() + i, group_width, all_groups.begin() + g * width);
    for (Index p = 0; p < shell_patches_.patches(); ++p, ++g)
      std::copy_n(shell_patches_.of(p).begin(), shell_patches_.width, all_groups.begin() + g * width);
    groups = all_groups;
    group_width = width;
  }
  // The groups around each node (CSR), and the nodes of the groups with a touched node.
  const Index ng = static_cast<Index>(groups.size() / group_width);
  auto group = [&](Index g) { return groups.subspan(static_cast<size_t>(g) * group_width, group_width); };
  std::vector<Index> group_offsets(nn + 1, 0), node_groups;
  for (Index g = 0; g < ng; ++g) {
    bool mine = false;
    for (Index n : group(g))
      if (n >= 0) ++group_offsets[n + 1], mine = mine || touches(n, rank_);
    if (mine)
      for (Index n : group(g))
        if (n >= 0) held[n] = 1;
  }
  for (Index n = 0; n < nn; ++n) group_offsets[n + 1] += group_offsets[n];
  node_groups.resize(group_offsets[nn]);
  {
    std::vector<Index> fill(group_offsets.begin(), group_offsets.end() - 1);
    for (Index g = 0; g < ng; ++g)
      for (Index n : group(g))
        if (n >= 0) node_groups[fill[n]++] = g;
  }
  for (Index n = 0; n < nn; ++n)
    if (held[n]) held_nodes_.push_back(n);

  // Receive: ghost-only nodes (held, not touched) from their owners.
  std::map<int, std::vector<Index>>& recv = recv_;
  std::map<int, std::vector<Index>>& send = send_;
  recv.clear();
  send.clear();
  ghost_only_nodes_.clear();
  for (Index n : held_nodes_)
    if (!touches(n, rank_)) {
      recv[node_owner(n)].push_back(n);
      ghost_only_nodes_.push_back(n);
    }
  // Send: nodes owned here to every rank holding them without touching
  // them. Rank q holds n when it touches a node of an element of n's star or
  // of a group holding n. The ranks touching each element's nodes and each
  // group's come first (CSR), then each owned node's holders are their union,
  // marked per rank (mark[q] == n: q is listed for n), without sorting.
  auto ranks_of_lists = [&](Index count, auto nodes_of) {
    NodeRanks out;
    out.offsets.assign(1, 0);
    std::vector<Index> mark(size_, -1);
    for (Index i = 0; i < count; ++i) {
      for (Index m : nodes_of(i))
        if (m >= 0)
          for (Index q = node_rank_offsets_[m]; q < node_rank_offsets_[m + 1]; ++q)
            if (mark[node_ranks_[q]] != i) mark[node_ranks_[q]] = i, out.ranks.push_back(node_ranks_[q]);
      out.offsets.push_back(static_cast<Index>(out.ranks.size()));
    }
    return out;
  };
  const NodeRanks element_ranks =
      ranks_of_lists(ne, [&](Index e) { return std::span<const Index>(mesh.element(e), static_cast<size_t>(k)); });
  const NodeRanks group_ranks = ranks_of_lists(ng, group);
  std::vector<Index> mark(size_, -1);
  for (Index n : touched_nodes_) {
    if (node_owner(n) != rank_) continue;
    auto send_to = [&](std::span<const int> ranks) {
      for (int q : ranks)
        if (mark[q] != n) {
          mark[q] = n;
          if (!touches(n, q)) send[q].push_back(n);
        }
    };
    for (Index p = mesh.node_elem_offsets[n]; p < mesh.node_elem_offsets[n + 1]; ++p)
      send_to(element_ranks.of(mesh.node_elem[p]));
    for (Index p = group_offsets[n]; p < group_offsets[n + 1]; ++p) send_to(group_ranks.of(node_groups[p]));
  }
  halo_ = std::make_unique<Halo>(nn, exchange_from(send), exchange_from(recv), comm_, kGhostTag);
}

void Decomposition::begin_ghost_update(std::span<const Vec3> x) const {
  if (halo_) halo_->begin_update(x);
}

void Decomposition::end_ghost_update(std::span<Vec3> x) const {
  if (halo_) halo_->end_update(x);
}

std::size_t Decomposition::ghost_bytes() const { return halo_ ? halo_->update_bytes(3) : 0; }

DecompositionStats Decomposition::stats() const {
  long v[5] = {-owned_elements_, owned_elements_, static_cast<long>(local_elements_.size()),
               static_cast<long>(ghost_bytes()), halo_ ? halo_->update_messages() : 0};
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, v, 5, MPI_LONG, MPI_MAX, comm_);
  return {-v[0], v[1], v[2], v[3], v[4]};
}

std::size_t Decomposition::sum_bytes(std::size_t count, std::size_t maxima) { return allreduce_bytes(count, maxima); }

void Decomposition::sum(std::span<ExactSum> values, std::span<long> most) const {
  if (size_ > 1) allreduce(values, comm_, most);
}

void Decomposition::broadcast(std::span<double> values, int root) const {
  if (size_ > 1) MPI_Bcast(values.data(), static_cast<int>(values.size()), MPI_DOUBLE, root, comm_);
}

std::string Decomposition::broadcast(std::string text, int root) const {
  if (size_ == 1) return text;
  int n = static_cast<int>(text.size());
  MPI_Bcast(&n, 1, MPI_INT, root, comm_);
  text.resize(n);
  MPI_Bcast(text.data(), n, MPI_CHAR, root, comm_);
  return text;
}

std::vector<Index> Decomposition::allgather(std::span<const Index> mine) const {
  if (size_ == 1) return {mine.begin(), mine.end()};
  static_assert(sizeof(Index) == sizeof(int));
  return allgather_list(mine, MPI_INT, comm_);
}

std::vector<double> Decomposition::allgather(std::span<const double> mine) const {
  if (size_ == 1) return {mine.begin(), mine.end()};
  return allgather_list(mine, MPI_DOUBLE, comm_);
}

std::vector<GlobalId> Decomposition::share_with_neighbours(std::span<const GlobalId> mine) const {
  std::vector<GlobalId> out(mine.begin(), mine.end());
  if (size_ == 1) return out;
  std::vector<std::vector<GlobalId>> to(size_);
  for (const int q : neighbours_) to[q] = out;
  for (const std::vector<GlobalId>& from : alltoall(to)) out.insert(out.end(), from.begin(), from.end());
  return out;
}

std::vector<std::vector<Index>> Decomposition::alltoall(const std::vector<std::vector<Index>>& to) const {
  static_assert(sizeof(Index) == sizeof(int));
  return alltoall_of(to, MPI_INT);
}

std::vector<std::vector<GlobalId>> Decomposition::alltoall(const std::vector<std::vector<GlobalId>>& to) const {
  static_assert(sizeof(GlobalId) == sizeof(std::int64_t));
  return alltoall_of(to, MPI_INT64_T);
}

template <class T>
std::vector<std::vector<T>> Decomposition::alltoall_of(const std::vector<std::vector<T>>& to, MPI_Datatype type) const {
  SHATTER_REQUIRE(static_cast<int>(to.size()) == size_, "alltoall: " << to.size() << " lists for " << size_ << " ranks");
  if (size_ == 1) return to;
  return alltoall_lists(to, type, comm_);
}

std::vector<GlobalId> Decomposition::allgather(std::span<const GlobalId> mine) const {
  if (size_ == 1) return {mine.begin(), mine.end()};
  static_assert(sizeof(GlobalId) == sizeof(std::int64_t));
  return allgather_list(mine, MPI_INT64_T, comm_);
}

double Decomposition::min(double value) const {
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MIN, comm_);
  return value;
}

void Decomposition::min(std::span<double> values) const {
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_MIN, comm_);
}

void Decomposition::min(std::span<double> values, std::pair<double, long>& least) const {
  if (size_ > 1) allreduce_min(values, least, comm_);
}

void Decomposition::max(std::span<double> values) const {
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_MAX, comm_);
}

int Decomposition::rank_of_min(double value) const {
  struct {
    double value;
    int rank;
  } least{value, rank_};
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, &least, 1, MPI_DOUBLE_INT, MPI_MINLOC, comm_);
  return least.rank;
}

std::vector<long> Decomposition::sum(std::vector<long> values) const {
  if (size_ > 1)
    MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_LONG, MPI_SUM, comm_);
  return values;
}

int Decomposition::max(int value) const {
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_INT, MPI_MAX, comm_);
  return value;
}

long Decomposition::max(long value) const {
  if (size_ > 1) MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_LONG, MPI_MAX, comm_);
  return value;
}

std::vector<long> Decomposition::gather(long value) const {
  std::vector<long> all(rank_ == 0 ? size_ : 0);
  if (size_ == 1) all[0] = value;
  else MPI_Gather(&value, 1, MPI_LONG, all.data(), 1, MPI_LONG, 0, comm_);
  return all;
}

}  // namespace shatter
