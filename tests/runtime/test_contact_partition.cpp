// The contact partition's numbering of its parts (runtime/contact_partition.hpp):
// align_parts on its own, and ContactPartition at 1, 2 and 3 ranks handing each
// RCB part to the rank where its objects' volume nodes are (their homes).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "mpi_environment.hpp"
#include "runtime/contact_partition.hpp"

namespace shatter {
namespace {

TEST(AlignParts, EachPartGoesWhereMostOfItsObjectsAreAtHome) {
  // Parts 0 and 1 swapped with respect to the ranks, part 2 kept.
  const std::vector<int> rank_of =
      align_parts(3, {{0, 1, 100}, {0, 0, 5}, {1, 0, 90}, {1, 2, 7}, {2, 2, 50}, {2, 1, 40}});
  EXPECT_EQ(rank_of, (std::vector<int>{1, 0, 2}));
}

TEST(AlignParts, EntriesOfSeveralRanksAreSummedInAnyOrder) {
  // Part 0: 60 objects at home on rank 0 in two entries, 50 on rank 1 in one.
  std::vector<std::array<long, 3>> overlap{{0, 0, 30}, {0, 1, 50}, {0, 0, 30}, {1, 1, 10}, {1, 0, 5}};
  const std::vector<int> expected{0, 1};
  EXPECT_EQ(align_parts(2, overlap), expected);
  std::mt19937 shuffle(7);
  for (int k = 0; k < 10; ++k) {
    std::shuffle(overlap.begin(), overlap.end(), shuffle);
    EXPECT_EQ(align_parts(2, overlap), expected);
  }
}

TEST(AlignParts, PartsWithoutAFreeHomeTakeTheRanksLeftInOrder) {
  // Both parts are at home on rank 2 only: the larger takes it, the other and the empty
  // part take ranks 0 and 1 in ascending order. Ties go to the lower part.
  EXPECT_EQ(align_parts(3, {{0, 2, 10}, {2, 2, 20}}), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(align_parts(3, {{1, 2, 20}, {2, 2, 10}}), (std::vector<int>{0, 2, 1}));
  EXPECT_EQ(align_parts(2, {{0, 1, 10}, {1, 1, 10}}), (std::vector<int>{1, 0}));
}

TEST(ContactPartition, PartsGoToTheRanksWhereTheirObjectsAreAtHome) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  // 300 objects per rank, scattered over the ranks along the x axis in [0, 1), so that RCB
  // cuts it into slabs; an object's home is the rank of its slab counted from the right,
  // so RCB's own numbering (from the left) would put most of them away from home.
  constexpr int kPerRank = 300;
  const int total = kPerRank * ranks;
  std::vector<Index> names;
  std::vector<Vec3> points;
  std::vector<float> weights;
  std::vector<int> homes;
  for (int k = 0; k < kPerRank; ++k) {
    const int g = rank * kPerRank + k;
    const double x = (static_cast<long>(g) * 7919 % total + 0.5) / total;
    names.insert(names.end(), {0, g, 0, 0});
    points.push_back(Vec3(x, 0.0, 0.0));
    weights.insert(weights.end(), {1.0f, 1.0f});
    homes.push_back(ranks - 1 - std::min(ranks - 1, static_cast<int>(x * ranks)));
  }
  ContactPartition partition(MPI_COMM_WORLD);
  const std::vector<int> to = partition.partition(names, points, weights, homes);
  ASSERT_EQ(to.size(), points.size());
  long at_home = 0, counts[2];
  for (size_t k = 0; k < to.size(); ++k) at_home += to[k] == homes[k];
  counts[0] = at_home, counts[1] = static_cast<long>(to.size());
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  // RCB cuts within its tolerance of the slabs' ends: a few objects per cut may stray.
  EXPECT_GE(counts[0], counts[1] - 10L * (ranks - 1)) << counts[0] << " of " << counts[1] << " at home";
}

}  // namespace
}  // namespace shatter
