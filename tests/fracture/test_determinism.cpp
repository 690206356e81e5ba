// Determinism: the facet check and the cohesive forces give identical results
// for 1, 2 and 4 threads (the forces: those of a serial scatter in element
// order), and the facet check split among owners of the
// elements finds the same facets.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "fracture/cohesive_elements.hpp"
#include "fracture_fixtures.hpp"

using namespace shatter;

TEST(Determinism, FacetCheckAndCohesiveForcesForAnyThreadCount) {
  // Allow 4 threads even on a smaller machine (oversubscription is fine here).
  tbb::global_control allow(tbb::global_control::max_allowed_parallelism, 4);
  Mesh m = test::box_mesh(0.1, 1);
  Topology t = build_topology(m);
  const CohesiveLaw law = make_cohesive_law(1.0e6, 50.0, 0.8, 1.0e12);
  const auto laws = test::one_law(law);
  // A smooth stress field plus noise, in Voigt layout, so that a fraction of
  // the facets is critical and many sit close to the threshold.
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.2e6);
  std::vector<double> stress(6 * m.num_elements());
  for (Index e = 0; e < m.num_elements(); ++e) {
    const Vec3 X = m.reference[m.element(e)[0]];
    const double s = 0.9e6 * (1 + std::sin(7 * X.x()) * std::cos(5 * X.y()));
    for (int i = 0; i < 6; ++i) stress[6 * e + i] = (i < 3 ? s : 0.3 * s) + noise(rng);
  }
  std::vector<Index> reference_facets;
  for (int threads : {1, 2, 4}) {
    tbb::task_arena arena(threads);
    const std::vector<Index> facets =
        arena.execute([&] { return critical_facets(m, t, m.reference, stress, 6, laws); });
    if (threads == 1) {
      reference_facets = facets;
      EXPECT_GT(facets.size(), 50u);
      EXPECT_LT(facets.size(), static_cast<size_t>(t.num_facets()));
      for (size_t i = 1; i < facets.size(); ++i)
        EXPECT_LT(t.facet_gid[facets[i - 1]], t.facet_gid[facets[i]]);
      // The same set as a direct serial evaluation of the criterion.
      std::vector<GlobalId> direct, found;
      for (Index f = 0; f < t.num_facets(); ++f) {
        if (!t.is_interior(f)) continue;
        const auto [e0, e1] = t.facet_elem[f];
        const auto fn = face_nodes(m, e0, t.facet_face[f][0]);
        const Vec3 n = (m.reference[fn[1]] - m.reference[fn[0]])
                           .cross(m.reference[fn[2]] - m.reference[fn[0]])
                           .normalized();
        const Mat3 sigma =
            0.5 * (element_cauchy_stress(stress, 6, e0) + element_cauchy_stress(stress, 6, e1));
        if (facet_effective_traction(sigma, n, law.beta) >= law.sigma_c)
          direct.push_back(t.facet_gid[f]);
      }
      for (const Index f : facets) found.push_back(t.facet_gid[f]);
      std::sort(direct.begin(), direct.end());
      EXPECT_EQ(found, direct);
      // Split among 3 owners as ranks split the elements (interleaved runs
      // of 37): each facet is found by the owner of its smaller element, and
      // the owners' lists together are the whole list.
      std::vector<Index> joined;
      for (int part = 0; part < 3; ++part) {
        std::vector<Index> owned, local;
        for (Index e = 0; e < m.num_elements(); ++e)
          if ((e / 37) % 3 == part) owned.push_back(e);
        // The owned elements and their facet neighbours; the others' stresses spoiled.
        std::vector<char> near(m.num_elements(), 0);
        for (Index e : owned)
          for (int i = 0; i < 4; ++i) {
            const auto fe = t.facet_elem[t.elem_facet[4 * e + i]];
            near[fe[0]] = 1;
            if (fe[1] >= 0) near[fe[1]] = 1;
          }
        std::vector<double> spoiled = stress;
        for (Index e = 0; e < m.num_elements(); ++e)
          if (near[e]) local.push_back(e);
          else for (int c = 0; c < 6; ++c) spoiled[6 * e + c] = 1e30;
        const std::vector<Index> mine = critical_facets(m, t, m.reference, spoiled, 6, laws, local, owned);
        for (const Index f : mine)
          EXPECT_TRUE(std::binary_search(owned.begin(), owned.end(), std::min(t.facet_elem[f][0], t.facet_elem[f][1])));
        joined.insert(joined.end(), mine.begin(), mine.end());
      }
      std::sort(joined.begin(), joined.end(), [&](Index a, Index b) { return t.facet_gid[a] < t.facet_gid[b]; });
      EXPECT_EQ(joined, facets);
    } else {
      EXPECT_EQ(facets, reference_facets) << threads << " threads";
    }
  }

  CohesiveElements coh;
  const Insertion ins = insert_cohesive_elements(m, t, coh, reference_facets);
  std::vector<Vec3> x(m.num_nodes());
  std::uniform_real_distribution<double> u(-1e-5, 1e-5);
  for (Index n = 0; n < m.num_nodes(); ++n) x[n] = m.reference[n] + Vec3(u(rng), u(rng), u(rng));
  std::vector<Vec3> reference_force;
  CohesiveEnergy reference_energy;
  for (int threads : {1, 2, 4}) {
    CohesiveElements state = coh;
    std::vector<Vec3> f(m.num_nodes(), Vec3::Zero());
    tbb::task_arena arena(threads);
    const CohesiveEnergy energy =
        arena.execute([&] { return cohesive_forces(m, t, state, laws, x, f); });
    if (threads == 1) {
      reference_force = f;
      reference_energy = energy;
      EXPECT_GT(energy.dissipated.value(), 0.0);
    } else {
      EXPECT_TRUE(f == reference_force) << threads << " threads";  // bitwise
      EXPECT_EQ(energy.stored.value(), reference_energy.stored.value());
      EXPECT_EQ(energy.dissipated.value(), reference_energy.dissipated.value());
    }
  }
  // The parallel scatter adds to every node in the order of a serial loop
  // over the elements: the same bits as adding the elements one at a time.
  ASSERT_GT(coh.size(), 4 * 64);  // enough for 4 node ranges in one block
  std::vector<Vec3> serial(m.num_nodes(), Vec3::Zero());
  for (Index c = 0; c < coh.size(); ++c) {
    CohesiveElements one;
    one.facet = {coh.facet[c]};
    const size_t slots = 12 * static_cast<size_t>(c);  // 2 sides x 6 slots
    one.side_local.assign(coh.side_local.begin() + slots, coh.side_local.begin() + slots + 12);
    one.side_nodes.assign(coh.side_nodes.begin() + slots, coh.side_nodes.begin() + slots + 12);
    one.area = {coh.area[c]};
    one.normal = {coh.normal[c]};
    one.delta_max.assign(coh.delta_max.begin() + kCohesivePoints * c,
                         coh.delta_max.begin() + kCohesivePoints * (c + 1));
    cohesive_forces(m, t, one, laws, x, serial);
  }
  EXPECT_TRUE(serial == reference_force);  // bitwise
  EXPECT_GT(ins.new_nodes.size(), 0u);
}
