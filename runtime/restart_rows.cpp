#include "runtime/restart_rows.hpp"

#include <algorithm>
#include <array>

#include "runtime/alltoall_lists.hpp"

namespace shatter {
namespace {

int comm_size(MPI_Comm comm) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  return ranks;
}

int comm_rank(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

}  // namespace

std::vector<std::size_t> block_firsts(std::size_t rows, int ranks) {
  std::vector<std::size_t> first(ranks + 1);
  for (int r = 0; r <= ranks; ++r) first[r] = rows * r / ranks;
  return first;
}

PartBcRows part_bc_rows(std::span<const std::uint8_t> block, std::size_t n, std::span<const Index> rows,
                        MPI_Comm comm) {
  const int ranks = comm_size(comm), rank = comm_rank(comm);
  const std::vector<std::size_t> first = block_firsts(n, ranks);
  // The prescribed rows before this block, and in the whole model.
  long count = static_cast<long>(std::count_if(block.begin(), block.end(), [](std::uint8_t m) { return m != 0; }));
  long before = 0, total = 0;
  MPI_Exscan(&count, &before, 1, MPI_LONG, MPI_SUM, comm);
  if (rank == 0) before = 0;
  MPI_Allreduce(&count, &total, 1, MPI_LONG, MPI_SUM, comm);
  std::vector<long> rank_in_block(block.size(), -1);
  for (size_t i = 0; i < block.size(); ++i)
    if (block[i]) rank_in_block[i] = before++;
  // Each row asks its block's rank (rows ascending: each rank's answers come in order).
  auto block_of = [&](Index row) {
    return static_cast<int>(std::upper_bound(first.begin(), first.end(), static_cast<std::size_t>(row)) - first.begin()) - 1;
  };
  std::vector<std::vector<std::int64_t>> ask(ranks);
  for (const Index row : rows) ask[block_of(row)].push_back(row);
  std::vector<std::vector<std::int64_t>> answer(ranks);
  const std::vector<std::vector<std::int64_t>> asked = alltoall_lists(ask, MPI_INT64_T, comm);
  for (int r = 0; r < ranks; ++r)
    for (const std::int64_t row : asked[r]) {
      const auto i = static_cast<std::size_t>(row) - first[rank];
      answer[r].push_back(block[i] ? rank_in_block[i] * 256 + block[i] : 0);
    }
  const std::vector<std::vector<std::int64_t>> answered = alltoall_lists(answer, MPI_INT64_T, comm);
  PartBcRows out;
  out.whole_bc_nodes = static_cast<Index>(total);
  std::vector<size_t> next(ranks, 0);
  for (const Index row : rows) {
    const int r = block_of(row);
    const std::int64_t a = answered[r][next[r]++];
    out.mask.push_back(static_cast<std::uint8_t>(a % 256));
    if (a % 256) out.bc_rows.push_back(static_cast<Index>(a / 256));
  }
  return out;
}

PartFacets part_facets(std::span<const GlobalId> facet_block, std::size_t facets,
                       std::span<const GlobalId> cohesive_block, std::size_t cohesive,
                       std::span<const GlobalId> elements, MPI_Comm comm) {
  const int ranks = comm_size(comm), rank = comm_rank(comm);
  const std::size_t facet_first = block_firsts(facets, ranks)[rank];
  const std::size_t cohesive_first = block_firsts(cohesive, ranks)[rank];
  // Every block's range of gids (the blocks follow each other in gid order).
  const std::int64_t mine[2] = {facet_block.empty() ? -1 : facet_block.front(),
                                facet_block.empty() ? -1 : facet_block.back()};
  std::vector<std::int64_t> range(2 * ranks);
  MPI_Allgather(mine, 2, MPI_INT64_T, range.data(), 2, MPI_INT64_T, comm);
  std::vector<int> held;  // the ranks whose blocks hold a facet, in gid order
  for (int r = 0; r < ranks; ++r)
    if (range[2 * r] >= 0) held.push_back(r);
  // The first of those whose block ends at or after gid.
  auto from = [&](GlobalId gid) {
    return std::partition_point(held.begin(), held.end(), [&](int r) { return range[2 * r + 1] < gid; });
  };
  // Each cohesive element to the rank whose block holds its facet.
  std::vector<std::vector<std::int64_t>> to(ranks);
  std::string error;
  for (size_t i = 0; i < cohesive_block.size(); ++i) {
    const auto at = from(cohesive_block[i]);
    if (at == held.end() || range[2 * *at] > cohesive_block[i]) {
      error = "/fracture/cohesive_facet names facet " + std::to_string(cohesive_block[i]) +
              ", which /fracture/facet_gid does not list (corrupted checkpoint?)";
      continue;
    }
    to[*at].insert(to[*at].end(), {cohesive_block[i], static_cast<std::int64_t>(cohesive_first + i)});
  }
  std::vector<std::int64_t> cohesive_of(facet_block.size(), -1);
  for (const std::vector<std::int64_t>& list : alltoall_lists(to, MPI_INT64_T, comm))
    for (size_t k = 0; k < list.size(); k += 2) {
      const auto at = std::lower_bound(facet_block.begin(), facet_block.end(), list[k]);
      if (at == facet_block.end() || *at != list[k]) {
        error = "/fracture/cohesive_facet names facet " + std::to_string(list[k]) +
                ", which /fracture/facet_gid does not list (corrupted checkpoint?)";
        continue;
      }
      cohesive_of[at - facet_block.begin()] = list[k + 1];
    }
  // Each element asks the blocks that may hold its facets, gids 4 g .. 4 g + 3.
  std::vector<std::vector<std::int64_t>> ask(ranks);
  for (const GlobalId g : elements)
    for (auto at = from(4 * g); at != held.end() && range[2 * *at] <= 4 * g + 3; ++at) ask[*at].push_back(g);
  std::vector<std::vector<std::int64_t>> answer(ranks);
  const std::vector<std::vector<std::int64_t>> asked = alltoall_lists(ask, MPI_INT64_T, comm);
  for (int r = 0; r < ranks; ++r)
    for (const std::int64_t g : asked[r])
      for (auto at = std::lower_bound(facet_block.begin(), facet_block.end(), 4 * g);
           at != facet_block.end() && *at < 4 * g + 4; ++at) {
        const auto i = at - facet_block.begin();
        answer[r].insert(answer[r].end(), {static_cast<std::int64_t>(facet_first + i), *at, cohesive_of[i]});
      }
  std::vector<std::array<std::int64_t, 3>> found;
  for (const std::vector<std::int64_t>& list : alltoall_lists(answer, MPI_INT64_T, comm))
    for (size_t k = 0; k < list.size(); k += 3) found.push_back({list[k], list[k + 1], list[k + 2]});
  std::sort(found.begin(), found.end());
  PartFacets out;
  std::vector<std::array<std::int64_t, 2>> by_cohesive;
  for (const auto& [row, gid, c] : found) {
    out.facet_rows.push_back(static_cast<Index>(row));
    out.facet_gid.push_back(gid);
    if (c >= 0) by_cohesive.push_back({c, gid});
  }
  std::sort(by_cohesive.begin(), by_cohesive.end());
  for (const auto& [c, gid] : by_cohesive) {
    out.cohesive_rows.push_back(static_cast<Index>(c));
    out.cohesive_gid.push_back(gid);
  }
  out.error = error;
  return out;
}

}  // namespace shatter
