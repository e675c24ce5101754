#pragma once
// Small raster helpers for the CPU-drawn pictures of projection/ (the display preview, the test
// patterns): sRGB encoding, filled rectangles and text into RGBA8 images, row 0 at the top.
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace facet::raster {

// Linear RGB in [0, 1] (clamped) to sRGB bytes, alpha 255.
glm::u8vec4 srgb8(glm::vec3 linear);

// Fills rect (x, y, width, height; clipped to the image) with `colour`.
void fill_rect(std::vector<std::uint8_t>& rgba, glm::ivec2 size, glm::ivec4 rect,
               glm::u8vec4 colour);

// Draws `text` with its top-left corner at pixel (x, y) in `colour`, `scale` pixels per font unit
// (stb_easy_font: about 6 units per character across, 7 tall). Clipped to the image.
void draw_text(std::vector<std::uint8_t>& rgba, glm::ivec2 size, int x, int y,
               const std::string& text, glm::u8vec4 colour, int scale);

// The width in font units stb_easy_font gives `text`.
int text_width(const std::string& text);

}  // namespace facet::raster
