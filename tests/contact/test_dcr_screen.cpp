// DCR's first-round screen (contact/dcr.hpp: DcrScratch::gaps and ::drift, pair_gaps,
// kGapDrift): a pair whose gap at the search exceeds kGapDrift x (d_A + d_B) fails
// pair_boxes_overlap for every motion that keeps each node within its drift d of its
// position at the search (max norm), at x_old and at x_new. Checked on random pairs at the
// bound itself with the extreme motions (every node at a corner of its drift cube), thick
// pairs included; and the bound's inflation term is needed: without it a pair the screen
// would skip overlaps.
#include <gtest/gtest.h>

#include <random>

#include "contact/dcr.hpp"

using namespace shatter;

namespace {

/// Positions of a pair's four nodes (nodes 0..3 of the arrays).
struct Motion {
  std::vector<Vec3> x_old, x_new;
};

bool overlap(const ContactPair& p, const Motion& m, double reach) {
  PairPoints X_old, X_new;
  for (int c = 0; c < 4; ++c) X_old.col(c) = m.x_old[p.nodes[c]], X_new.col(c) = m.x_new[p.nodes[c]];
  return pair_boxes_overlap(p.kind, X_old, X_new, reach);
}

}  // namespace

TEST(DcrScreen, PairsBeyondTheBoundFailTheBoxTestForEveryMotionWithinTheirDrifts) {
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), share(0.05, 1.0);
  std::bernoulli_distribution coin(0.5);
  long tested = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const bool vf = trial % 2 == 0;
    const ContactPair p{vf ? ContactPair::VertexFace : ContactPair::EdgeEdge, {0, 1, 2, 3}};
    const int first = vf ? 1 : 2;
    // Side A near the origin, side B shifted along a random axis; coordinates far from 0
    // on some trials (the slack's scale).
    const double size = std::pow(10.0, unit(rng) * 3), offset = trial % 7 == 0 ? 1e3 * size : 0.0;
    const int axis = static_cast<int>(rng() % 3);
    std::vector<Vec3> x(4);
    for (int i = 0; i < 4; ++i) {
      x[i] = Vec3(unit(rng), unit(rng), unit(rng)) * (0.3 * size) + Vec3::Constant(offset);
      if (i >= first) x[i][axis] += size * (1.0 + share(rng));
    }
    std::vector<double> reach(4, 0.0);
    if (trial % 3 == 0) reach = {0.05 * size, 0.05 * size, 0.02 * size, 0.02 * size};
    const DcrSurface surface{nullptr, nullptr, {}, trial % 3 == 0 ? std::span<const double>(reach) : std::span<const double>()};
    const double gap = pair_gaps(std::span<const ContactPair>(&p, 1), x, surface)[0];
    ASSERT_GT(gap, 0.0);
    const double h = pair_thickness(p, surface).reach;
    // Drifts in a random split, scaled so that the screen just skips the pair.
    std::vector<double> d(4);
    for (double& di : d) di = share(rng);
    double d_a = 0, d_b = 0;
    for (int i = 0; i < 4; ++i) (i < first ? d_a : d_b) = std::max(i < first ? d_a : d_b, d[i]);
    const double scale = gap / (kGapDrift * (d_a + d_b)) * (1.0 - 1e-12);
    for (double& di : d) di *= scale;
    ASSERT_GT(gap, kGapDrift * (d_a + d_b) * scale);
    // Motions: each node at corners of its drift cube at x_old and at x_new, random, and the
    // extreme one (side A toward B along the axis and spread, side B toward A and spread).
    for (int sample = 0; sample < 64; ++sample) {
      Motion m{std::vector<Vec3>(4), std::vector<Vec3>(4)};
      for (int i = 0; i < 4; ++i) {
        const double toward = i < first ? 1.0 : -1.0;
        for (int c = 0; c < 3; ++c) {
          const bool extreme = sample == 0;
          m.x_old[i][c] = x[i][c] + d[i] * (extreme ? (c == axis ? toward : -1.0) : (coin(rng) ? 1.0 : -1.0));
          m.x_new[i][c] = x[i][c] + d[i] * (extreme ? (c == axis ? toward : 1.0) : (coin(rng) ? 1.0 : -1.0));
        }
      }
      EXPECT_FALSE(overlap(p, m, h)) << "trial " << trial << ", sample " << sample << ": gap " << gap;
      ++tested;
    }
  }
  EXPECT_EQ(tested, 4000 * 64);
}

TEST(DcrScreen, TheBoundNeedsTheBoxesInflation) {
  // A vertex at the origin and a small triangle at x = g: the vertex sweeps [-d, d] along
  // x, the triangle [g - d, g + d]; each box grows by kBoxInflation x 2d, so they overlap
  // up to g = 2 d (1 + 2 kBoxInflation). A screen without the inflation term (2 d) would
  // skip g = 2 d (1 + kBoxInflation); kGapDrift does not.
  const double d = 0.01, g = 2.0 * d * (1.0 + kBoxInflation);
  const ContactPair p{ContactPair::VertexFace, {0, 1, 2, 3}};
  const std::vector<Vec3> x{Vec3::Zero(), Vec3(g, 0, 0), Vec3(g, 1e-9, 0), Vec3(g, 0, 1e-9)};
  const double gap = pair_gaps(std::span<const ContactPair>(&p, 1), x, DcrSurface{})[0];
  EXPECT_GT(gap, 2.0 * d * (1.0 + 1e-9));  // beyond a bound without the inflation
  EXPECT_LE(gap, kGapDrift * 2.0 * d);      // within kGapDrift's: checked, not skipped
  Motion m{{Vec3(-d, 0, 0), x[1] - Vec3(d, 0, 0), x[2] - Vec3(d, 0, 0), x[3] - Vec3(d, 0, 0)},
           {Vec3(d, 0, 0), x[1] + Vec3(d, 0, 0), x[2] + Vec3(d, 0, 0), x[3] + Vec3(d, 0, 0)}};
  EXPECT_TRUE(overlap(p, m, 0.0));
}
