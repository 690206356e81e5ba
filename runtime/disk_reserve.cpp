#include "runtime/disk_reserve.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

namespace shatter {
namespace {

char g_reserve[4096] = "";  // a fixed buffer: read by a signal handler

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
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return std::strerror(errno);
  const int err = write_all(fd, std::vector<char>(kDiskReserveBytes, 0));
  ::close(fd);
  if (err != 0) {
    ::unlink(file.c_str());
    return std::strerror(err);
  }
  std::strcpy(g_reserve, file.c_str());
  return "";
}

void release_disk_space() {
  if (g_reserve[0] == '\0') return;
  ::unlink(g_reserve);
  g_reserve[0] = '\0';
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
  if (g_reserve[0] == '\0') return false;
  std::error_code ec;
  const std::filesystem::space_info s = std::filesystem::space(std::filesystem::path(g_reserve).parent_path(), ec);
  return !ec && s.available < 64 * 1024;
}

const char* disk_reserve_path() {
  return g_reserve;
}

}  // namespace shatter
