#include "runtime/output_folder.hpp"

#include "kernels/error.hpp"
#include "runtime/disk_reserve.hpp"

namespace shatter {

void on_root_for_all(MPI_Comm comm, const std::function<void()>& check) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string error;
  if (rank == 0) try {
      check();
    } catch (const InputError& e) {
      error = e.what();
    }
  int length = static_cast<int>(error.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, comm);
  if (length == 0) return;
  error.resize(static_cast<std::size_t>(length));
  MPI_Bcast(error.data(), length, MPI_CHAR, 0, comm);
  throw InputError(error);
}

void refuse_non_file_at(const std::filesystem::path& file, bool devices) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(file, ec);  // through links
  if (!std::filesystem::exists(st) || std::filesystem::is_regular_file(st)) return;
  if (!devices && !std::filesystem::is_directory(st)) return;
  const std::string what = std::filesystem::is_directory(st) ? "a folder" : "not a regular file (a device or a pipe)";
  throw InputError("output folder " + file.parent_path().string() + ": " + file.string() + " is " + what +
                   "; expected a file the run can replace, or nothing");
}

void prepare_output_folder(const std::filesystem::path& dir, MPI_Comm comm) {
  on_root_for_all(comm, [&] {
    const std::string where = "output folder " + dir.string();
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw InputError(where + ": cannot create it (" + ec.message() + ")");
    if (!std::filesystem::is_directory(dir, ec))
      throw InputError(where + ": it exists and is not a folder");
    // The disk reserve (disk_reserve.hpp), written now: a read-only or full
    // file system is found here, with the OS's reason, not by an output.
    const std::string reason = reserve_disk_space(dir);
    if (!reason.empty()) throw InputError(where + ": cannot write in it (" + reason + ")");
    // A device under a CSV or JSON file fails its first write cleanly (and
    // is how tests/mpi/failures.sh fails rank 0 alone); under an HDF5 file
    // it would fail a close (disk_reserve.hpp).
    for (const char* name : {"history.csv", "bodies.csv", "fields.xdmf", "summary.json", "fragments.csv"})
      refuse_non_file_at(dir / name, false);
    for (const char* name : {"fields.h5", "checkpoint.h5", "checkpoint.h5.tmp"}) refuse_non_file_at(dir / name, true);
  });
}

}  // namespace shatter
