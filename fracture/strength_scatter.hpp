#pragma once
// Strength scatter (scene key materials.<m>.fracture.scatter): each facet
// gets its own cohesive strength, drawn from its global id and a seed, so
// the value is the same on any decomposition and after a restart (nothing
// to checkpoint: it is recomputed from the ids).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "kernels/cohesive.hpp"
#include "mesh/topology.hpp"

namespace shatter {

enum class ScatterDistribution { weibull, uniform };

struct StrengthScatter {
  ScatterDistribution distribution = ScatterDistribution::weibull;
  double modulus = 0;              ///< Weibull modulus m (weibull), > 0
  double spread = 0;               ///< half-width as a fraction of sigma_c (uniform), in [0, 1)
  std::uint64_t seed = 0;          ///< stream of draws
  double reference_area = 1.0e-6;  ///< A_0, m^2: the area whose mean Weibull strength is sigma_c
};

/// A uniform number in (0, 1) for facet `facet_gid` (Topology::facet_gid)
/// and `seed`: SplitMix64 (Steele, Lea & Flood, OOPSLA 2014) of the pair,
/// the top 53 bits centred in their interval. Pure: no stream to carry.
double facet_uniform(std::uint64_t seed, GlobalId facet_gid);

/// Strength of a facet of area `area` (m^2) for the material strength
/// sigma_c (Pa) and the draw u in (0, 1), Pa:
///   weibull: sigma_c (A_0 / area)^(1/m) (-ln(1 - u))^(1/m) / Gamma(1 + 1/m)
///            (the inverse of P_f = 1 - exp(-(area / A_0) (s / s_0)^m),
///            s_0 = sigma_c / Gamma(1 + 1/m): facets of area A_0 have mean
///            strength sigma_c, larger ones are weaker; Weibull 1951,
///            Zhou, Molinari & Ramesh, IJSS 42 (2005) 3287)
///   uniform: sigma_c (1 + spread (2u - 1))
double scattered_strength(const StrengthScatter& scatter, double sigma_c, double area, double u);

/// Strength of every facet of `topo` (Pa, layout [f]): for an interior facet
/// with a law (facet_law: the material of its element 0), the material's
/// sigma_c, scattered when `scatter` (indexed like `laws`) has a value for
/// that material; +infinity elsewhere (such facets never break). The area is
/// that of the reference corner triangle.
std::vector<double> facet_strengths(const Mesh& mesh, const Topology& topo,
                                    std::span<const std::optional<CohesiveLaw>> laws,
                                    std::span<const std::optional<StrengthScatter>> scatter);

}  // namespace shatter
