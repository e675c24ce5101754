#pragma once
// Portable float maps (PFM), the geometry warp files of MPCDI.
//
// A PFM is the text header "PF" (three channels) or "Pf" (one channel), then "W H", then a scale
// whose sign gives the byte order (negative: little-endian), each on its own line, followed by
// W·H·channels float32 values, row after row. Plain PFM stores the bottom row first; MPCDI (and
// the files SGCT writes) store the top row first. This reader does not reorder anything: row 0 of
// the result is the first row in the file, and the caller says what it means.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace facet::interop {

struct PfmImage {
  int width = 0, height = 0;
  int channels = 3;           // 1 or 3
  std::vector<float> values;  // row-major in file order, `channels` values per pixel; may be NaN

  float at(int x, int y, int c) const {
    return values[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels) +
                  std::size_t(c)];
  }
};

// Largest width·height accepted, so that a hostile header cannot ask for gigabytes.
inline constexpr std::size_t kMaxPfmPixels = std::size_t(1) << 26;

// Parses a whole PFM file held in memory. Throws InputError(source, field, expected) for a bad
// magic, size or scale line, a size of 0 or above kMaxPfmPixels, or too few data bytes. Bytes
// after the data are ignored. Values are returned as stored (NaN and Inf included).
PfmImage parse_pfm(std::string_view bytes, const std::string& source);

// The file bytes: "PF"/"Pf", little-endian (scale −1), rows in the order of `image.values`.
std::string format_pfm(const PfmImage& image);

}  // namespace facet::interop
