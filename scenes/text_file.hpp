// scenes/text_file.hpp — reading an input file (a scene file, a magsolve case) whole, from
// regular files only and up to a size bound. A FIFO without a writer would block for ever,
// /dev/zero would be read until memory runs out, and a directory reads as nothing: each is
// refused by name before a byte is read. Header-only: scene files (magsim_scenes) and
// magsolve (magnetics only) both use it.
#pragma once

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace magsim::scenes {

/// The largest input file read (1 GiB): a million bodies as written by --write-scene take
/// about half of it, and the parsed document needs several times the text.
constexpr long long kMaxInputBytes = 1LL << 30;

/// Thrown by read_text_file; what() says what is wrong without the path ("is a FIFO, not a
/// regular file"), so each caller words it in its own error line.
struct InputFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What a file of this st_mode is, for "is a ..., not a regular file".
inline const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "a file of unknown kind";
}

/// The whole of the regular file at `path` (symlinks followed); throws InputFileError for
/// anything else, a file above kMaxInputBytes or a failed read. The file is opened without
/// blocking (O_NONBLOCK: a FIFO would wait for a writer) and checked with fstat on the
/// descriptor that is read, so what is checked is what is read.
inline std::string read_text_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) throw InputFileError(std::string("cannot open (") + std::strerror(errno) + ")");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw InputFileError(std::string("cannot read (") + std::strerror(errno) + ")");
  if (S_ISDIR(st.st_mode)) throw InputFileError("is a directory, not a file");
  if (!S_ISREG(st.st_mode)) throw InputFileError(std::string("is ") + file_kind(st.st_mode) + ", not a regular file");
  const auto too_big = [] {
    return InputFileError("larger than " + std::to_string(kMaxInputBytes >> 30) + " GiB, the bound on input files");
  };
  if (st.st_size > kMaxInputBytes) throw too_big();
  std::string text;
  text.reserve(static_cast<std::size_t>(st.st_size));
  char buf[1 << 16];
  for (;;) {  // to the end, not to st_size: /proc files say 0, a file may grow meanwhile
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputFileError(std::string("cannot read (") + std::strerror(errno) + ")");
    }
    if (static_cast<long long>(text.size()) + n > kMaxInputBytes) throw too_big();
    text.append(buf, static_cast<std::size_t>(n));
  }
  return text;
}

}  // namespace magsim::scenes
