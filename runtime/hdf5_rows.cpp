#include "runtime/hdf5_rows.hpp"

#include <array>
#include <cerrno>

#include "kernels/error.hpp"
#include "runtime/hdf5_failure.hpp"

namespace shatter {
namespace {

H5Id checked(hid_t id, herr_t (*close)(hid_t), const std::string& who, const std::string& what) {
  SHATTER_REQUIRE(id >= 0, who << ": " << hdf5_write_failure(what));
  return H5Id(id, close);
}

void check(herr_t status, const std::string& who, const std::string& what) {
  SHATTER_REQUIRE(status >= 0, who << ": " << hdf5_write_failure(what));
}

}  // namespace

H5Id mpio_access(MPI_Comm comm, const std::string& who) {
  H5Id fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, who, "create a file access list");
  check(H5Pset_fapl_mpio(fapl.get(), comm, MPI_INFO_NULL), who, "select the MPI-IO driver");
  check(H5Pset_coll_metadata_write(fapl.get(), true), who, "request collective metadata writes");
  return fapl;
}

void write_rows(hid_t group, const char* name, hid_t mem_type, hid_t file_type, const void* data, const Rows& rows,
                hsize_t cols, const std::string& who, hid_t dcpl, bool collective) {
  const int rank = cols == 0 ? 1 : 2;
  const std::array<hsize_t, 2> dims{rows.total, cols};
  const std::array<hsize_t, 2> local{rows.local, cols};
  const std::array<hsize_t, 2> start{rows.offset, 0};
  errno = 0;  // hdf5_write_failure reports the OS's reason of a failure in here
  H5Id file_space = checked(H5Screate_simple(rank, dims.data(), nullptr), H5Sclose, who,
                            std::string("create the dataspace of ") + name);
  H5Id dset = checked(H5Dcreate2(group, name, file_type, file_space.get(), H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose,
                      who, std::string("create dataset ") + name);
  if (rows.total == 0) return;  // (a collective transfer to an empty dataset fails)
  H5Id mem_space = checked(H5Screate_simple(rank, local.data(), nullptr), H5Sclose, who,
                           std::string("create the memory space of ") + name);
  if (rows.local == 0) {
    // A rank without rows still joins the collective transfer.
    check(H5Sselect_none(file_space.get()), who, "select nothing");
    check(H5Sselect_none(mem_space.get()), who, "select nothing");
  } else {
    check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, local.data(), nullptr), who,
          std::string("select the rows of ") + name);
  }
  H5Id xfer = checked(H5Pcreate(H5P_DATASET_XFER), H5Pclose, who, "create a transfer list");
  if (collective) check(H5Pset_dxpl_mpio(xfer.get(), H5FD_MPIO_COLLECTIVE), who, "request collective transfer");
  static const double no_data = 0.0;
  check(H5Dwrite(dset.get(), mem_type, mem_space.get(), file_space.get(), xfer.get(), data ? data : &no_data), who,
        std::string("write dataset ") + name);
}

}  // namespace shatter
