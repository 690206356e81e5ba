#include "fracture/facet_criterion.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "kernels/error.hpp"

namespace shatter {

const CohesiveLaw* facet_law(const Mesh& mesh, const Topology& topo, FractureLaws laws, Index f) {
  const auto [e0, e1] = topo.facet_elem[f];
  if (e1 < 0) return nullptr;
  const std::optional<CohesiveLaw>& l0 = laws[mesh.elem_material[e0]];
  const std::optional<CohesiveLaw>& l1 = laws[mesh.elem_material[e1]];
  return l0 && l1 ? &*l0 : nullptr;
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
                                   std::span<const double> stress, int stress_size,
                                   FractureLaws laws) {
  SHATTER_REQUIRE(stress_size == 6 || stress_size == 9,
                  "critical_facets: stress_size must be 6 or 9, got " << stress_size);
  SHATTER_REQUIRE(stress.size() >= static_cast<size_t>(mesh.num_elements()) * stress_size,
                  "critical_facets: " << stress.size() << " stress values for "
                                      << mesh.num_elements() << " elements");
  const Index nf = topo.num_facets(), ne = mesh.num_elements();
  // A cheap exact filter: the effective traction on any plane is at most
  // |t| max(1, 1/beta) <= |sigma|_F max(1, 1/beta), and the facet's stress is
  // the mean of its two elements', so a facet with
  // (|sigma_0|_F + |sigma_1|_F) / 2 x max(1, 1/beta) < sigma_c cannot break.
  std::vector<double> frobenius(ne);
  tbb::parallel_for(tbb::blocked_range<Index>(0, ne, 2048), [&](const tbb::blocked_range<Index>& r) {
    for (Index e = r.begin(); e != r.end(); ++e) frobenius[e] = element_cauchy_stress(stress, stress_size, e).norm();
  });
  double weakest = HUGE_VAL, widest = 1.0;  // smallest sigma_c, largest max(1, 1/beta)
  for (const auto& law : laws)
    if (law) {
      weakest = std::min(weakest, law->sigma_c);
      widest = std::max(widest, 1.0 / law->beta);
    }
  if (*std::max_element(frobenius.begin(), frobenius.end()) * widest < weakest) return {};
  // One flag per facet, then a serial gather: the output is independent of
  // how the range is split among threads.
  std::vector<char> breaks(nf, 0);
  tbb::parallel_for(tbb::blocked_range<Index>(0, nf, 512), [&](const tbb::blocked_range<Index>& r) {
    for (Index f = r.begin(); f != r.end(); ++f) {
      if (topo.facet_state[f] != FacetState::intact) continue;
      const CohesiveLaw* law = facet_law(mesh, topo, laws, f);  // none on the boundary
      if (!law) continue;
      const auto [e0, e1] = topo.facet_elem[f];
      if (0.5 * (frobenius[e0] + frobenius[e1]) * std::max(1.0, 1.0 / law->beta) < law->sigma_c) continue;
      const std::array<Index, 6> fn = face_nodes(mesh, e0, topo.facet_face[f][0]);
      const Vec3 area_vector = (x[fn[1]] - x[fn[0]]).cross(x[fn[2]] - x[fn[0]]);
      const Vec3 n = area_vector.normalized();
      const Mat3 sigma = 0.5 * (element_cauchy_stress(stress, stress_size, e0) +
                                element_cauchy_stress(stress, stress_size, e1));
      breaks[f] = facet_effective_traction(sigma, n, law->beta) >= law->sigma_c;
    }
  });
  std::vector<Index> out;
  for (Index f = 0; f < nf; ++f)
    if (breaks[f]) out.push_back(f);
  std::sort(out.begin(), out.end(),
            [&](Index a, Index b) { return topo.facet_gid[a] < topo.facet_gid[b]; });
  return out;
}

}  // namespace shatter
