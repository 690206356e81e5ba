#pragma once
// What the HDF5 writers (fields.h5, checkpoint.h5) say and do when HDF5
// fails: no HDF5 diagnostics on stderr (QuietHdf5), one message with the
// OS's reason, and the disk reserve given back (disk_reserve.hpp) so that
// closing the failed file cannot fail too.
#include <hdf5.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "runtime/disk_reserve.hpp"

namespace shatter {

/// "HDF5 failed to <what>" plus, when a system call failed in it, the OS's
/// reason (errno, cleared by the caller before the HDF5 calls; MPI-IO does
/// not always set it, and then a full output folder is told by its free
/// space); gives the disk reserve back.
inline std::string hdf5_write_failure(const std::string& what) {
  int err = errno;
  if (err == 0 && output_folder_is_full()) err = ENOSPC;
  release_disk_space();
  std::string message = "HDF5 failed to " + what;
  if (err != 0) message += std::string(" (") + std::strerror(err) + ")";
  return message;
}

/// Silences HDF5's error stack printing while alive: failures are reported
/// by our own messages.
class QuietHdf5 {
 public:
  QuietHdf5() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  QuietHdf5(const QuietHdf5&) = delete;
  QuietHdf5& operator=(const QuietHdf5&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

}  // namespace shatter
