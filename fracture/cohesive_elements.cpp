#include "fracture/cohesive_elements.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>

#include "kernels/error.hpp"

namespace shatter {

namespace {

constexpr int kSlots = 6;  // node slots per side, enough for a TET10 facet

/// Facet shape functions at barycentrics L (corners a, b, c; then for the
/// 6-node facet the mid-edge nodes of (a,b), (b,c), (c,a)).
std::array<double, 6> facet_shape(const Vec3& L, int k) {
  if (k == 3) return {L[0], L[1], L[2], 0, 0, 0};
  return {L[0] * (2 * L[0] - 1), L[1] * (2 * L[1] - 1), L[2] * (2 * L[2] - 1),
          4 * L[0] * L[1],       4 * L[1] * L[2],       4 * L[2] * L[0]};
}

const std::array<Vec3, kCohesivePoints>& facet_points() {
  static const std::array<Vec3, kCohesivePoints> p = {Vec3(2.0 / 3, 1.0 / 6, 1.0 / 6),
                                                      Vec3(1.0 / 6, 2.0 / 3, 1.0 / 6),
                                                      Vec3(1.0 / 6, 1.0 / 6, 2.0 / 3)};
  return p;
}

void refresh_side_nodes(const Mesh& mesh, const Topology& topo, CohesiveElements& coh,
                        Index first) {
  const int k = mesh.order == 1 ? 3 : 6;
  coh.side_nodes.resize(static_cast<size_t>(coh.size()) * 2 * kSlots, -1);
  for (Index c = first; c < coh.size(); ++c)
    for (int s = 0; s < 2; ++s) {
      const Index* conn = mesh.element(topo.facet_elem[coh.facet[c]][s]);
      const size_t slot = (static_cast<size_t>(c) * 2 + s) * kSlots;
      for (int j = 0; j < k; ++j) coh.side_nodes[slot + j] = conn[coh.side_local[slot + j]];
    }
}

/// Where cohesive element c is at positions x: its mid-surface corners
/// (averages of the two sides' corners), their area vector (its direction is
/// the normal, from side 0 to side 1) and the opening x(side 1) - x(side 0)
/// at each quadrature point.
struct FacetKinematics {
  std::array<Vec3, 3> mid;
  Vec3 area_vector;
  std::array<Vec3, kCohesivePoints> opening;
};

FacetKinematics facet_kinematics(const CohesiveElements& coh, Index c, int k,
                                 std::span<const Vec3> x) {
  const Index* side0 = coh.side_nodes.data() + static_cast<size_t>(c) * 2 * kSlots;
  const Index* side1 = side0 + kSlots;
  FacetKinematics s;
  for (int j = 0; j < 3; ++j) s.mid[j] = 0.5 * (x[side0[j]] + x[side1[j]]);
  s.area_vector = (s.mid[1] - s.mid[0]).cross(s.mid[2] - s.mid[0]);
  for (int q = 0; q < kCohesivePoints; ++q) {
    const std::array<double, 6> N = facet_shape(facet_points()[q], k);
    s.opening[q] = Vec3::Zero();
    for (int j = 0; j < k; ++j) s.opening[q] += N[j] * (x[side1[j]] - x[side0[j]]);
  }
  return s;
}

/// The elements of `share`: count(), the i-th's index, and whether it counts.
struct ShareView {
  CohesiveShare share;
  Index all;
  Index count() const { return share.every ? all : static_cast<Index>(share.computed.size()); }
  Index operator[](Index i) const { return share.every ? i : share.computed[i]; }
  bool counted(Index i) const { return share.every || share.counted[i]; }
};

/// Adds the forces of the elements at positions [first, last) of `which`
/// (local_force, 2k per element from `first`) to f_int. Every node receives
/// them in the order of a serial loop over the elements (side 0 then side 1
/// of each slot), so the bits are those of that loop for any thread count,
/// and for any subset of the elements that holds a node's whole list. In
/// parallel without coloring: the node ids are cut into as many ranges as
/// threads, each holding about the same number of the block's slots
/// (quantiles of a sample), and the task of a range walks the block in
/// element order and adds only to its nodes. Each task reads every slot's
/// node id (sequential) but writes only its own (the random accesses), so the
/// writes divide among the threads.
void scatter_block(const CohesiveElements& coh, const ShareView& which, int k, Index first, Index last,
                   std::span<const Vec3> local_force, std::span<Vec3> f_int) {
  auto nodes_of = [&](Index i) { return coh.side_nodes.data() + static_cast<size_t>(which[i]) * 2 * kSlots; };
  auto add = [&](Index lo, Index hi) {
    for (Index i = first; i < last; ++i) {
      const Index* nodes = nodes_of(i);
      const Vec3* f = local_force.data() + static_cast<size_t>(i - first) * 2 * k;
      for (int j = 0; j < k; ++j) {
        if (nodes[j] >= lo && nodes[j] < hi) f_int[nodes[j]] += f[j];
        if (nodes[kSlots + j] >= lo && nodes[kSlots + j] < hi) f_int[nodes[kSlots + j]] += f[k + j];
      }
    }
  };
  const Index num_nodes = static_cast<Index>(f_int.size());
  const int ranges = std::min<Index>(tbb::this_task_arena::max_concurrency(), (last - first) / 64);
  if (ranges <= 1) return add(0, num_nodes);
  constexpr int kSampleStride = 7;  // slots between samples (odd: both sides sampled)
  std::vector<Index> sample;
  size_t slot = 0;
  for (Index i = first; i < last; ++i)
    for (int t = 0; t < 2 * kSlots; ++t, ++slot)
      if (slot % kSampleStride == 0 && nodes_of(i)[t] >= 0) sample.push_back(nodes_of(i)[t]);
  std::sort(sample.begin(), sample.end());
  std::vector<Index> cut(ranges + 1, num_nodes);
  cut[0] = 0;
  for (int r = 1; r < ranges; ++r) cut[r] = sample[sample.size() * r / ranges];
  tbb::parallel_for(0, ranges, [&](int r) { add(cut[r], cut[r + 1]); });
}

}  // namespace

std::vector<Index> Insertion::changed_nodes() const {
  std::vector<Index> nodes;
  for (const auto& [copy, parent] : new_nodes) nodes.insert(nodes.end(), {copy, parent});
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

Insertion insert_cohesive_elements(Mesh& mesh, Topology& topo, CohesiveElements& coh,
                                   std::span<const Index> facets) {
  const int k = mesh.order == 1 ? 3 : 6;
  std::vector<Index> sorted(facets.begin(), facets.end());
  std::sort(sorted.begin(), sorted.end(),
            [&](Index a, Index b) { return topo.facet_gid[a] < topo.facet_gid[b]; });
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());

  Insertion out;
  out.first_cohesive = coh.size();
  for (const Index f : sorted) {
    SHATTER_REQUIRE(topo.facet_state[f] == FacetState::intact && topo.is_interior(f),
                    "insert_cohesive_elements: facet " << topo.facet_gid[f]
                                                       << " is not an intact interior facet");
    topo.facet_state[f] = FacetState::cohesive;
    const auto [e0, e1] = topo.facet_elem[f];
    const int face0 = topo.facet_face[f][0];
    const Index* c0 = mesh.element(e0);
    const Index* c1 = mesh.element(e1);
    // The facet is intact, so both sides still share its nodes: match them by id.
    std::array<std::int8_t, 2 * kSlots> local;
    local.fill(-1);
    for (int j = 0; j < k; ++j) {
      local[j] = static_cast<std::int8_t>(kTetFaces[face0][j]);
      const Index n = c0[local[j]];
      for (int a = 0; a < mesh.nodes_per_element(); ++a)
        if (c1[a] == n) local[kSlots + j] = static_cast<std::int8_t>(a);
      SHATTER_ASSERT(local[kSlots + j] >= 0);
    }
    const Vec3& X0 = mesh.reference[c0[local[0]]];
    const Vec3 area_vector =
        0.5 * (mesh.reference[c0[local[1]]] - X0).cross(mesh.reference[c0[local[2]]] - X0);
    coh.facet.push_back(f);
    coh.side_local.insert(coh.side_local.end(), local.begin(), local.end());
    coh.area.push_back(area_vector.norm());
    coh.normal.push_back(area_vector.normalized());
    coh.delta_max.insert(coh.delta_max.end(), kCohesivePoints, 0.0);
    out.crack_faces.push_back({e0, face0});
    out.crack_faces.push_back({e1, topo.facet_face[f][1]});
  }
  out.new_nodes = split_nodes(mesh, topo, sorted);
  // Splits renumber nodes of older cohesive elements too.
  refresh_side_nodes(mesh, topo, coh, out.new_nodes.empty() ? out.first_cohesive : 0);
  return out;
}

CohesiveEnergy cohesive_forces(const Mesh& mesh, const Topology& topo, CohesiveElements& coh,
                               FractureLaws laws, std::span<const Vec3> x, std::span<Vec3> f_int,
                               CohesiveShare share) {
  const int k = mesh.order == 1 ? 3 : 6;
  const ShareView which{share, coh.size()};
  const Index nc = which.count();
  // Blocks of elements: local forces computed in parallel into a buffer that
  // stays in cache, then scattered in parallel by node ranges, each node in
  // element order (scatter_block), so the sums do not depend on the threads.
  constexpr Index kBlock = 4096;
  std::vector<Vec3> local_force(static_cast<size_t>(std::min(nc, kBlock)) * 2 * k);
  std::vector<std::array<double, 2>> local_energy(std::min(nc, kBlock));  // stored, dissipated
  CohesiveEnergy total;
  for (Index first = 0; first < nc; first += kBlock) {
    const Index last = std::min(nc, first + kBlock);
    tbb::parallel_for(
        tbb::blocked_range<Index>(first, last, 256), [&](const tbb::blocked_range<Index>& r) {
          for (Index i = r.begin(); i != r.end(); ++i) {
            const Index c = which[i];
            const std::optional<CohesiveLaw> law_or = facet_law(mesh, topo, laws, coh.facet[c]);
            SHATTER_ASSERT(law_or);  // insertion happens only where the criterion has a law
            const CohesiveLaw& law = *law_or;
            Vec3* f = local_force.data() + static_cast<size_t>(i - first) * 2 * k;
            std::fill(f, f + 2 * k, Vec3::Zero());
            auto& [stored, dissipated] = local_energy[i - first];
            stored = dissipated = 0;
            if (topo.facet_state[coh.facet[c]] == FacetState::free) {
              // Debonded: no traction is left, and no compression penalty either:
              // its faces may have moved apart by many element sizes, where the
              // mid-surface of the two defines no normal (a penalty on that
              // "interpenetration" once reached 3700 sigma_c and inverted an
              // element of the fine expanding ring, docs/validation.md). Crack
              // faces meet through contact.
              dissipated = law.fracture_energy() * coh.area[c];
              continue;
            }
            const FacetKinematics fs = facet_kinematics(coh, c, k, x);
            const std::array<Vec3, 3>& mid = fs.mid;
            const Vec3 n = fs.area_vector.normalized();
            Vec3 dE_dn = Vec3::Zero();  // sum_q w_q dphi/dn, J
            for (int q = 0; q < kCohesivePoints; ++q) {
              const std::array<double, 6> N = facet_shape(facet_points()[q], k);
              double& delta_max = coh.delta_max[static_cast<size_t>(c) * kCohesivePoints + q];
              const CohesiveTraction t = cohesive_traction(law, fs.opening[q], n, delta_max);
              delta_max = t.delta_max;
              const double w = coh.area[c] / kCohesivePoints;
              for (int j = 0; j < k; ++j) {
                f[k + j] += (w * N[j]) * t.traction;
                f[j] -= (w * N[j]) * t.traction;
              }
              stored += w * t.stored;
              dissipated += w * t.dissipated;
              dE_dn += w * t.dphi_dn;
            }
            // The normal follows the mid-surface corners m_j = (x0_j + x1_j) / 2:
            // dn = (I - n n^T) dA / |A| with dA = dm_j x (m_{j+1} - m_{j+2}), so
            // dE/dm_j = (m_{j+1} - m_{j+2}) x h, h = (I - n n^T) dE/dn / |A|, half
            // to each side. With it the forces are the gradient of a rotation
            // invariant energy: no net force and no net torque.
            // (A mid-surface of zero area has no normal: n = 0 above, and no term.)
            const double area = fs.area_vector.norm();
            const Vec3 h = area > 0 ? Vec3((dE_dn - dE_dn.dot(n) * n) / area) : Vec3::Zero();
            for (int j = 0; j < 3; ++j) {
              const Vec3 fj = 0.5 * (mid[(j + 1) % 3] - mid[(j + 2) % 3]).cross(h);
              f[j] += fj;
              f[k + j] += fj;
            }
          }
        });
    scatter_block(coh, which, k, first, last, local_force, f_int);
    for (Index i = first; i < last; ++i) {
      if (!which.counted(i)) continue;
      total.stored += local_energy[i - first][0];
      total.dissipated += local_energy[i - first][1];
    }
  }
  return total;
}

double cohesive_eigenvalue_bound(const Mesh& mesh, const Topology& topo,
                                 const CohesiveElements& coh, FractureLaws laws,
                                 std::span<const double> mass, CohesiveShare share) {
  const int k = mesh.order == 1 ? 3 : 6;
  // Per facet node j: sum_q (1/3) |N_j(x_q)| sum_l |N_l(x_q)|, times the area.
  std::array<double, 6> row{};
  for (const Vec3& p : facet_points()) {
    const std::array<double, 6> N = facet_shape(p, k);
    double sum_abs = 0;
    for (int l = 0; l < k; ++l) sum_abs += std::abs(N[l]);
    for (int j = 0; j < k; ++j) row[j] += std::abs(N[j]) * sum_abs / kCohesivePoints;
  }
  std::vector<double> stiffness(mass.size(), 0.0);  // Gershgorin row sums, N/m
  const ShareView which{share, coh.size()};
  for (Index i = 0; i < which.count(); ++i) {
    const Index c = which[i];
    if (topo.facet_state[coh.facet[c]] != FacetState::cohesive) continue;
    const double kc = 2.0 * cohesive_stiffness_bound(*facet_law(mesh, topo, laws, coh.facet[c]));
    const Index* nodes = coh.side_nodes.data() + static_cast<size_t>(c) * 2 * kSlots;
    for (int s = 0; s < 2; ++s)
      for (int j = 0; j < k; ++j) stiffness[nodes[s * kSlots + j]] += kc * coh.area[c] * row[j];
  }
  double bound = 0;
  for (size_t i = 0; i < mass.size(); ++i)
    if (stiffness[i] > 0) bound = std::max(bound, stiffness[i] / mass[i]);
  return bound;
}

std::vector<double> element_damage(const Mesh& mesh, const Topology& topo,
                                   const CohesiveElements& coh, FractureLaws laws) {
  std::vector<double> damage(mesh.num_elements(), 0.0);
  for (Index c = 0; c < coh.size(); ++c) {
    const Index f = coh.facet[c];
    double d = 1.0;
    if (topo.facet_state[f] == FacetState::cohesive) {
      const double* dm = coh.delta_max.data() + static_cast<size_t>(c) * kCohesivePoints;
      d = std::min(1.0, *std::max_element(dm, dm + kCohesivePoints) /
                            facet_law(mesh, topo, laws, f)->delta_c);
    }
    for (const Index e : topo.facet_elem[f]) damage[e] = std::max(damage[e], d);
  }
  return damage;
}

namespace {

/// Cohesive element c has opened past delta_c at every point.
bool debonded(const CohesiveElements& coh, Index c, const CohesiveLaw& law) {
  const double* dm = coh.delta_max.data() + static_cast<size_t>(c) * kCohesivePoints;
  return std::all_of(dm, dm + kCohesivePoints, [&](double d) { return d >= law.delta_c; });
}

}  // namespace

CrackArea crack_area(const Mesh& mesh, const Topology& topo, const CohesiveElements& coh,
                     FractureLaws laws, std::span<const Index> elem_fragment, CohesiveShare share) {
  CrackArea a;
  const ShareView which{share, coh.size()};
  for (Index i = 0; i < which.count(); ++i) {
    if (!which.counted(i)) continue;
    const Index c = which[i];
    const Index f = coh.facet[c];
    const CohesiveLaw law = *facet_law(mesh, topo, laws, f);
    if (!debonded(coh, c, law)) continue;
    a.debonded += coh.area[c];
    a.debonded_dissipated += law.fracture_energy() * coh.area[c];
    const auto [e0, e1] = topo.facet_elem[f];
    if (elem_fragment[e0] != elem_fragment[e1]) a.between_fragments += coh.area[c];
  }
  return a;
}

std::vector<Index> debonded_facets(const Topology& topo, const CohesiveElements& coh, CohesiveShare share) {
  std::vector<Index> out;
  const ShareView which{share, coh.size()};
  for (Index i = 0; i < which.count(); ++i) {
    const Index c = which[i], f = coh.facet[c];
    if (!which.counted(i) || topo.facet_state[f] != FacetState::cohesive) continue;
    // Every point has come apart (kernels/cohesive.hpp): past delta_c, and
    // no penalty holds energy that would vanish from the ledger.
    const double* dm = coh.delta_max.data() + static_cast<size_t>(c) * kCohesivePoints;
    if (std::all_of(dm, dm + kCohesivePoints, [](double d) { return d == kPointApart; })) out.push_back(f);
  }
  return out;
}

Index release_debonded(Topology& topo, const CohesiveElements& coh) {
  const std::vector<Index> facets = debonded_facets(topo, coh);
  for (Index f : facets) topo.facet_state[f] = FacetState::free;
  return static_cast<Index>(facets.size());
}

}  // namespace shatter
