// render/png_io.cpp — PNG writing with libpng's full API (for the compression level and
// filter choice) and reading with its simplified png_image API (which converts any format).
//
// libpng reports errors by longjmp; write_png_impl keeps only trivially destructible locals
// between setjmp and the calls that may jump, so jumping out of it is well defined.
#include "render/png_io.hpp"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace magsim::render {

namespace {

struct PngErrorState {
  char message[256];
};

void png_error_fn(png_structp png, png_const_charp msg) {
  auto* st = static_cast<PngErrorState*>(png_get_error_ptr(png));
  // libpng's "Write Error" comes from a failed fwrite: errno says why (a full disk, EFBIG)
  const int err = errno;
  if (err != 0)
    std::snprintf(st->message, sizeof st->message, "%s (%s)", msg ? msg : "unknown libpng error", std::strerror(err));
  else
    std::snprintf(st->message, sizeof st->message, "%s", msg ? msg : "unknown libpng error");
  png_longjmp(png, 1);
}

void png_warning_fn(png_structp, png_const_charp) {}

// returns nullptr on success, else a message (static or in `st`)
const char* write_png_impl(std::FILE* f, int w, int h, const std::uint8_t* rgb,
                           PngErrorState* st) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, st, png_error_fn,
                                            png_warning_fn);
  if (!png) return "png_create_write_struct failed";
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    return "png_create_info_struct failed";
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return st->message;
  }
  png_init_io(png, f);
  png_set_compression_level(png, 1);
  // the "sub" filter alone: nearly the size of adaptive filtering at a fraction of the time
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, png_uint_32(w), png_uint_32(h), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(png, info);
  const std::size_t stride = std::size_t(w) * 3;
  for (int y = 0; y < h; ++y)
    png_write_row(png, const_cast<png_bytep>(rgb + std::size_t(y) * stride));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return nullptr;
}

void set_error(std::string* error, const std::string& msg) {
  if (error) *error = msg;
}

// The process's umask without changing it (umask(2) can only be read by setting it, which
// would race with other threads creating files): /proc/self/status "Umask:", else 022.
mode_t current_umask() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  unsigned mask = 022;
  if (f) {
    char line[256];
    while (std::fgets(line, sizeof line, f))
      if (std::sscanf(line, "Umask: %o", &mask) == 1) break;
    std::fclose(f);
  }
  return static_cast<mode_t>(mask & 0777);
}

}  // namespace

// Written to a unique temporary file beside `path` (".NAME.XXXXXX") and renamed over it when
// complete: a failed write (a full disk, a file size limit) removes the temporary file and
// leaves no truncated PNG under the frame's name.
bool write_png(const std::string& path, int w, int h, const std::uint8_t* rgb,
               std::string* error) {
  if (w <= 0 || h <= 0 || !rgb) {
    set_error(error, "write_png: empty image for " + path);
    return false;
  }
  const std::size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  std::string tmp = dir + "." + base + ".XXXXXX";
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0) {
    set_error(error, "write_png: cannot open " + path + ": " + std::strerror(errno));
    return false;
  }
  static const mode_t mask = current_umask();
  if (::fchmod(fd, 0666 & ~mask) != 0) {  // mkstemp makes 0600; a frame is as fopen would make it
    set_error(error, "write_png: cannot set the permissions of " + tmp + ": " + std::strerror(errno));
    ::close(fd);
    ::unlink(tmp.c_str());
    return false;
  }
  std::FILE* f = ::fdopen(fd, "wb");
  if (!f) {
    set_error(error, "write_png: cannot open " + path + ": " + std::strerror(errno));
    ::close(fd);
    ::unlink(tmp.c_str());
    return false;
  }
  PngErrorState st{};
  errno = 0;
  const char* msg = write_png_impl(f, w, h, rgb, &st);
  errno = 0;
  const bool flushed = std::fflush(f) == 0 && !std::ferror(f);
  const int flush_errno = errno;
  const bool closed = std::fclose(f) == 0;
  const int close_errno = errno;
  if (msg || !flushed || !closed) {
    ::unlink(tmp.c_str());
    if (msg) set_error(error, "write_png: " + path + ": " + msg);
    else
      set_error(error, "write_png: error writing " + path + ": " +
                           std::strerror(!flushed ? (flush_errno ? flush_errno : EIO) : (close_errno ? close_errno : EIO)));
    return false;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    set_error(error, "write_png: cannot rename " + tmp + " to " + path + ": " + std::strerror(err));
    return false;
  }
  return true;
}

bool read_png(const std::string& path, int* w, int* h, std::vector<std::uint8_t>* rgb,
              std::string* error) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) {
    set_error(error, "read_png: " + path + ": " + image.message);
    png_image_free(&image);
    return false;
  }
  image.format = PNG_FORMAT_RGB;
  rgb->resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, rgb->data(), 0, nullptr)) {
    set_error(error, "read_png: " + path + ": " + image.message);
    png_image_free(&image);
    return false;
  }
  *w = int(image.width);
  *h = int(image.height);
  return true;
}

}  // namespace magsim::render
