#pragma once
// Helpers shared by the mesh tests.
#include <functional>
#include <string>

#include "kernels/error.hpp"
#include "mesh/mesh.hpp"
#include "mesh/shell_mesh.hpp"

namespace shatter::test {

/// Sum of the elements' reference volumes, m^3.
inline double total_volume(const Mesh& m) {
  double v = 0;
  for (Index e = 0; e < m.num_elements(); ++e) v += element_reference_volume(m, e);
  return v;
}

/// The message of the InputError `f` throws, or "" when it throws none.
inline std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// An n x n square lattice of spacing h in z = 0, vertex (i, j) at index
/// i + n j, every cell split along the same diagonal: interior vertices of
/// valence 6, right-angled corners of 1 and 2 triangles.
inline ShellMesh square_shell_lattice(int n, double h, const std::string& where) {
  std::vector<Vec3> x;
  std::vector<std::array<Index, 3>> tris;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) x.emplace_back(i * h, j * h, 0);
  auto id = [n](int i, int j) { return Index(i + n * j); };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      tris.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
      tris.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return build_shell_mesh(std::move(x), std::move(tris), where);
}

}  // namespace shatter::test
