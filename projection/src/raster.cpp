#include "raster.hpp"

#include <stb/stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace facet::raster {

glm::u8vec4 srgb8(glm::vec3 linear) {
  auto encode = [](float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    const float e = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1 / 2.4f) - 0.055f;
    return std::uint8_t(std::lround(e * 255));
  };
  return {encode(linear.x), encode(linear.y), encode(linear.z), 255};
}

void fill_rect(std::vector<std::uint8_t>& rgba, glm::ivec2 size, glm::ivec4 rect,
               glm::u8vec4 colour) {
  for (int py = std::max(rect.y, 0); py < std::min(rect.y + rect.w, size.y); ++py)
    for (int px = std::max(rect.x, 0); px < std::min(rect.x + rect.z, size.x); ++px)
      std::copy_n(&colour[0], 4, &rgba[(std::size_t(py) * size.x + px) * 4]);
}

void draw_text(std::vector<std::uint8_t>& rgba, glm::ivec2 size, int x, int y,
               const std::string& text, glm::u8vec4 colour, int scale) {
  // stb_easy_font writes 4 vertices (x, y, z, colour: 16 bytes) per quad.
  std::vector<char> buffer(text.size() * 64 * 16 + 1024);
  std::string copy = text;
  const int quads =
      stb_easy_font_print(0, 0, copy.data(), nullptr, buffer.data(), int(buffer.size()));
  for (int q = 0; q < quads; ++q) {
    float v[16];  // the quad's 4 vertices: x, y, z and a packed colour each
    std::memcpy(v, buffer.data() + std::size_t(q) * sizeof v, sizeof v);
    const float k = float(scale);
    const int x0 = x + int(std::lround(v[0] * k)), y0 = y + int(std::lround(v[1] * k));
    const int x1 = x + int(std::lround(v[8] * k)), y1 = y + int(std::lround(v[9] * k));
    for (int py = std::max(y0, 0); py < std::min(y1, size.y); ++py)
      for (int px = std::max(x0, 0); px < std::min(x1, size.x); ++px)
        std::copy_n(&colour[0], 4, &rgba[(std::size_t(py) * size.x + px) * 4]);
  }
}

int text_width(const std::string& text) {
  std::string copy = text;
  return stb_easy_font_width(copy.data());
}

}  // namespace facet::raster
