// Strength scatter: the draws are uniform and depend only on (seed, facet
// gid); the Weibull and uniform strengths have the stated mean, range and
// size scaling; a facet's strength does not depend on the order of the
// elements (so not on the decomposition), and the criterion and the law use it.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "expect_close.hpp"
#include "fracture/cohesive_elements.hpp"
#include "fracture/strength_scatter.hpp"
#include "fracture_fixtures.hpp"

using namespace shatter;

namespace {

constexpr int kDraws = 200000;

StrengthScatter weibull(double m) {
  StrengthScatter s;
  s.modulus = m;
  s.seed = 7;
  return s;
}

}  // namespace

TEST(StrengthScatter, DrawsAreUniformAndPerFacet) {
  double sum = 0, sum2 = 0, lo = 1, hi = 0;
  for (GlobalId g = 0; g < kDraws; ++g) {
    const double u = facet_uniform(3, g);
    ASSERT_GT(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  // Mean 1/2 and variance 1/12 within 5 standard errors of the sample.
  const double mean = sum / kDraws, var = sum2 / kDraws - mean * mean;
  EXPECT_NEAR(mean, 0.5, 5 * std::sqrt(1.0 / 12 / kDraws));
  EXPECT_NEAR(var, 1.0 / 12, 5 * std::sqrt(1.0 / 180 / kDraws));
  EXPECT_LT(lo, 1e-4);
  EXPECT_GT(hi, 1 - 1e-4);
  // A pure function of (seed, gid).
  EXPECT_EQ(facet_uniform(3, 12345), facet_uniform(3, 12345));
  EXPECT_NE(facet_uniform(3, 12345), facet_uniform(4, 12345));
  EXPECT_NE(facet_uniform(3, 12345), facet_uniform(3, 12346));
}

TEST(StrengthScatter, WeibullMeanAndSizeScaling) {
  const double sigma_c = 300e6;
  for (double m : {3.0, 10.0}) {
    const StrengthScatter s = weibull(m);
    // Facets of the reference area: mean strength sigma_c, standard
    // deviation sigma_c sqrt(Gamma(1 + 2/m) / Gamma(1 + 1/m)^2 - 1).
    double sum = 0;
    for (GlobalId g = 0; g < kDraws; ++g)
      sum += scattered_strength(s, sigma_c, s.reference_area, facet_uniform(s.seed, g));
    const double cv = std::sqrt(std::tgamma(1 + 2 / m) / std::pow(std::tgamma(1 + 1 / m), 2) - 1);
    EXPECT_NEAR(sum / kDraws, sigma_c, 5 * cv * sigma_c / std::sqrt(kDraws)) << "m " << m;
    // Weakest link: 2^m times the area, half the strength for the same draw.
    for (double u : {0.01, 0.5, 0.99})
      EXPECT_CLOSE(scattered_strength(s, sigma_c, std::pow(2.0, m) * s.reference_area, u),
                   0.5 * scattered_strength(s, sigma_c, s.reference_area, u), 1e-14, 0);
    // The median draw: sigma_0 (ln 2)^(1/m).
    EXPECT_CLOSE(scattered_strength(s, sigma_c, s.reference_area, 0.5),
                 sigma_c / std::tgamma(1 + 1 / m) * std::pow(std::log(2.0), 1 / m), 1e-14, 0);
  }
}

TEST(StrengthScatter, UniformRangeAndMean) {
  StrengthScatter s;
  s.distribution = ScatterDistribution::uniform;
  s.spread = 0.2;
  const double sigma_c = 3e6;
  double sum = 0;
  for (GlobalId g = 0; g < kDraws; ++g) {
    const double v = scattered_strength(s, sigma_c, 1.0, facet_uniform(s.seed, g));
    ASSERT_GE(v, 0.8 * sigma_c);
    ASSERT_LE(v, 1.2 * sigma_c);
    sum += v;
  }
  EXPECT_NEAR(sum / kDraws, sigma_c, 5 * 0.2 * sigma_c / std::sqrt(3.0 * kDraws));
}

TEST(StrengthScatter, FacetStrengthIsTheSameForAnyElementOrder) {
  const Mesh a = test::box_mesh(0.25, 1);
  // The same elements listed backwards (as another rank or decomposition
  // would hold them): other local facet ids, same global ids.
  Mesh b = a;
  const Index ne = a.num_elements();
  for (Index e = 0; e < ne; ++e) {
    std::copy(a.element(ne - 1 - e), a.element(ne - 1 - e) + 4, b.conn.begin() + 4 * e);
    b.elem_gid[e] = a.elem_gid[ne - 1 - e];
    b.elem_body[e] = a.elem_body[ne - 1 - e];
    b.elem_material[e] = a.elem_material[ne - 1 - e];
  }
  b.build_node_elements();
  const auto laws = test::one_law(make_cohesive_law(3e6, 40.0, 1.0, 1e12));
  const std::vector<std::optional<StrengthScatter>> scatter = {weibull(5.0)};
  std::map<GlobalId, double> by_gid;
  const Topology ta = build_topology(a), tb = build_topology(b);
  const std::vector<double> sa = facet_strengths(a, ta, laws, scatter);
  const std::vector<double> sb = facet_strengths(b, tb, laws, scatter);
  Index interior = 0;
  for (Index f = 0; f < ta.num_facets(); ++f) {
    by_gid[ta.facet_gid[f]] = sa[f];
    interior += ta.is_interior(f);
    EXPECT_EQ(std::isinf(sa[f]), !ta.is_interior(f));  // boundary facets never break
  }
  ASSERT_GT(interior, 100);
  ASSERT_EQ(tb.num_facets(), ta.num_facets());
  Index moved = 0;
  for (Index f = 0; f < tb.num_facets(); ++f) {
    EXPECT_EQ(sb[f], by_gid.at(tb.facet_gid[f]));
    moved += ta.facet_elem[f][0] != tb.facet_elem[f][0];
  }
  EXPECT_GT(moved, 0);  // the facets' local elements did change

  // The law of a facet is its own: strength scattered, Gc kept.
  const FractureLaws fl(laws, sa, *std::min_element(sa.begin(), sa.end()));
  for (Index f = 0; f < ta.num_facets(); ++f)
    if (ta.is_interior(f)) {
      const CohesiveLaw law = *facet_law(a, ta, fl, f);
      EXPECT_EQ(law.sigma_c, sa[f]);
      EXPECT_CLOSE(law.fracture_energy(), 40.0, 1e-14, 0);
    }
}
