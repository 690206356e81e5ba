#include "fracture/strength_scatter.hpp"

#include <cmath>
#include <limits>

#include "fracture/facet_criterion.hpp"

namespace shatter {

namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

double facet_uniform(std::uint64_t seed, GlobalId facet_gid) {
  const std::uint64_t bits = splitmix64(seed ^ splitmix64(static_cast<std::uint64_t>(facet_gid)));
  return (static_cast<double>(bits >> 11) + 0.5) * 0x1.0p-53;
}

double scattered_strength(const StrengthScatter& scatter, double sigma_c, double area, double u) {
  if (scatter.distribution == ScatterDistribution::uniform)
    return sigma_c * (1.0 + scatter.spread * (2.0 * u - 1.0));
  const double inv_m = 1.0 / scatter.modulus;
  return sigma_c * std::pow(scatter.reference_area / area, inv_m) * std::pow(-std::log1p(-u), inv_m) /
         std::tgamma(1.0 + inv_m);
}

std::vector<double> facet_strengths(const Mesh& mesh, const Topology& topo,
                                    std::span<const std::optional<CohesiveLaw>> laws,
                                    std::span<const std::optional<StrengthScatter>> scatter) {
  std::vector<double> strength(topo.num_facets(), std::numeric_limits<double>::infinity());
  for (Index f = 0; f < topo.num_facets(); ++f) {
    const std::optional<CohesiveLaw> law = facet_law(mesh, topo, laws, f);
    if (!law) continue;
    const std::optional<StrengthScatter>& s = scatter[mesh.elem_material[topo.facet_elem[f][0]]];
    if (!s) {
      strength[f] = law->sigma_c;
      continue;
    }
    const std::array<Index, 6> fn = face_nodes(mesh, topo.facet_elem[f][0], topo.facet_face[f][0]);
    const Vec3& X0 = mesh.reference[fn[0]];
    const double area = 0.5 * (mesh.reference[fn[1]] - X0).cross(mesh.reference[fn[2]] - X0).norm();
    strength[f] = scattered_strength(*s, law->sigma_c, area, facet_uniform(s->seed, topo.facet_gid[f]));
  }
  return strength;
}

}  // namespace shatter
