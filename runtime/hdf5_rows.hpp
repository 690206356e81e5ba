#pragma once
// What the two HDF5 writers share (fields.h5, runtime/field_output.hpp, and
// checkpoint.h5, runtime/checkpoint.hpp): identifiers closed on scope exit,
// a file access list for the MPI-IO driver, and a dataset whose rows the
// ranks write collectively, each one contiguous block of them.
#include <hdf5.h>
#include <mpi.h>

#include <string>

namespace shatter {

/// Owns one HDF5 identifier and closes it with the matching H5?close.
class H5Id {
 public:
  H5Id() = default;
  H5Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  H5Id(const H5Id&) = delete;
  H5Id& operator=(const H5Id&) = delete;
  H5Id(H5Id&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
  H5Id& operator=(H5Id&& o) noexcept {
    reset();
    id_ = o.id_;
    close_ = o.close_;
    o.id_ = H5I_INVALID_HID;
    return *this;
  }
  ~H5Id() { reset(); }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset() {
    if (id_ >= 0) close_(id_);
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*close_)(hid_t) = nullptr;
};

/// Row placement of one rank's block of a global array.
struct Rows {
  hsize_t local = 0;   ///< rows this rank writes
  hsize_t offset = 0;  ///< first global row of this rank
  hsize_t total = 0;   ///< rows of all ranks
};

/// A file access list for the MPI-IO driver on `comm`, metadata written
/// collectively. Throws Error "`who`: HDF5 failed to ..." when HDF5 fails.
H5Id mpio_access(MPI_Comm comm, const std::string& who);

/// Creates dataset `name` in `group` with `rows.total` x `cols` entries (1-D
/// when cols == 0; creation list `dcpl`) and writes this rank's rows `data`
/// at rows.offset, collectively when `collective` (the file is open with the
/// MPI-IO driver on several ranks; a rank without rows still joins).
/// Throws Error "`who`: HDF5 failed to ..." when HDF5 fails.
void write_rows(hid_t group, const char* name, hid_t mem_type, hid_t file_type, const void* data, const Rows& rows,
                hsize_t cols, const std::string& who, hid_t dcpl = H5P_DEFAULT, bool collective = true);

}  // namespace shatter
