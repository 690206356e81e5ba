#include "mesh/reorder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace shatter {

namespace {
// Spread the low 21 bits of v so that bit i lands at bit 3 i.
std::uint64_t spread_bits3(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

template <class T>
void permute(std::vector<T>& a, const std::vector<Index>& new_of_old) {
  if (a.empty()) return;
  std::vector<T> out(a.size());
  for (size_t i = 0; i < a.size(); ++i) out[new_of_old[i]] = std::move(a[i]);
  a.swap(out);
}
}  // namespace

std::uint64_t morton_code(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  constexpr double kCells = double(1 << 21);
  std::uint64_t code = 0;
  for (int k = 0; k < 3; ++k) {
    const double ext = hi[k] - lo[k];
    double t = ext > 0 ? (p[k] - lo[k]) / ext : 0.0;
    t = std::clamp(t * kCells, 0.0, kCells - 1.0);
    code |= spread_bits3(static_cast<std::uint64_t>(t)) << k;
  }
  return code;
}

std::pair<Vec3, Vec3> bounding_cube(std::span<const Vec3> points) {
  Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return {lo, lo + Vec3::Constant((hi - lo).maxCoeff())};
}

MeshPermutation reorder_for_locality(Mesh& mesh, GlobalIdPolicy gids) {
  const Index n = mesh.num_nodes(), ne = mesh.num_elements();
  const int k = mesh.nodes_per_element();
  MeshPermutation perm;
  if (ne == 0) {
    perm.node_new_of_old.resize(n);
    std::iota(perm.node_new_of_old.begin(), perm.node_new_of_old.end(), 0);
    return perm;
  }
  // Element order: Morton code of the corner centroid in the mesh's cube, stable on ties.
  const auto [lo, hi] = bounding_cube(mesh.reference);
  const std::vector<Index> old_of_new = morton_order(
      ne,
      [&](Index e) {
        const Index* c = mesh.element(e);
        return Vec3(0.25 * (mesh.reference[c[0]] + mesh.reference[c[1]] + mesh.reference[c[2]] +
                            mesh.reference[c[3]]));
      },
      lo, hi);
  perm.elem_new_of_old.resize(ne);
  for (Index i = 0; i < ne; ++i) perm.elem_new_of_old[old_of_new[i]] = i;

  // Node order: first use by the sorted elements.
  perm.node_new_of_old.assign(n, -1);
  Index next = 0;
  for (Index i = 0; i < ne; ++i) {
    const Index* c = mesh.element(old_of_new[i]);
    for (int a = 0; a < k; ++a)
      if (perm.node_new_of_old[c[a]] < 0) perm.node_new_of_old[c[a]] = next++;
  }
  for (Index v = 0; v < n; ++v)
    if (perm.node_new_of_old[v] < 0) perm.node_new_of_old[v] = next++;

  std::vector<Index> conn(mesh.conn.size());
  for (Index i = 0; i < ne; ++i) {
    const Index* c = mesh.element(old_of_new[i]);
    for (int a = 0; a < k; ++a) conn[static_cast<size_t>(i) * k + a] = perm.node_new_of_old[c[a]];
  }
  mesh.conn.swap(conn);
  permute(mesh.elem_gid, perm.elem_new_of_old);
  permute(mesh.elem_body, perm.elem_new_of_old);
  permute(mesh.elem_material, perm.elem_new_of_old);
  permute(mesh.reference, perm.node_new_of_old);
  permute(mesh.node_gid, perm.node_new_of_old);
  permute(mesh.node_body, perm.node_new_of_old);
  if (gids == GlobalIdPolicy::renumber) {
    std::sort(mesh.node_gid.begin(), mesh.node_gid.end());
    std::sort(mesh.elem_gid.begin(), mesh.elem_gid.end());
  }
  mesh.build_node_elements();
  ++mesh.revision;
  return perm;
}

}  // namespace shatter
