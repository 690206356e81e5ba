#include "fracture/facet_criterion.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numeric>
#include <utility>

#include "kernels/error.hpp"

namespace shatter {

namespace {

/// Facets per call of facet_traction_lanes: one AVX-512 vector, two AVX ones.
constexpr int kFacetLanes = 8;
/// Facets screened at a time before their tractions are evaluated.
constexpr Index kFacetChunk = 256;

/// Whether any of the kFacetLanes flags is set, tested as one word.
bool any_lane(const bool (&flag)[kFacetLanes]) {
  std::uint64_t word;  // byte l: lane l
  static_assert(sizeof(flag) == sizeof(word));
  std::memcpy(&word, flag, sizeof(word));
  return word != 0;
}

/// Sorts (key, facet) pairs by key: least-significant-digit radix sort, 8
/// bits of key - min key per pass (3 passes for 2^24 keys: ~10x faster than
/// std::sort on the thousands of facets of a hot field, whose comparisons
/// mispredict).
void sort_by_key(std::vector<std::pair<GlobalId, Index>>& v) {
  if (v.size() < 2) return;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  const GlobalId base = lo->first, span = hi->first - base;
  std::vector<std::pair<GlobalId, Index>> tmp(v.size());
  for (int shift = 0; shift < 64 && (span >> shift) != 0; shift += 8) {
    std::array<size_t, 257> start{};
    auto digit = [&](const std::pair<GlobalId, Index>& p) { return ((p.first - base) >> shift) & 255; };
    for (const auto& p : v) ++start[digit(p) + 1];
    for (int d = 0; d < 256; ++d) start[d + 1] += start[d];
    for (const auto& p : v) tmp[start[digit(p)]++] = p;
    v.swap(tmp);
  }
}

}  // namespace

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
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) sigma(i, j) = s[stress_size == 6 ? kVoigtOfRowMajor[3 * i + j] : 3 * i + j];
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
  // Pass 1 computes the norms (one contiguous, vectorisable sweep) and stops
  // the check when no element is hot (a cold field); pass 2 screens the
  // facets with the bound. The factor 1 + 1e-12 keeps the bound safe against
  // the round-off of the norms. Pass 1 covers the local elements (all on one
  // rank), pass 2 the facets whose smaller element is owned.
  constexpr double kSafe = 1.0 + 1e-12;
  const bool all = local.empty();
  const Index nlocal = all ? ne : static_cast<Index>(local.size());
  auto elem = [&](Index k) { return all ? k : local[k]; };
  // Set for the local elements; on ranks 0 for the others (pass 2 reads them, never to keep a facet).
  std::unique_ptr<double[]> frobenius(all ? new double[ne] : new double[ne]());
  const double* s = stress.data();
  const double hot = weakest / widest;
  const int* mat = mesh.elem_material.data();
  const bool every_material_fractures =
      std::all_of(laws.material.begin(), laws.material.end(), [](const auto& law) { return law.has_value(); });
  std::atomic<bool> any_hot = false;
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
    // facet_law's rule: a facet has a law only when both its materials
    // fracture. An element of a material that does not gets -inf: the bound
    // of its facets is -inf, so pass 2 drops them without the materials.
    bool hot_here = false;
    for (Index k = r.begin(); k != r.end(); ++k) {
      const Index e = elem(k);
      if (!every_material_fractures && !laws.material[mat[e]]) frobenius[e] = -HUGE_VAL;
      hot_here |= frobenius[e] >= hot;
    }
    if (hot_here) any_hot = true;
  });
  if (!any_hot) return {};
  std::unique_ptr<char[]> owned_flag;  // on ranks: 1 for the owned elements
  if (!owned.empty()) {
    owned_flag.reset(new char[ne]());
    for (Index e : owned) owned_flag[e] = 1;
  }
  // Pass 2, over the facets: keep those whose bound reaches the strength
  // (with the largest max(1, 1/beta) and, without scatter, the smallest
  // sigma_c: still a safe bound, read without the materials), written
  // without branches; then evaluate them kFacetLanes at a time (the law of
  // element 0's material, facet_law's).
  tbb::enumerable_thread_specific<std::vector<Index>> found;
  const Index nf = topo.num_facets();
  tbb::parallel_for(tbb::blocked_range<Index>(0, nf, kFacetChunk), [&](const tbb::blocked_range<Index>& r) {
    std::vector<Index>* local_found = nullptr;
    Index candidate[kFacetChunk], side[2][kFacetChunk], broken_facet[kFacetChunk];
    for (Index f0 = r.begin(); f0 < r.end(); f0 += kFacetChunk) {
      const Index f1 = std::min<Index>(f0 + kFacetChunk, r.end());
      int count = 0;
      for (Index f = f0; f < f1; ++f) {
        const auto [e0, e1] = topo.facet_elem[f];
        const Index e1_or_e0 = e1 < 0 ? e0 : e1;  // intact facets have two elements
        const double strength = laws.facet_strength.empty() ? weakest : laws.facet_strength[f];
        const bool keep = (topo.facet_state[f] == FacetState::intact) &
                          (!owned_flag || owned_flag[std::min(e0, e1_or_e0)]) &
                          (0.5 * (frobenius[e0] + frobenius[e1_or_e0]) * widest >= strength);
        candidate[count] = f;
        side[0][count] = e0;
        side[1][count] = e1_or_e0;
        count += keep;
      }
      // Element 1's stress row is the one load of the evaluation out of
      // order (the facets follow their elements 0): ask for the rows now, so
      // that their misses overlap here rather than stall the lanes' filling.
      for (int k = 0; k < count; ++k) {
        const double* row = stress.data() + static_cast<size_t>(side[1][k]) * stress_size;
        __builtin_prefetch(row);
        __builtin_prefetch(row + stress_size - 1);
      }
      int nbroken = 0;  // the facets found in the chunk: broken_facet[0, nbroken)
      auto evaluate = [&]<int S>() {
        // The kept facets side by side (lane k = candidate k), filled facet by
        // facet; each group of kFacetLanes then loads its rows as vectors,
        // with no transposition (the stores have long left when they are read).
        // One group of lanes more than the chunk: rows a power of two apart
        // would share the L1 sets (4 KiB apart) and evict each other.
        FacetTractionLanes<kFacetChunk + kFacetLanes, S> chunk;
        double chunk_strength[kFacetChunk];
        const int padded = (count + kFacetLanes - 1) / kFacetLanes * kFacetLanes;
        for (int j = 0; j < padded; ++j) {
          const int k = std::min(j, count - 1);  // lanes past the last repeat it
          const Index* corner = mesh.element(side[0][k]);  // the conn rows of the elements 0, in order
          const std::array<int, 6>& face = kTetFaces[topo.facet_face[candidate[k]][0]];
          for (int a = 0; a < 3; ++a) {
            const double* p = x[corner[face[a]]].data();
            for (int c = 0; c < 3; ++c) chunk.x[3 * a + c][j] = p[c];
          }
          const double* s0 = stress.data() + static_cast<size_t>(side[0][k]) * S;
          const double* s1 = stress.data() + static_cast<size_t>(side[1][k]) * S;
          for (int q = 0; q < S; ++q) chunk.stress_sum[q][j] = s0[q] + s1[q];
          const CohesiveLaw& law = *laws.material[mat[side[0][k]]];  // facet_law's
          chunk.beta[j] = law.beta;
          chunk_strength[j] = laws.facet_strength.empty() ? law.sigma_c : laws.facet_strength[candidate[k]];
        }
        for (int k0 = 0; k0 < count; k0 += kFacetLanes) {
          const int lanes = std::min(kFacetLanes, count - k0);
          FacetTractionLanes<kFacetLanes, S> L;
          double strength[kFacetLanes];
          for (int r = 0; r < 9; ++r) std::copy_n(chunk.x[r] + k0, kFacetLanes, L.x[r]);
          for (int q = 0; q < S; ++q) std::copy_n(chunk.stress_sum[q] + k0, kFacetLanes, L.stress_sum[q]);
          std::copy_n(chunk.beta + k0, kFacetLanes, L.beta);
          std::copy_n(chunk_strength + k0, kFacetLanes, strength);
          // The decisions without division or square root; the tractions
          // themselves only where the margin leaves a lane undecided (rare:
          // t_eff within ~1e-10 of the strength).
          bool broken[kFacetLanes], undecided[kFacetLanes];
          facet_criterion_lanes(L, strength, broken, undecided);
          if (any_lane(undecided)) {
            facet_traction_lanes(L);
            for (int l = 0; l < kFacetLanes; ++l) broken[l] = L.traction[l] >= strength[l];
          }
          if (!any_lane(broken)) continue;  // few break
          for (int l = 0; l < lanes; ++l) {  // without branches: which lanes break is unpredictable
            broken_facet[nbroken] = candidate[k0 + l];
            nbroken += broken[l];
          }
        }
      };
      if (stress_size == 6)
        evaluate.template operator()<6>();
      else
        evaluate.template operator()<9>();
      if (nbroken > 0) {
        if (!local_found) local_found = &found.local();
        local_found->insert(local_found->end(), broken_facet, broken_facet + nbroken);
      }
    }
  });
  std::vector<std::pair<GlobalId, Index>> keyed;
  keyed.reserve(std::accumulate(found.begin(), found.end(), size_t{0},
                                [](size_t n, const std::vector<Index>& v) { return n + v.size(); }));
  for (const std::vector<Index>& v : found)
    for (Index f : v) keyed.emplace_back(topo.facet_gid[f], f);
  sort_by_key(keyed);  // global ids are distinct: one order
  std::vector<Index> out(keyed.size());
  for (size_t i = 0; i < keyed.size(); ++i) out[i] = keyed[i].second;
  return out;
}

}  // namespace shatter
