#pragma once
// The one place where the driver turns rows over. facet's images have row 0 at the top (the
// output pixels of the warp, image files, the maps of display.json); GL textures and framebuffers
// have row 0 at the bottom. Every copy between the two takes its row from here.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace facet::driver {

// Row `y` of an image `height` rows high counted from the other end: the GL row of an image row,
// and the image row of a GL row.
constexpr int flipped_row(int y, int height) { return height - 1 - y; }

// The index of the first of the `row_values` values of that row.
constexpr std::size_t flipped_row_start(int y, int height, std::size_t row_values) {
  return std::size_t(flipped_row(y, height)) * row_values;
}

// `pixels` (rows of `row_values` values) with the order of its rows reversed, in place.
template <typename T>
void flip_rows(std::vector<T>& pixels, std::size_t row_values) {
  const std::size_t rows = pixels.size() / row_values;
  for (std::size_t j = 0; j < rows / 2; ++j) {
    std::swap_ranges(pixels.begin() + std::ptrdiff_t(j * row_values),
                     pixels.begin() + std::ptrdiff_t((j + 1) * row_values),
                     pixels.begin() + std::ptrdiff_t((rows - 1 - j) * row_values));
  }
}

}  // namespace facet::driver
