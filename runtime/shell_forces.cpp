#include "runtime/shell_forces.hpp"

#include <algorithm>
#include <numeric>

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

/// The forces, energy and stable step of the patches `patches` of `set` (in parallel).
template <int N>
void compute_set(const ShellBody& s, const ShellPatchSet& set, std::span<const Index> patches, const NeoHookean& mat,
                 std::span<const Vec3> x, Index first_patch, std::vector<Vec3>& slot_force,
                 std::vector<double>& energy, std::vector<double>& dt) {
  constexpr int K = N + 6;
  const auto& basis = shell_basis<N>();
  parallel_for_each(static_cast<Index>(patches.size()), [&](Index k) {
    const Index p = patches[k], t = set.triangle[p];
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
    auto& computed = computed_.emplace_back();
    for (const ShellPatchSet& set : s.sets) {
      const Index n = static_cast<Index>(set.triangle.size());
      patches += n;
      auto& all = computed.emplace_back(n);
      std::iota(all.begin(), all.end(), 0);
    }
    auto& vertices = vertices_.emplace_back(s.mesh.num_vertices());
    std::iota(vertices.begin(), vertices.end(), 0);
    triangle_owned_.emplace_back(s.mesh.num_triangles(), 1);
    patch_energy_.emplace_back(patches);
    patch_dt_.emplace_back(patches, HUGE_VAL);
    elements_ += patches;
  }
  owned_elements_ = elements_;
}

void ShellForces::restrict_to(std::span<const Index> touched, const std::function<bool(Index)>& owns) {
  std::vector<char> is_touched(model_.mesh.num_nodes(), 0);
  for (const Index n : touched) is_touched[n] = 1;
  const ShellPatchNodes patch_nodes = shell_patch_nodes(model_.shells);
  Index patch = 0;  // over every body's patches, in shell_patch_nodes' order
  elements_ = owned_elements_ = 0;
  for (std::size_t b = 0; b < model_.shells.size(); ++b) {
    const ShellBody& s = model_.shells[b];
    for (std::size_t k = 0; k < s.sets.size(); ++k) {
      const ShellPatchSet& set = s.sets[k];
      std::vector<Index>& computed = computed_[b][k];
      computed.clear();
      for (Index p = 0; p < static_cast<Index>(set.triangle.size()); ++p, ++patch) {
        const auto nodes = patch_nodes.of(patch);
        if (std::any_of(nodes.begin(), nodes.end(), [&](Index n) { return n >= 0 && is_touched[n]; }))
          computed.push_back(p);
        triangle_owned_[b][set.triangle[p]] = owns(s.first_node + s.mesh.triangles[set.triangle[p]][0]) ? 1 : 0;
        owned_elements_ += triangle_owned_[b][set.triangle[p]];
      }
      elements_ += static_cast<Index>(computed.size());
    }
    vertices_[b].clear();
    for (Index v = 0; v < s.mesh.num_vertices(); ++v)
      if (is_touched[s.first_node + v]) vertices_[b].push_back(v);
  }
}

std::vector<ShellResultants> ShellForces::resultants(std::span<const Vec3> x) const {
  std::vector<ShellResultants> out;
  for (std::size_t b = 0; b < model_.shells.size(); ++b) {
    const ShellBody& s = model_.shells[b];
    const NeoHookean& mat = model_.materials[s.material];
    const std::span<const Vec3> xs = x.subspan(s.first_node, s.mesh.num_vertices());
    const std::size_t first = out.size();
    out.resize(first + s.mesh.num_triangles());
    for (const ShellPatchSet& set : s.sets)
      with_valence(set.valence, [&](auto N) {
        constexpr int K = N() + 6;
        parallel_for_each(static_cast<Index>(set.triangle.size()), [&](Index p) {
          const Index t = set.triangle[p];
          if (!triangle_owned_[b][t]) return;
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
    for (std::size_t k = 0; k < s.sets.size(); ++k) {
      const ShellPatchSet& set = s.sets[k];
      with_valence(set.valence, [&](auto N) {
        compute_set<N()>(s, set, computed_[b][k], mat, xs, first_patch, slot_force_[b], patch_energy_[b], patch_dt_[b]);
      });
      first_patch += static_cast<Index>(set.triangle.size());
    }
    const std::vector<Vec3>& slot = slot_force_[b];
    const std::vector<Index>& vertices = vertices_[b];
    parallel_for_each(static_cast<Index>(vertices.size()), [&](Index i) {
      const Index v = vertices[i];
      Vec3 f = Vec3::Zero();
      for (Index k = s.vertex_slot_offsets[v]; k < s.vertex_slot_offsets[v + 1]; ++k)
        f += s.vertex_slot_weight[k] * slot[s.vertex_slot[k]];
      f_int[s.first_node + v] = f;
    });
    // The energy of the owned patches, exactly (any grouping over the ranks gives the
    // same sum); the stable step over the computed ones (a minimum, exact in any order).
    first_patch = 0;
    for (std::size_t k = 0; k < s.sets.size(); ++k) {
      for (const Index p : computed_[b][k]) {
        if (triangle_owned_[b][s.sets[k].triangle[p]]) r.strain_energy += patch_energy_[b][first_patch + p];
        if (patch_dt_[b][first_patch + p] < r.stable_dt)
          r.stable_dt = patch_dt_[b][first_patch + p], r.worst_body = static_cast<Index>(b);
      }
      first_patch += static_cast<Index>(s.sets[k].triangle.size());
    }
  }
  return r;
}

}  // namespace shatter
