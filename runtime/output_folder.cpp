#include "runtime/output_folder.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "kernels/error.hpp"

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

void refuse_folder_at(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError("output folder " + file.parent_path().string() + ": " + file.string() +
                     " is a folder; expected a file the run can replace, or nothing");
}

void prepare_output_folder(const std::filesystem::path& dir, MPI_Comm comm) {
  on_root_for_all(comm, [&] {
    const std::string where = "output folder " + dir.string();
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw InputError(where + ": cannot create it (" + ec.message() + ")");
    if (!std::filesystem::is_directory(dir, ec))
      throw InputError(where + ": it exists and is not a folder");
    // A file written and removed: a read-only or full file system is found
    // here, with the OS's reason, rather than by the first output of the run.
    const std::filesystem::path probe = dir / ".shatter_write_probe";
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int err = fd < 0 ? errno : 0;
    if (fd >= 0) {
      const char byte = 0;
      if (::write(fd, &byte, 1) != 1 || ::fsync(fd) != 0) err = errno;
      if (::close(fd) != 0 && err == 0) err = errno;
      ::unlink(probe.c_str());
    }
    if (err != 0) throw InputError(where + ": cannot write in it (" + std::strerror(err) + ")");
    for (const char* name : {"history.csv", "bodies.csv", "fields.h5", "fields.xdmf", "summary.json",
                             "fragments.csv", "checkpoint.h5", "checkpoint.h5.tmp"})
      refuse_folder_at(dir / name);
  });
}

}  // namespace shatter
