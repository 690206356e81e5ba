#pragma once
// The attribute `failure` of a checkpoint written after a failed step (the
// error's message; docs/errors.md "During a run").
#include <hdf5.h>

#include <filesystem>
#include <string>

namespace shatter::test {

inline std::string failure_attribute(const std::filesystem::path& file) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t a = H5Aopen(f, "failure", H5P_DEFAULT);
  const hid_t t = H5Aget_type(a);
  std::string s(H5Tget_size(t), '\0');
  H5Aread(a, t, s.data());
  H5Tclose(t);
  H5Aclose(a);
  H5Fclose(f);
  return s.c_str();
}

}  // namespace shatter::test
