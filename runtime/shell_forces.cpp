#include "runtime/shell_forces.hpp"

#include <algorithm>

#include "kernels/shell_stable_dt.hpp"
#include "runtime/parallel.hpp"
#include "runtime/shell_model.hpp"

namespace shatter {

namespace {

/// The positions of the K entries of triangle t's patch (ghosts from their rules).
template <int K>
Eigen::Matrix<double, 3, K> patch_positions(const ShellBody& s, Index t, std::span<const Vec3> x) {
  Eigen::Matrix<double, 3, K> xe;
  for (int a = 0; a < K; ++a) xe.col(a) = s.mesh.entry_position(x, s.mesh.patch_of(t)[a]);
  return xe;
}

/// The forces, energy and stable step of every patch of `set` (in parallel).
template <int N>
void compute_set(const ShellBody& s, const ShellPatchSet& set, const NeoHookean& mat, std::span<const Vec3> x,
                 Index first_patch, std::vector<Vec3>& slot_force, std::vector<double>& energy,
                 std::vector<double>& dt) {
  constexpr int K = N + 6;
  const auto& basis = shell_basis<N>();
  parallel_for_each(static_cast<Index>(set.triangle.size()), [&](Index p) {
    const Index t = set.triangle[p];
    const ShellForce<K> out =
        shell_internal_force<K, kShellPoints>(patch_positions<K>(s, t, x), basis, set.reference[p], mat);
    Vec3* f = slot_force.data() + set.first_slot + static_cast<Index>(p) * K;
    for (int a = 0; a < K; ++a) f[a] = out.f.col(a);
    const auto& c = s.mesh.triangles[t];
    energy[first_patch + p] = out.energy;
    dt[first_patch + p] = shell_stable_dt(shell_stable_length(x[c[0]], x[c[1]], x[c[2]]), s.thickness, mat);
  });
}

}  // namespace

ShellForces::ShellForces(const Model& model) : model_(model) {
  for (const ShellBody& s : model.shells) {
    slot_force_.emplace_back(s.slots);
    Index patches = 0;
    for (const ShellPatchSet& set : s.sets) patches += static_cast<Index>(set.triangle.size());
    patch_energy_.emplace_back(patches);
    patch_dt_.emplace_back(patches);
    elements_ += patches;
  }
}

std::vector<ShellResultants> ShellForces::resultants(std::span<const Vec3> x) const {
  std::vector<ShellResultants> out;
  for (const ShellBody& s : model_.shells) {
    const NeoHookean& mat = model_.materials[s.material];
    const std::span<const Vec3> xs = x.subspan(s.first_node, s.mesh.num_vertices());
    const std::size_t first = out.size();
    out.resize(first + s.mesh.num_triangles());
    for (const ShellPatchSet& set : s.sets)
      with_valence(set.valence, [&](auto N) {
        constexpr int K = N() + 6;
        parallel_for_each(static_cast<Index>(set.triangle.size()), [&](Index p) {
          const Index t = set.triangle[p];
          out[first + t] =
              shell_resultants<K, kShellPoints>(patch_positions<K>(s, t, xs), shell_basis<N()>(), set.reference[p], mat);
        });
      });
  }
  return out;
}

ShellLoopResult ShellForces::compute(std::span<const Vec3> x, std::span<Vec3> f_int) const {
  ShellLoopResult r;
  for (std::size_t b = 0; b < model_.shells.size(); ++b) {
    const ShellBody& s = model_.shells[b];
    const NeoHookean& mat = model_.materials[s.material];
    const std::span<const Vec3> xs = x.subspan(s.first_node, s.mesh.num_vertices());
    Index first_patch = 0;
    for (const ShellPatchSet& set : s.sets) {
      with_valence(set.valence, [&](auto N) {
        compute_set<N()>(s, set, mat, xs, first_patch, slot_force_[b], patch_energy_[b], patch_dt_[b]);
      });
      first_patch += static_cast<Index>(set.triangle.size());
    }
    const std::vector<Vec3>& slot = slot_force_[b];
    parallel_for_each(s.mesh.num_vertices(), [&](Index v) {
      Vec3 f = Vec3::Zero();
      for (Index k = s.vertex_slot_offsets[v]; k < s.vertex_slot_offsets[v + 1]; ++k)
        f += s.vertex_slot_weight[k] * slot[s.vertex_slot[k]];
      f_int[s.first_node + v] = f;
    });
    for (const double e : patch_energy_[b]) r.strain_energy += e;
    const double dt = *std::min_element(patch_dt_[b].begin(), patch_dt_[b].end());
    if (dt < r.stable_dt) r.stable_dt = dt, r.worst_body = static_cast<Index>(b);
  }
  return r;
}

}  // namespace shatter
