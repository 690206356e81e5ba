// The rows a part finds with the other ranks at a restart (runtime/restart_rows.hpp),
// at any rank count (ctest runs it at 1, 2 and 3 ranks): every rank knows the
// whole datasets here, passes only its block, and must get exactly what a scan
// of the whole would give it: its rows' masks and prescribed ranks, its
// elements' facets and their cohesive elements, in row order; a cohesive
// element whose facet is not listed is reported.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "mpi_environment.hpp"
#include "runtime/restart_rows.hpp"

namespace shatter {
namespace {

struct Ranks {
  int rank = 0, size = 1;
  Ranks() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
  }
};

template <class T>
std::vector<T> block_of(const std::vector<T>& whole, const Ranks& r) {
  const std::vector<std::size_t> first = block_firsts(whole.size(), r.size);
  return {whole.begin() + static_cast<std::ptrdiff_t>(first[r.rank]),
          whole.begin() + static_cast<std::ptrdiff_t>(first[r.rank + 1])};
}

void check_bc_rows(std::size_t n) {
  const Ranks r;
  std::mt19937 random(17);
  std::vector<std::uint8_t> mask(n);
  for (auto& m : mask) m = random() % 3 == 0 ? static_cast<std::uint8_t>(1 + random() % 7) : 0;
  // Each rank holds an overlapping, rank-dependent set of rows.
  std::vector<Index> rows;
  for (Index i = 0; i < static_cast<Index>(n); ++i)
    if ((i * 7 + r.rank) % 4 != 0) rows.push_back(i);
  const PartBcRows got = part_bc_rows(block_of(mask, r), n, rows, MPI_COMM_WORLD);
  std::vector<std::uint8_t> want_mask;
  std::vector<Index> want_bc;
  Index before = 0;
  for (Index i = 0, k = 0; i < static_cast<Index>(n); ++i) {
    if (k < static_cast<Index>(rows.size()) && rows[k] == i) {
      want_mask.push_back(mask[i]);
      if (mask[i]) want_bc.push_back(before);
      ++k;
    }
    before += mask[i] != 0;
  }
  EXPECT_EQ(got.mask, want_mask) << n << " rows";
  EXPECT_EQ(got.bc_rows, want_bc) << n << " rows";
  EXPECT_EQ(got.whole_bc_nodes, before) << n << " rows";
}

TEST(RestartRows, PrescribedRanksAsFromTheWholeMask) {
  check_bc_rows(1000);
  check_bc_rows(2);  // fewer rows than ranks at 3: a rank with an empty block
}

TEST(RestartRows, FacetsOfThePartsElementsAsFromTheWholeLists) {
  const Ranks r;
  std::mt19937 random(5);
  // Facets 4 g + face of elements g = 3, 5, ..., sorted; some elements have several.
  std::vector<GlobalId> facets;
  for (GlobalId g = 3; g < 400; g += 2)
    for (int face = 0; face < 4; ++face)
      if (random() % 5 == 0) facets.push_back(4 * g + face);
  // One cohesive element per facet, in a shuffled order.
  std::vector<GlobalId> cohesive = facets;
  std::shuffle(cohesive.begin(), cohesive.end(), random);
  // The part's elements: a rank-dependent window of element gids, with facets or not.
  std::vector<GlobalId> elements;
  for (GlobalId g = 50 * r.rank; g < 50 * r.rank + 260; ++g) elements.push_back(g);
  const PartFacets got =
      part_facets(block_of(facets, r), facets.size(), block_of(cohesive, r), cohesive.size(), elements, MPI_COMM_WORLD);
  auto held = [&](GlobalId gid) { return std::binary_search(elements.begin(), elements.end(), gid / 4); };
  PartFacets want;
  for (size_t i = 0; i < facets.size(); ++i)
    if (held(facets[i])) want.facet_rows.push_back(static_cast<Index>(i)), want.facet_gid.push_back(facets[i]);
  for (size_t i = 0; i < cohesive.size(); ++i)
    if (held(cohesive[i])) want.cohesive_rows.push_back(static_cast<Index>(i)), want.cohesive_gid.push_back(cohesive[i]);
  ASSERT_FALSE(want.facet_rows.empty());
  EXPECT_EQ(got.facet_rows, want.facet_rows);
  EXPECT_EQ(got.facet_gid, want.facet_gid);
  EXPECT_EQ(got.cohesive_rows, want.cohesive_rows);
  EXPECT_EQ(got.cohesive_gid, want.cohesive_gid);
  EXPECT_TRUE(got.error.empty()) << got.error;
}

TEST(RestartRows, ACohesiveElementOfAnUnlistedFacetIsReported) {
  const Ranks r;
  std::vector<GlobalId> facets, cohesive;
  for (GlobalId g = 0; g < 60; ++g) facets.push_back(4 * g + 1);
  cohesive = facets;
  cohesive[37] = 4 * 100 + 2;  // no such facet
  std::vector<GlobalId> elements = {0, 1, 2};
  const PartFacets got =
      part_facets(block_of(facets, r), facets.size(), block_of(cohesive, r), cohesive.size(), elements, MPI_COMM_WORLD);
  int reported = got.error.find("402") != std::string::npos ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &reported, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(reported, 1) << "the rank whose block holds the cohesive element, or the facet's, reports it once";
}

}  // namespace
}  // namespace shatter
