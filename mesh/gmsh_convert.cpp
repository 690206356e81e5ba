#include "mesh/gmsh_convert.hpp"

#include <gmsh.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "kernels/error.hpp"
#include "mesh/gmsh_model.hpp"

namespace shatter {
namespace {

enum ChildStatus { kConverted = 0, kUnreadable = 3, kUnwritable = 4 };

/// The child's side: open, write, report a failure's message on `out`.
[[noreturn]] void convert(const std::string& path, const std::string& format, const std::string& copy,
                          const std::string& where, int out) {
  int status = kConverted;
  std::string message;
  try {
    open_in_gmsh(path, format, where);
    gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
    gmsh::option::setNumber("Mesh.Binary", 1);
    gmsh::option::setNumber("Mesh.SaveAll", 1);
    try {
      gmsh::write(copy);
    } catch (...) {
      status = kUnwritable;
      message = where + ": cannot write the temporary copy '" + copy + "' of '" + path +
                "' (is the temporary folder writable?)";
    }
  } catch (const InputError& e) {
    status = kUnreadable;
    message = e.what();
  }
  for (std::size_t done = 0; done < message.size();) {
    const ssize_t n = write(out, message.data() + done, message.size() - done);
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  _exit(status);  // no atexit handlers, no destructors of the parent's objects
}

}  // namespace

void convert_to_msh_in_child(const std::string& path, const std::string& format, const std::string& copy,
                             const std::string& where) {
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0)
    throw Error(where + ": cannot create a pipe to convert '" + path + "': " + std::strerror(errno));
  std::fflush(nullptr);  // the child must not write the parent's buffered output again
  const pid_t pid = fork();
  if (pid < 0) {
    close(pipe_fds[0]);
    close(pipe_fds[1]);
    throw Error(where + ": cannot start a process to convert '" + path + "': " + std::strerror(errno));
  }
  if (pid == 0) {
    close(pipe_fds[0]);
    convert(path, format, copy, where, pipe_fds[1]);
  }
  close(pipe_fds[1]);
  std::string message;
  char buffer[4096];
  for (ssize_t n; (n = read(pipe_fds[0], buffer, sizeof buffer)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    message.append(buffer, static_cast<std::size_t>(n));
  }
  close(pipe_fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw Error(where + ": lost the process converting '" + path + "'");
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == kConverted) return;
  if (code == kUnreadable) throw InputError(message);
  if (code == kUnwritable) throw Error(message);
  // A signal, or (under a sanitizer) the sanitizer's exit status.
  const std::string how = WIFSIGNALED(status)
                              ? "signal " + std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status))
                              : "exit status " + std::to_string(code);
  throw InputError(where + ": Gmsh crashed reading '" + path + "' as " + format + " file (" + how +
                   "); expected a well-formed file of that format");
}

}  // namespace shatter
