#include "runtime/disk_reserve.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <vector>

namespace shatter {
namespace {

// A fixed buffer, read by a signal handler once g_named says it holds the
// whole path: the path is published before the file is created, so a stop
// during the write (1 MiB and an fsync: slow on a busy disk) removes it too.
char g_reserve[4096] = "";
volatile std::sig_atomic_t g_named = 0;

/// Writes all of `bytes`; returns 0 or the errno of the failure (ENOSPC when
/// the file system took fewer bytes without saying why).
int write_all(int fd, const std::vector<char>& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    errno = 0;
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return errno != 0 ? errno : ENOSPC;
    done += static_cast<std::size_t>(n);
  }
  return ::fsync(fd) == 0 ? 0 : errno;
}

}  // namespace

std::string reserve_disk_space(const std::filesystem::path& dir) {
  release_disk_space();
  const std::filesystem::path file = dir / ".shatter_reserve";
  if (file.native().size() >= sizeof g_reserve) return "path too long";
  std::strcpy(g_reserve, file.c_str());
  g_named = 1;
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int err = fd < 0 ? errno : write_all(fd, std::vector<char>(kDiskReserveBytes, 0));
  if (fd >= 0) ::close(fd);
  if (err != 0) {
    release_disk_space();
    return std::strerror(err);
  }
  return "";
}

void release_disk_space() {
  if (!g_named) return;
  ::unlink(g_reserve);  // before the flag falls: a stop in between unlinks it again, harmlessly
  g_named = 0;
}

std::string lacking_space(const std::filesystem::path& dir, std::uintmax_t bytes) {
  std::error_code ec;
  const std::filesystem::space_info s = std::filesystem::space(dir.empty() ? "." : dir, ec);
  const std::uintmax_t needed = bytes + kDiskReserveBytes / 4;
  if (ec || s.available >= needed) return "";
  return std::string(std::strerror(ENOSPC)) + " (" + std::to_string(s.available / 1024) + " kB free, about " +
         std::to_string(needed / 1024) + " kB needed)";
}

bool output_folder_is_full() {
  if (!g_named) return false;
  std::error_code ec;
  const std::filesystem::space_info s = std::filesystem::space(std::filesystem::path(g_reserve).parent_path(), ec);
  return !ec && s.available < 64 * 1024;
}

const char* disk_reserve_path() {
  return g_named ? g_reserve : "";
}

}  // namespace shatter
