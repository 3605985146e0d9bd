// render/png_io.hpp — 8-bit RGB PNG files (libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace magsim::render {

/// Writes w × h RGB8 pixels (top row first) at zlib level 1 (fast; ≈ 36 ms for 720p).
/// On failure returns false and, if error is non-null, says why.
bool write_png(const std::string& path, int w, int h, const std::uint8_t* rgb,
               std::string* error);

/// Reads any PNG (grey, palette, alpha and 16-bit are converted) as RGB8, top row first.
bool read_png(const std::string& path, int* w, int* h, std::vector<std::uint8_t>* rgb,
              std::string* error);

}  // namespace magsim::render
