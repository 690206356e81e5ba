#pragma once
// Executor of the shell element loop (STYLE.md level 3; docs/shells.md "The
// runtime"): the patches of every shell body run as oneTBB tasks, each
// writing its forces into its own slots; then every control vertex sums its
// slots in ascending order (ShellBody::vertex_slot). A vertex thus receives
// its contributions in a fixed order, and the forces, the strain energy
// (summed over the patches in order) and the stable step are bitwise the
// same for any thread count, without coloring or atomics.
#include <cmath>
#include <functional>
#include <span>
#include <vector>

#include "kernels/exact_sum.hpp"
#include "kernels/shell_kl.hpp"
#include "runtime/model.hpp"

namespace shatter {

struct ShellLoopResult {
  ExactSum strain_energy;       ///< J, of the owned patches (every patch unless restricted), exact
  double stable_dt = HUGE_VAL;  ///< s, min over the elements of shell_stable_dt at the current positions
  Index worst_body = -1;        ///< the shell body (Model::shells index) setting stable_dt
};

class ShellForces {
 public:
  explicit ShellForces(const Model& model);

  /// On a rank of a decomposition (docs/parallel.md "Shells on ranks"):
  /// compute only the patches with a node in `touched` (ascending model node
  /// ids; the patches' other nodes must be current), write the forces of the
  /// shell nodes in `touched` only, and count the energy of the patches
  /// whose triangle's first corner satisfies owns(node) (each patch once
  /// over the ranks). A vertex sums its slots in the same order whatever the
  /// restriction, so it gets the same bits.
  void restrict_to(std::span<const Index> touched, const std::function<bool(Index)>& owns);

  /// f_int of the shell bodies' nodes = dE/dx at positions x (overwrites
  /// their rows; the solids' rows are left as they are).
  ShellLoopResult compute(std::span<const Vec3> x, std::span<Vec3> f_int) const;

  /// The stress resultants (membrane force, bending moment; ShellResultants)
  /// of every shell triangle at positions x: body after body, each body's
  /// triangles in its control mesh's order; with restrict_to, only the owned
  /// patches' triangles are computed (the others are left zero).
  std::vector<ShellResultants> resultants(std::span<const Vec3> x) const;
  /// Whether the patch of triangle t of shell body b is owned here (every one unless restricted).
  bool owns_triangle(std::size_t b, Index t) const { return triangle_owned_[b][t] != 0; }

  /// Shell elements computed per call (owned and ghost patches).
  Index elements() const { return elements_; }
  /// Shell elements whose energy is counted here (owned patches).
  Index owned_elements() const { return owned_elements_; }

 private:
  const Model& model_;
  Index elements_ = 0, owned_elements_ = 0;
  /// Per shell body: per set, the patches computed; the vertices whose
  /// forces are written; per triangle, 1 when its patch's energy is counted here.
  std::vector<std::vector<std::vector<Index>>> computed_;
  std::vector<std::vector<Index>> vertices_;
  std::vector<std::vector<char>> triangle_owned_;
  /// Per shell body: forces per slot, N; energy and stable step per patch (set after set).
  mutable std::vector<std::vector<Vec3>> slot_force_;
  mutable std::vector<std::vector<double>> patch_energy_, patch_dt_;
};

}  // namespace shatter
