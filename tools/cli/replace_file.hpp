// tools/cli/replace_file.hpp — writing a whole file so that a failed write never leaves half of
// it under the name: the text goes to a new temporary file beside the target and is renamed
// over it when complete. Renaming is right for regular files only: a device node, FIFO,
// socket or directory at the path is refused (a rename turns a device node into a plain file
// for every program on the machine), a symlink is written through to the regular file it
// names, as a plain open would, and the temporary name is unique (mkstemp), so no file the
// program did not create is ever clobbered.
#pragma once

#include "scenes/text_file.hpp"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace magsim::tools {

/// The path names something that must not be replaced by a file (bad input: exit 1).
struct NotARegularFile : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// Writing, flushing or renaming failed (an I/O error: exit 3); what() holds strerror.
struct WriteFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Writes `text` to `path`, replacing it as a whole (see above). `path` may be a regular
/// file (its permission bits are kept), a symlink to one (the target is replaced, the link
/// stays) or absent (created with 0666 & ~umask, as a plain open would). Throws
/// NotARegularFile for anything else, a dangling symlink included; WriteFailed when the
/// temporary file cannot be made, written or renamed (it is removed then).
inline void replace_file(const std::string& path, const std::string& text) {
  std::string target = path;
  mode_t mode;
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) throw WriteFailed(std::string("cannot look at it (") + std::strerror(errno) + ")");
    // a new file gets what open(O_CREAT, 0666) would give it (no other thread makes files
    // while either program writes these)
    const mode_t mask = ::umask(0);
    ::umask(mask);
    mode = 0666 & ~mask;
  } else {
    const bool link = S_ISLNK(st.st_mode);
    if (link) {
      char real[PATH_MAX];
      if (!::realpath(path.c_str(), real) || ::stat(real, &st) != 0)
        throw NotARegularFile(std::string("is a symbolic link that leads to no file (") + std::strerror(errno) + ")");
      target = real;
    }
    if (!S_ISREG(st.st_mode))
      throw NotARegularFile(std::string("is ") + (link ? "a symbolic link to " : "") + scenes::file_kind(st.st_mode) +
                            ", not a regular file; it is not replaced");
    mode = st.st_mode & 07777;
  }
  const std::size_t slash = target.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : target.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? target : target.substr(slash + 1);
  std::string tmp = dir + "." + base + ".XXXXXX";
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0) throw WriteFailed(std::string("cannot create a temporary file beside it (") + std::strerror(errno) + ")");
  auto fail = [&](const char* what, int err) {
    ::unlink(tmp.c_str());
    throw WriteFailed(std::string(what) + " (" + std::strerror(err) + ")");
  };
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      fail("writing failed", err);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fchmod(fd, mode) != 0) {
    const int err = errno;
    ::close(fd);
    fail("cannot set its permissions", err);
  }
  if (::close(fd) != 0) fail("writing failed", errno);
  if (::rename(tmp.c_str(), target.c_str()) != 0) fail("cannot rename the temporary file over it", errno);
}

}  // namespace magsim::tools
