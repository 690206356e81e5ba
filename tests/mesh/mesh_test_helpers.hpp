#pragma once
// Helpers shared by the mesh tests.
#include <functional>
#include <string>

#include "kernels/error.hpp"
#include "mesh/mesh.hpp"

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

}  // namespace shatter::test
