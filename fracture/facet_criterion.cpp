#include "fracture/facet_criterion.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "kernels/error.hpp"

namespace shatter {

namespace {

/// Facets per call of facet_traction_lanes: one AVX-512 vector, two AVX ones.
constexpr int kFacetLanes = 8;

/// Element e's Cauchy stress from `stress` (6 Voigt or 9 row-major values
/// per element, as element_cauchy_stress) into lane l, row-major.
template <int N>
[[gnu::always_inline]] inline void gather_stress(const double* stress, int stress_size, Index e, double (&out)[9][N],
                                                 int l) {
  const double* s = stress + static_cast<size_t>(e) * stress_size;
  if (stress_size == 6) {
    constexpr int kVoigt[9] = {0, 5, 4, 5, 1, 3, 4, 3, 2};
    for (int q = 0; q < 9; ++q) out[q][l] = s[kVoigt[q]];
  } else {
    for (int q = 0; q < 9; ++q) out[q][l] = s[q];
  }
}

/// The law of the material of element e0 of an interior facet (e0, e1) when
/// both adjacent materials fracture, else none (facet_law without the
/// facet's own strength).
const CohesiveLaw* material_law(const Mesh& mesh, const FractureLaws& laws, Index e0, Index e1) {
  const std::optional<CohesiveLaw>& l0 = laws.material[mesh.elem_material[e0]];
  const std::optional<CohesiveLaw>& l1 = laws.material[mesh.elem_material[e1]];
  return l0 && l1 ? &*l0 : nullptr;
}

/// Lane `to` := lane `from`.
template <int N>
void copy_lane(FacetTractionLanes<N>& L, int from, int to) {
  for (int q = 0; q < 9; ++q) {
    L.x[q][to] = L.x[q][from];
    L.stress[0][q][to] = L.stress[0][q][from];
    L.stress[1][q][to] = L.stress[1][q][from];
  }
  L.beta[to] = L.beta[from];
}

}  // namespace

std::optional<CohesiveLaw> facet_law(const Mesh& mesh, const Topology& topo, FractureLaws laws, Index f) {
  const auto [e0, e1] = topo.facet_elem[f];
  if (e1 < 0) return std::nullopt;
  const CohesiveLaw* law = material_law(mesh, laws, e0, e1);
  if (!law) return std::nullopt;
  return laws.facet_strength.empty() ? *law : with_strength(*law, laws.facet_strength[f]);
}

Mat3 element_cauchy_stress(std::span<const double> stress, int stress_size, Index e) {
  double s[9][1];
  gather_stress(stress.data(), stress_size, e, s, 0);
  Mat3 sigma;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) sigma(i, j) = s[3 * i + j][0];
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
  // Per material: max(1, 1/beta) of its law (no law: never read).
  std::vector<double> wide(laws.material.size(), 1.0);
  for (size_t m = 0; m < wide.size(); ++m)
    if (laws.material[m]) wide[m] = std::max(1.0, 1.0 / laws.material[m]->beta);
  std::unique_ptr<char[]> owned_flag;  // on ranks: 1 for the owned elements
  if (!owned.empty()) {
    owned_flag.reset(new char[ne]());
    for (Index e : owned) owned_flag[e] = 1;
  }
  auto is_owned = [&](Index e) { return !owned_flag || owned_flag[e]; };
  const int* mat = mesh.elem_material.data();
  const Vec3* xs = x.data();
  // Each facet is evaluated once, from the hot adjacent element of smaller
  // local id; the facets that pass the cheap tests are gathered kFacetLanes
  // at a time and their tractions computed side by side
  // (facet_traction_lanes: each lane the bits of a lone facet's). Facets
  // found by any thread are gathered and sorted by global id, so the result
  // does not depend on the threads.
  tbb::enumerable_thread_specific<std::vector<Index>> found;
  tbb::parallel_for(tbb::blocked_range<Index>(0, nlocal, 1024), [&](const tbb::blocked_range<Index>& r) {
    std::vector<Index>* local_found = nullptr;
    FacetTractionLanes<kFacetLanes> L;
    Index lane_facet[kFacetLanes];
    double lane_strength[kFacetLanes];
    int lanes = 0;
    auto evaluate = [&] {
      for (int l = lanes; l < kFacetLanes; ++l) copy_lane(L, 0, l);  // padding, not read back
      facet_traction_lanes(L);
      for (int l = 0; l < lanes; ++l)
        if (L.traction[l] >= lane_strength[l]) {
          if (!local_found) local_found = &found.local();
          local_found->push_back(lane_facet[l]);
        }
      lanes = 0;
    };
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
        // facet_law's sigma_c and beta, without building the law.
        const CohesiveLaw* law = material_law(mesh, laws, e0, e1);
        if (!law) continue;
        const double sigma_c = laws.facet_strength.empty() ? law->sigma_c : laws.facet_strength[f];
        if (0.5 * (frobenius[e0] + frobenius[e1]) * wide[mat[e0]] < sigma_c) continue;
        const Index* corner = mesh.element(e0);
        const std::array<int, 6>& face = kTetFaces[topo.facet_face[f][0]];
        for (int a = 0; a < 3; ++a)
          for (int c = 0; c < 3; ++c) L.x[3 * a + c][lanes] = xs[corner[face[a]]][c];
        gather_stress(stress.data(), stress_size, e0, L.stress[0], lanes);
        gather_stress(stress.data(), stress_size, e1, L.stress[1], lanes);
        L.beta[lanes] = law->beta;
        lane_facet[lanes] = f;
        lane_strength[lanes] = sigma_c;
        if (++lanes == kFacetLanes) evaluate();
      }
    }
    if (lanes > 0) evaluate();
  });
  std::vector<std::pair<GlobalId, Index>> keyed;
  for (const std::vector<Index>& v : found)
    for (Index f : v) keyed.emplace_back(topo.facet_gid[f], f);
  std::sort(keyed.begin(), keyed.end());  // global ids are distinct
  std::vector<Index> out(keyed.size());
  for (size_t i = 0; i < keyed.size(); ++i) out[i] = keyed[i].second;
  return out;
}

}  // namespace shatter
