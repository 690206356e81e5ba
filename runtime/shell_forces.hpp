#pragma once
// Executor of the shell element loop (STYLE.md level 3; docs/shells.md "The
// runtime"): the patches of every shell body run as oneTBB tasks, each
// writing its forces into its own slots; then every control vertex sums its
// slots in ascending order (ShellBody::vertex_slot). A vertex thus receives
// its contributions in a fixed order, and the forces, the strain energy
// (summed over the patches in order) and the stable step are bitwise the
// same for any thread count, without coloring or atomics.
#include <cmath>
#include <span>
#include <vector>

#include "kernels/shell_kl.hpp"
#include "runtime/model.hpp"

namespace shatter {

struct ShellLoopResult {
  double strain_energy = 0;     ///< J, of every shell body
  double stable_dt = HUGE_VAL;  ///< s, min over the elements of shell_stable_dt at the current positions
  Index worst_body = -1;        ///< the shell body (Model::shells index) setting stable_dt
};

class ShellForces {
 public:
  explicit ShellForces(const Model& model);

  /// f_int of the shell bodies' nodes = dE/dx at positions x (overwrites
  /// their rows; the solids' rows are left as they are).
  ShellLoopResult compute(std::span<const Vec3> x, std::span<Vec3> f_int) const;

  /// The stress resultants (membrane force, bending moment; ShellResultants)
  /// of every shell triangle at positions x: body after body, each body's
  /// triangles in its control mesh's order.
  std::vector<ShellResultants> resultants(std::span<const Vec3> x) const;

  /// Shell elements computed per call.
  Index elements() const { return elements_; }

 private:
  const Model& model_;
  Index elements_ = 0;
  /// Per shell body: forces per slot, N; energy and stable step per patch (set after set).
  mutable std::vector<std::vector<Vec3>> slot_force_;
  mutable std::vector<std::vector<double>> patch_energy_, patch_dt_;
};

}  // namespace shatter
