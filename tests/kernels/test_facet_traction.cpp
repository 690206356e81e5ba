// facet_traction_lanes (the facet check's per-facet traction, vectorised
// across facets): every lane has the bits of the one-facet Eigen form the
// check evaluated before (so the check decides the same facets), whatever
// its lane and the number of lanes; the analytic traction of a uniaxial
// stress on an inclined facet; a zero-area facet carries no traction.
// facet_criterion_lanes (the decisions without divisions or square roots)
// decides every lane it decides as t_eff >= strength does, leaves undecided
// the strengths within an ulp of t_eff, and decides those 30 % away.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "expect_close.hpp"
#include "kernels/facet_traction.hpp"

using namespace shatter;

namespace {

// The Eigen form: n = (b - a) x (c - a) / |.|, sigma = (sigma_0 + sigma_1) / 2,
// t = sigma n, t_eff = sqrt(<t.n>^2 + |t - (t.n) n|^2 / beta^2).
double eigen_form(const Vec3& a, const Vec3& b, const Vec3& c, const Mat3& s0, const Mat3& s1, double beta) {
  const Vec3 n = (b - a).cross(c - a).normalized();
  const Mat3 sigma = 0.5 * (s0 + s1);
  const Vec3 t = sigma * n;
  const double tn = t.dot(n);
  const double tau2 = (t - tn * n).squaredNorm();
  const double tn_pos = std::max(tn, 0.0);
  return std::sqrt(tn_pos * tn_pos + tau2 / (beta * beta));
}

bool same_bits(double u, double v) { return std::memcmp(&u, &v, sizeof(double)) == 0; }

struct Facet {
  Vec3 x[3];
  Mat3 sigma[2];
  double beta;
};

template <int N, int S>
void set_lane(FacetTractionLanes<N, S>& L, const Facet& f, int l) {
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < 3; ++i) L.x[3 * a + i][l] = f.x[a][i];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (S == 9)
        L.stress_sum[3 * i + j][l] = f.sigma[0](i, j) + f.sigma[1](i, j);
      else if (j >= i)
        L.stress_sum[kVoigtOfRowMajor[3 * i + j]][l] = f.sigma[0](i, j) + f.sigma[1](i, j);
    }
  L.beta[l] = f.beta;
}

// Lanes of N facets with S stress components from facets[k0..k0 + N).
template <int N, int S>
FacetTractionLanes<N, S> evaluated(const std::vector<Facet>& facets, size_t k0) {
  FacetTractionLanes<N, S> L;
  for (int l = 0; l < N; ++l) set_lane(L, facets[k0 + l], l);
  facet_traction_lanes(L);
  return L;
}

// Facets of a mm-sized mesh far from the origin (as in a body), symmetric
// stresses of either sign up to a GPa, beta from 0.2 to 5; every 97th facet
// a sliver (third corner 1e-9 of an edge off the line of the other two).
std::vector<Facet> random_facets(int count) {
  std::mt19937_64 rng(19);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(std::log(0.2), std::log(5.0));
  std::vector<Facet> out(count);
  for (int k = 0; k < count; ++k) {
    Facet& f = out[k];
    const Vec3 origin(0.05 * g(rng), 0.05 * g(rng), 0.05 * g(rng));
    for (Vec3& p : f.x) p = origin + 1e-3 * Vec3(g(rng), g(rng), g(rng));
    if (k % 97 == 0) f.x[2] = 0.3 * f.x[0] + 0.7 * f.x[1] + 1e-12 * Vec3(g(rng), g(rng), g(rng));
    for (Mat3& s : f.sigma) {
      Mat3 m;
      for (int q = 0; q < 9; ++q) m.data()[q] = 3e8 * g(rng);
      s = 0.5 * (m + m.transpose());
    }
    f.beta = std::exp(u(rng));
  }
  return out;
}

}  // namespace

