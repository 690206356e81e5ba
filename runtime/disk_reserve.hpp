#pragma once
// A little disk space kept in reserve for the HDF5 writers (fields.h5,
// checkpoint.h5; docs/errors.md, "Output files"). HDF5 1.10 frees a file
// whose close fails (its last metadata flush, on a full disk) but keeps its
// identifier, and closes it again when MPI_Finalize ends the library: a
// segmentation fault at exit. So a run writes `.shatter_reserve`
// (kDiskReserveBytes) in its output folder before anything else, and a
// writer whose write failed gives the space back before its file is closed:
// the close then finds room for its metadata and succeeds.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace shatter {

inline constexpr std::size_t kDiskReserveBytes = std::size_t(1) << 20;

/// Creates `dir`/.shatter_reserve of kDiskReserveBytes (written and synced);
/// returns "" or the OS reason it could not be (then no file is left).
std::string reserve_disk_space(const std::filesystem::path& dir);

/// Removes the reserve file, if any (a write failed, or the run ends).
void release_disk_space();

/// "" when the file system of `dir` has room for `bytes` (plus a quarter
/// of kDiskReserveBytes of slack for HDF5's metadata), else the reason: "No
/// space left on device (N kB free, about M kB needed)". Checked before an
/// HDF5 file or frame is written, because HDF5 1.10 cannot close a file
/// whose flush failed (the reserve alone does not save that case).
std::string lacking_space(const std::filesystem::path& dir, std::uintmax_t bytes);

/// True when the folder of the reserve file has less than 64 kB free (the
/// reason of a write that failed without an errno); false without a reserve.
bool output_folder_is_full();

/// The reserve file's path as a C string ("" when none), for a signal
/// handler to unlink (async-signal-safe).
const char* disk_reserve_path();

}  // namespace shatter
