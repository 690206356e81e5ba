// critical_facets (screened over the facets, tractions 8 at a time) finds
// exactly the facets of the criterion evaluated one by one with facet_law and
// the Eigen form, on a body of two materials (one that does not fracture, or
// one with another strength and beta), with and without strength scatter,
// with Voigt (6) and full (9) stresses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "fracture/facet_criterion.hpp"
#include "fracture_fixtures.hpp"

using namespace shatter;

namespace {

// Global ids of the intact facets whose traction reaches their law's strength, one by one.
std::vector<GlobalId> direct_criterion(const Mesh& m, const Topology& t, const std::vector<double>& stress, int size,
                                       FractureLaws laws) {
  std::vector<GlobalId> out;
  for (Index f = 0; f < t.num_facets(); ++f) {
    if (t.facet_state[f] != FacetState::intact) continue;
    const std::optional<CohesiveLaw> law = facet_law(m, t, laws, f);
    if (!law) continue;
    const auto [e0, e1] = t.facet_elem[f];
    const auto fn = face_nodes(m, e0, t.facet_face[f][0]);
    const Vec3 n =
        (m.reference[fn[1]] - m.reference[fn[0]]).cross(m.reference[fn[2]] - m.reference[fn[0]]).normalized();
    const Mat3 sigma =
        0.5 * (element_cauchy_stress(stress, size, e0) + element_cauchy_stress(stress, size, e1));
    if (facet_effective_traction(sigma, n, law->beta) >= law->sigma_c) out.push_back(t.facet_gid[f]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(FacetCriterion, TwoMaterialsAndScatterAsTheCriterionFacetByFacet) {
  Mesh m = test::box_mesh(0.1, 1);
  for (Index e = 0; e < m.num_elements(); ++e)  // material 1 where x < 0.35, across the stress peak
    m.elem_material[e] = m.reference[m.element(e)[0]].x() < 0.35 ? 1 : 0;
  const Topology t = build_topology(m);
  // A smooth field plus noise (many facets near their strength), symmetric.
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.2e6);
  std::vector<double> voigt(6 * static_cast<size_t>(m.num_elements()));
  std::vector<double> full(9 * static_cast<size_t>(m.num_elements()));
  for (Index e = 0; e < m.num_elements(); ++e) {
    const Vec3 X = m.reference[m.element(e)[0]];
    const double s = 0.9e6 * (1 + std::sin(7 * X.x()) * std::cos(5 * X.y()));
    for (int i = 0; i < 6; ++i) voigt[6 * e + i] = (i < 3 ? s : 0.3 * s) + noise(rng);
    const Mat3 sigma = element_cauchy_stress(voigt, 6, e);
    for (int q = 0; q < 9; ++q) full[9 * e + q] = sigma(q / 3, q % 3);
  }
  // Strength scatter: each facet its own sigma_c within +-20 %.
  std::uniform_real_distribution<double> spread(0.8, 1.2);
  std::vector<double> strength(t.num_facets());
  for (double& s : strength) s = 1.0e6 * spread(rng);
  const double weakest = *std::min_element(strength.begin(), strength.end());

  const CohesiveLaw brittle = make_cohesive_law(1.0e6, 50.0, 0.8, 1.0e12);
  const CohesiveLaw other = make_cohesive_law(1.3e6, 80.0, 1.7, 1.0e12);
  const std::vector<std::vector<std::optional<CohesiveLaw>>> cases = {{brittle, std::nullopt}, {brittle, other}};
  for (const auto& materials : cases)
    for (const bool scatter : {false, true}) {
      const FractureLaws laws = scatter ? FractureLaws(materials, strength, weakest) : FractureLaws(materials);
      for (const int size : {6, 9}) {
        const std::vector<double>& stress = size == 6 ? voigt : full;
        std::vector<GlobalId> found;
        for (const Index f : critical_facets(m, t, m.reference, stress, size, laws)) found.push_back(t.facet_gid[f]);
        const std::vector<GlobalId> direct = direct_criterion(m, t, stress, size, laws);
        EXPECT_GT(direct.size(), 20u) << "second material " << (materials[1] ? "fractures" : "does not");
        // Both materials' facets break (the second's too when it fractures).
        const bool second = std::any_of(direct.begin(), direct.end(), [&](GlobalId g) {
          const Index f = static_cast<Index>(std::find(t.facet_gid.begin(), t.facet_gid.end(), g) - t.facet_gid.begin());
          return m.elem_material[t.facet_elem[f][0]] == 1 || m.elem_material[t.facet_elem[f][1]] == 1;
        });
        EXPECT_EQ(second, materials[1].has_value());
        EXPECT_LT(direct.size(), static_cast<size_t>(t.num_facets()) / 2);
        EXPECT_TRUE(std::is_sorted(found.begin(), found.end()));
        EXPECT_EQ(found, direct) << "second material " << (materials[1] ? "fractures" : "does not")
                                 << ", scatter " << scatter << ", " << size << " components";
      }
    }
}
