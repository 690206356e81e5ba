#include "fracture/facet_criterion.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "kernels/error.hpp"

namespace shatter {

std::optional<CohesiveLaw> facet_law(const Mesh& mesh, const Topology& topo, FractureLaws laws, Index f) {
  const auto [e0, e1] = topo.facet_elem[f];
  if (e1 < 0) return std::nullopt;
  const std::optional<CohesiveLaw>& l0 = laws.material[mesh.elem_material[e0]];
  const std::optional<CohesiveLaw>& l1 = laws.material[mesh.elem_material[e1]];
  if (!l0 || !l1) return std::nullopt;
  return laws.facet_strength.empty() ? *l0 : with_strength(*l0, laws.facet_strength[f]);
}

Mat3 element_cauchy_stress(std::span<const double> stress, int stress_size, Index e) {
  const double* s = stress.data() + static_cast<size_t>(e) * stress_size;
  Mat3 sigma;
  if (stress_size == 6)
    sigma << s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2];
  else
    sigma << s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8];
  return sigma;
}

std::vector<Index> critical_facets(const Mesh& mesh, const Topology& topo, std::span<const Vec3> x,
                                   std::span<const double> stress, int stress_size, FractureLaws laws,
                                   std::span<const Index> local, std::span<const Index> owned) {
  SHATTER_REQUIRE(stress_size == 6 || stress_size == 9,
                  "critical_facets: stress_size must be 6 or 9, got " << stress_size);
  SHATTER_REQUIRE(stress.size() >= static_cast<size_t>(mesh.num_elements()) * stress_size,
                  "critical_facets: " << stress.size() << " stress values for "
                                      << mesh.num_elements() << " elements");
  const Index ne = mesh.num_elements();
  double weakest = HUGE_VAL, widest = 1.0;  // smallest sigma_c, largest max(1, 1/beta)
  for (const auto& law : laws.material)
    if (law) {
      weakest = std::min(weakest, law->sigma_c);
      widest = std::max(widest, 1.0 / law->beta);
    }
  if (weakest == HUGE_VAL) return {};
  if (!laws.facet_strength.empty()) weakest = laws.weakest_facet;
  // A cheap exact bound: the effective traction on any plane is at most
  // |t| max(1, 1/beta) <= |sigma|_F max(1, 1/beta), and the facet's stress is
  // the mean of its two elements', so a facet can break only if
  // (|sigma_0|_F + |sigma_1|_F) / 2 x max(1, 1/beta) >= sigma_c, hence only
  // if one of its elements is "hot": |sigma_e|_F max(1, 1/beta) >= sigma_c.
  // Pass 1 computes the norms (one contiguous, vectorisable sweep); pass 2
  // visits the facets of hot elements only. The factor 1 + 1e-12 keeps the
  // bound safe against the round-off of the norms. Both passes cover the
  // local elements (all on one rank).
  constexpr double kSafe = 1.0 + 1e-12;
  const bool all = local.empty();
  const Index nlocal = all ? ne : static_cast<Index>(local.size());
  auto elem = [&](Index k) { return all ? k : local[k]; };
  auto is_owned = [&](Index e) { return owned.empty() || std::binary_search(owned.begin(), owned.end(), e); };
  std::unique_ptr<double[]> frobenius(new double[ne]);  // set for the local elements
  const double* s = stress.data();
  tbb::parallel_for(tbb::blocked_range<Index>(0, nlocal, 4096), [&](const tbb::blocked_range<Index>& r) {
    if (stress_size == 6) {
      for (Index k = r.begin(); k != r.end(); ++k) {
        const double* v = s + 6 * static_cast<size_t>(elem(k));
        frobenius[elem(k)] = kSafe * std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] +
                                               2.0 * (v[3] * v[3] + v[4] * v[4] + v[5] * v[5]));
      }
    } else {
      for (Index k = r.begin(); k != r.end(); ++k) {
        const double* v = s + 9 * static_cast<size_t>(elem(k));
        double sum = 0;
        for (int i = 0; i < 9; ++i) sum += v[i] * v[i];
        frobenius[elem(k)] = kSafe * std::sqrt(sum);
      }
    }
  });
  const double hot = weakest / widest;
  // Each facet is evaluated once, from the hot adjacent element of smaller
  // local id; facets found by any thread are gathered and sorted by global
  // id, so the result does not depend on the threads.
  tbb::enumerable_thread_specific<std::vector<Index>> found;
  tbb::parallel_for(tbb::blocked_range<Index>(0, nlocal, 1024), [&](const tbb::blocked_range<Index>& r) {
    std::vector<Index>* local_found = nullptr;
    for (Index k = r.begin(); k != r.end(); ++k) {
      const Index e = elem(k);
      if (frobenius[e] < hot) continue;
      for (int i = 0; i < 4; ++i) {
        const Index f = topo.elem_facet[4 * static_cast<size_t>(e) + i];
        if (topo.facet_state[f] != FacetState::intact) continue;  // boundary, cohesive or free
        const auto [e0, e1] = topo.facet_elem[f];
        const Index other = e0 == e ? e1 : e0;
        // The owner of the smaller element checks the facet (then both are local).
        if (!is_owned(std::min(e, other))) continue;
        if (other < e && frobenius[other] >= hot) continue;  // evaluated from `other`
        const std::optional<CohesiveLaw> law = facet_law(mesh, topo, laws, f);
        if (!law) continue;
        const double wide = std::max(1.0, 1.0 / law->beta);
        if (0.5 * (frobenius[e0] + frobenius[e1]) * wide < law->sigma_c) continue;
        const std::array<Index, 6> fn = face_nodes(mesh, e0, topo.facet_face[f][0]);
        const Vec3 n = (x[fn[1]] - x[fn[0]]).cross(x[fn[2]] - x[fn[0]]).normalized();
        const Mat3 sigma = 0.5 * (element_cauchy_stress(stress, stress_size, e0) +
                                  element_cauchy_stress(stress, stress_size, e1));
        if (facet_effective_traction(sigma, n, law->beta) >= law->sigma_c) {
          if (!local_found) local_found = &found.local();
          local_found->push_back(f);
        }
      }
    }
  });
  std::vector<Index> out;
  for (const std::vector<Index>& v : found) out.insert(out.end(), v.begin(), v.end());
  std::sort(out.begin(), out.end(),
            [&](Index a, Index b) { return topo.facet_gid[a] < topo.facet_gid[b]; });
  return out;
}

}  // namespace shatter
