#pragma once
// Blend maps (FORMATS.md §3): `<projector>.blend.exr` holding the blend weight α per output pixel
// (channel Y, or R, G, B for one weight per colour) and the optional `<projector>.black.exr`
// holding the black level β in the same layout. Values are linear light in [0,1]; the composite
// of a linear colour c is c·α·(1−β) + β, encoded afterwards with the output's gamma.
#include <cstddef>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

namespace facet::projection_io {

struct BlendMap {
  glm::ivec2 size{0, 0};      // W, H in output pixels; pixel (0, 0) is the top-left one
  int channels = 1;           // 1 (Y) or 3 (R, G, B)
  std::vector<float> values;  // row-major, `channels` values per pixel

  static BlendMap constant(glm::ivec2 size, float value, int channels = 1);
  float at(int x, int y, int channel = 0) const {
    return values[(std::size_t(y) * size.x + x) * channels + channel];
  }
  float& at(int x, int y, int channel = 0) {
    return values[(std::size_t(y) * size.x + x) * channels + channel];
  }
  // Bilinear value at output position q (pixel centres at half-integers), clamped to the image.
  double sample(glm::dvec2 q, int channel = 0) const;

  // Throws InputError naming `source`: sizes, channel count, values outside [0,1] or non-finite
  // (naming the first bad pixel).
  void validate(const std::string& source = {}) const;
};

// Reads a blend or black-level map. Throws InputError naming the file and the field: not an
// image, missing `facet:blend` header attribute or wrong format string, neither Y nor R,G,B
// channels, values outside [0,1], NaN, or a size other than `expected_size` when given.
BlendMap read_blend_map(const std::string& path,
                        std::optional<glm::ivec2> expected_size = std::nullopt);

// Validates, then writes float32 EXR atomically (temporary file, then rename).
void write_blend_map(const std::string& path, const BlendMap& map);

}  // namespace facet::projection_io