TEST(FacetTraction, EveryLaneHasTheBitsOfTheEigenForm) {
  constexpr int kLanes = 8;
  const std::vector<Facet> facets = random_facets(200000);
  int mismatches = 0;
  for (size_t k0 = 0; k0 + kLanes <= facets.size(); k0 += kLanes) {
    const auto voigt = evaluated<kLanes, 6>(facets, k0);
    const auto full = evaluated<kLanes, 9>(facets, k0);
    for (int l = 0; l < kLanes; ++l) {
      const Facet& f = facets[k0 + l];
      const double ref = eigen_form(f.x[0], f.x[1], f.x[2], f.sigma[0], f.sigma[1], f.beta);
      mismatches += !same_bits(voigt.traction[l], ref) + !same_bits(full.traction[l], ref) +
                    !same_bits(evaluated<1, 6>(facets, k0 + l).traction[0], ref);
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(FacetTraction, OneFacetHasTheBitsOfTheEigenForm) {
  int mismatches = 0;
  for (const Facet& f : random_facets(20000)) {
    const Vec3 n = (f.x[1] - f.x[0]).cross(f.x[2] - f.x[0]).normalized();
    const Mat3 sigma = 0.5 * (f.sigma[0] + f.sigma[1]);
    mismatches += !same_bits(facet_effective_traction(sigma, n, f.beta),
                             eigen_form(f.x[0], f.x[1], f.x[2], f.sigma[0], f.sigma[1], f.beta));
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(FacetTraction, UniaxialStressOnAnInclinedFacet) {
  // sigma = s e_x e_x on a facet whose normal makes angle theta with e_x:
  // t = s cos(theta) e_x, tn = s cos^2, tau = s cos sin, so
  // t_eff = s cos(theta) sqrt(cos^2 + sin^2 / beta^2) (tension for any theta).
  const double s = 300e6;
  for (double beta : {0.5, 1.0, 2.0})
    for (double theta : {0.0, 0.3, 0.7, 1.2, 1.5}) {
      FacetTractionLanes<1, 9> L;
      // Corners in the plane through the origin normal to (cos, sin, 0), counter-clockwise.
      const Vec3 t1(-std::sin(theta), std::cos(theta), 0), t2(0, 0, 1);
      const Vec3 x[3] = {Vec3(0.01, 0.02, 0.03), Vec3(0.01, 0.02, 0.03) + 1e-3 * t1,
                         Vec3(0.01, 0.02, 0.03) + 1e-3 * t2};
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 3; ++i) L.x[3 * a + i][0] = x[a][i];
      for (int q = 0; q < 9; ++q) L.stress_sum[q][0] = q == 0 ? s * (0.5 + 1.5) : 0.0;
      L.beta[0] = beta;
      facet_traction_lanes(L);
      const double c = std::cos(theta), sn = std::sin(theta);
      EXPECT_CLOSE(L.traction[0], s * c * std::sqrt(c * c + sn * sn / (beta * beta)), 1e-14, 1e-9 * s)
          << "beta " << beta << " theta " << theta;
    }
}

TEST(FacetTraction, AZeroAreaFacetCarriesNoTraction) {
  FacetTractionLanes<2, 9> L;
  for (int l = 0; l < 2; ++l) {
    for (int q = 0; q < 9; ++q) L.x[q][l] = 0.25 * (q % 3) + (l == 1 ? 0.125 * (q / 3) : 0.0);  // exact in binary
    for (int q = 0; q < 9; ++q) L.stress_sum[q][l] = q % 4 == 0 ? 2e9 : 0.0;
    L.beta[l] = 1.0;
  }
  facet_traction_lanes(L);  // lane 0: three coincident corners; lane 1: collinear ones
  EXPECT_EQ(L.traction[0], 0.0);
  EXPECT_EQ(L.traction[1], 0.0);
}

TEST(FacetTraction, CriterionLanesDecideAsTheTraction) {
  // Each facet's strength is its own t_eff scaled by one of these: ulps and
  // 1e-12 from it must be left undecided, 30 % from it decided.
  const double t = 1.0;
  const double scale[] = {std::nextafter(t, 0.0), t, std::nextafter(t, 2.0), 1 - 1e-12, 1 + 1e-12, 0.7, 1.3};
  constexpr int kScales = sizeof(scale) / sizeof(scale[0]);
  constexpr int kLanes = 8;
  const std::vector<Facet> facets = random_facets(40000);
  int wrong = 0, near_decided = 0, far_undecided = 0, far = 0;
  for (size_t k0 = 0; k0 + kLanes <= facets.size(); k0 += kLanes)
    for (int i = 0; i < kScales; ++i) {
      auto check = [&]<int S>(FacetTractionLanes<kLanes, S> L) {
        double strength[kLanes];
        for (int l = 0; l < kLanes; ++l) strength[l] = scale[(i + l) % kScales] * L.traction[l];
        bool breaks[kLanes], undecided[kLanes];
        facet_criterion_lanes(L, strength, breaks, undecided);
        for (int l = 0; l < kLanes; ++l) {
          const double s = scale[(i + l) % kScales];
          const bool is_far = s == 0.7 || s == 1.3;
          wrong += !undecided[l] && breaks[l] != (L.traction[l] >= strength[l]);
          near_decided += !is_far && !undecided[l];
          far += is_far;
          far_undecided += is_far && undecided[l];
        }
      };
      check(evaluated<kLanes, 6>(facets, k0));
      check(evaluated<kLanes, 9>(facets, k0));
    }
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(near_decided, 0);
  EXPECT_GT(far, 20000);
  EXPECT_EQ(far_undecided, 0);
}

TEST(FacetTraction, CriterionLanesLeaveAZeroAreaFacetUndecided) {
  FacetTractionLanes<2, 9> L;
  for (int l = 0; l < 2; ++l) {
    for (int q = 0; q < 9; ++q) L.x[q][l] = 0.25 * (q % 3) + (l == 1 ? 0.125 * (q / 3) : 0.0);
    for (int q = 0; q < 9; ++q) L.stress_sum[q][l] = q % 4 == 0 ? 2e9 : 0.0;
    L.beta[l] = 1.0;
  }
  const double strength[2] = {1e6, 1e6};
  bool breaks[2], undecided[2];
  facet_criterion_lanes(L, strength, breaks, undecided);
  EXPECT_TRUE(undecided[0]);
  EXPECT_TRUE(undecided[1]);
}
