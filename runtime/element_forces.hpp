#pragma once
// Executor of the bulk element loop (STYLE.md level 3): elements are cut into
// consecutive blocks, blocks that share a node get different colors, and the
// blocks of one color run as oneTBB tasks, each scattering its elements'
// forces straight into the nodal array. A node receives its contributions in
// a fixed order (color, block, element), so forces are bitwise identical for
// any thread count.
#include <span>
#include <vector>

#include "runtime/coloring.hpp"
#include "runtime/model.hpp"

namespace shatter {

struct ElementLoopResult {
  double strain_energy = 0;       ///< J
  double stable_dt = HUGE_VAL;    ///< min over elements of h_e / c_d(e), s (no safety factor)
  Index worst_element = -1;       ///< element with the smallest det F (J)
  double min_jacobian = HUGE_VAL; ///< smallest det F over all elements/points
};

class ElementForces {
 public:
  /// Elements per block: large enough to amortise task overhead and reuse the
  /// block's nodes from cache, small enough to leave ~20 blocks per color at
  /// 300k elements (docs/performance.md, "Element kernels": 1024 and 4096
  /// equal within noise, 256 is 15 % slower).
  static constexpr Index kBlock = 1024;

  explicit ElementForces(const Model& model);

  /// Recolor after a topology change (node splitting).
  void rebuild();

  /// f_int = dE/dx at positions x (overwrites f_int, size = nodes). When
  /// stress6 is not empty, also writes each element's Cauchy stress there
  /// (6 per element, as element_cauchy_stress6) for the fracture check.
  ElementLoopResult compute(std::span<const Vec3> x, std::span<Vec3> f_int, std::span<double> stress6 = {}) const;

  int num_colors() const { return coloring_.num_colors(); }

 private:
  const Model& model_;
  Coloring coloring_;
  mutable std::vector<double> block_energy_, block_dt_, block_min_J_;
  mutable std::vector<Index> block_worst_;
};

/// Cauchy stress of element e at positions x, averaged over its points, as 6
/// Voigt components xx yy zz yz xz xy (Pa) written to out[0..5].
void element_cauchy_stress6(const Model& model, std::span<const Vec3> x, Index e, double* out);

/// element_cauchy_stress6 and the von Mises stress of every element.
void element_stresses(const Model& model, std::span<const Vec3> x, std::vector<double>& stress6,
                      std::vector<double>& von_mises_out);

}  // namespace shatter
