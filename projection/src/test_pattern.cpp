#include "facet/projection/test_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "facet/projection/display_preview.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "raster.hpp"

namespace facet {
namespace {

constexpr double kDegree = std::numbers::pi / 180;

// Distance of `angle` from the nearest multiple of `step` (radians).
double off_line(double angle, double step) {
  return std::abs(angle - std::round(angle / step) * step);
}

std::vector<std::uint8_t> latlong_image(const Warp& warp) {
  const glm::ivec2 size = warp.output_size;
  const std::vector<glm::dvec2> st = WarpInverse(warp).st_at_pixel_centres();
  std::vector<glm::dvec3> v(st.size(), glm::dvec3(0.0));
  for (std::size_t i = 0; i < st.size(); ++i)
    if (std::isfinite(st[i].x)) v[i] = glm::normalize(warp.v_eye_from_st(st[i]));
  std::vector<std::uint8_t> rgba(std::size_t(size.x) * size.y * 4, 0);
  for (std::size_t i = 3; i < rgba.size(); i += 4) rgba[i] = 255;
  auto direction = [&](int x, int y) -> const glm::dvec3& {
    return v[std::size_t(y) * size.x + x];
  };
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      const glm::dvec3& here = direction(x, y);
      if (here == glm::dvec3(0.0)) continue;
      // The pixel's angular size: the widest step to a covered neighbour.
      double pixel = 0;
      for (const glm::ivec2 step :
           {glm::ivec2(1, 0), glm::ivec2(-1, 0), glm::ivec2(0, 1), glm::ivec2(0, -1)}) {
        const glm::ivec2 n = glm::ivec2(x, y) + step;
        if (n.x < 0 || n.y < 0 || n.x >= size.x || n.y >= size.y) continue;
        const glm::dvec3& there = direction(n.x, n.y);
        if (there == glm::dvec3(0.0)) continue;
        pixel = std::max(pixel, std::acos(std::clamp(glm::dot(here, there), -1.0, 1.0)));
      }
      if (!(pixel > 0)) continue;
      const double elevation = std::asin(std::clamp(here.y, -1.0, 1.0));
      const double azimuth = std::atan2(here.x, -here.z);  // 0 ahead, +90° right
      const double across = std::cos(elevation);           // azimuth angles shrink by this
      glm::vec3 colour{0.0f};
      // Fine lines one pixel wide, the 30° ones two, the horizon and the front meridian three.
      if (off_line(elevation, 10 * kDegree) < 0.5 * pixel ||
          (across > 0.17 && off_line(azimuth, 10 * kDegree) * across < 0.5 * pixel))
        colour = glm::vec3(0.25f);
      if (off_line(elevation, 30 * kDegree) < pixel ||
          (across > 0.05 && off_line(azimuth, 30 * kDegree) * across < pixel))
        colour = glm::vec3(1.0f);
      if (std::abs(elevation) < 1.5 * pixel) colour = {0.0f, 1.0f, 0.0f};
      if (across > 0.05 && std::abs(azimuth) * across < 1.5 * pixel) colour = {1.0f, 0.0f, 0.0f};
      const glm::u8vec4 encoded = raster::srgb8(colour);
      std::copy_n(&encoded[0], 4, &rgba[(std::size_t(y) * size.x + x) * 4]);
    }
  return rgba;
}

std::vector<std::uint8_t> grid_image(glm::ivec2 size, std::size_t index, const std::string& name) {
  std::vector<std::uint8_t> rgba(std::size_t(size.x) * size.y * 4, 0);
  for (std::size_t i = 3; i < rgba.size(); i += 4) rgba[i] = 255;
  const glm::u8vec4 fine{110, 110, 110, 255}, bold{255, 255, 255, 255};
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      const bool border = x < 2 || y < 2 || x >= size.x - 2 || y >= size.y - 2;
      const bool centre = std::abs(2 * x + 1 - size.x) <= 2 || std::abs(2 * y + 1 - size.y) <= 2;
      glm::u8vec4 colour{0, 0, 0, 255};
      if (x % 32 == 0 || y % 32 == 0) colour = fine;
      if (x % 128 == 0 || y % 128 == 0 || border || centre) colour = bold;
      std::copy_n(&colour[0], 4, &rgba[(std::size_t(y) * size.x + x) * 4]);
    }
  const int scale = std::max(1, size.y / 300);
  raster::draw_text(rgba, size, 6 * scale, 6 * scale,
                    name + " (" + std::to_string(index) + ") " + std::to_string(size.x) + "x" +
                        std::to_string(size.y),
                    raster::srgb8(preview_projector_colour(index)), scale);
  return rgba;
}

std::vector<std::uint8_t> ids_image(glm::ivec2 size, std::size_t index, const std::string& name) {
  const glm::u8vec4 background = raster::srgb8(0.5f * preview_projector_colour(index));
  std::vector<std::uint8_t> rgba(std::size_t(size.x) * size.y * 4);
  for (std::size_t i = 0; i < rgba.size(); i += 4) std::copy_n(&background[0], 4, &rgba[i]);
  // The name across about 60% of the width, the index under it.
  const int name_units = std::max(1, raster::text_width(name));
  const int scale = std::max(1, std::min(size.x * 6 / 10 / name_units, size.y / 4 / 8));
  const int name_x = (size.x - name_units * scale) / 2, name_y = size.y / 2 - 8 * scale;
  raster::draw_text(rgba, size, name_x, name_y, name, {255, 255, 255, 255}, scale);
  const std::string number = "#" + std::to_string(index);
  const int small = std::max(1, scale / 2);
  raster::draw_text(rgba, size, (size.x - raster::text_width(number) * small) / 2,
                    size.y / 2 + 2 * scale, number, {255, 255, 255, 255}, small);
  return rgba;
}

}  // namespace

std::string to_string(TestPattern pattern) {
  switch (pattern) {
    case TestPattern::grid:
      return "grid";
    case TestPattern::latlong:
      return "latlong";
    case TestPattern::projector_ids:
      return "projector-ids";
    case TestPattern::white:
      return "white";
    case TestPattern::black:
      return "black";
    case TestPattern::checker:
      return "checker";
  }
  return "grid";
}

const std::vector<TestPattern>& all_test_patterns() {
  static const std::vector<TestPattern> patterns = {
      TestPattern::grid,  TestPattern::latlong, TestPattern::projector_ids,
      TestPattern::white, TestPattern::black,   TestPattern::checker};
  return patterns;
}

TestPattern test_pattern_from_string(const std::string& name, const std::string& source,
                                     const std::string& field) {
  for (TestPattern pattern : all_test_patterns())
    if (name == to_string(pattern)) return pattern;
  throw InputError(source, field,
                   "grid, latlong, projector-ids, white, black or checker, got '" + name + "'");
}

bool test_pattern_is_blended(TestPattern pattern) {
  return pattern == TestPattern::latlong || pattern == TestPattern::white ||
         pattern == TestPattern::black;
}

std::vector<std::uint8_t> test_pattern_image(TestPattern pattern, const Warp& warp,
                                             std::size_t index, const std::string& name) {
  const glm::ivec2 size = warp.output_size;
  const std::size_t bytes = std::size_t(size.x) * size.y * 4;
  switch (pattern) {
    case TestPattern::grid:
      return grid_image(size, index, name);
    case TestPattern::latlong:
      return latlong_image(warp);
    case TestPattern::projector_ids:
      return ids_image(size, index, name);
    case TestPattern::white:
      return std::vector<std::uint8_t>(bytes, 255);
    case TestPattern::black: {
      std::vector<std::uint8_t> rgba(bytes, 0);
      for (std::size_t i = 3; i < bytes; i += 4) rgba[i] = 255;
      return rgba;
    }
    case TestPattern::checker: {
      std::vector<std::uint8_t> rgba(bytes, 255);
      for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x)
          if ((x / 64 + y / 64) % 2)
            std::fill_n(&rgba[(std::size_t(y) * size.x + x) * 4], 3, std::uint8_t(0));
      return rgba;
    }
  }
  return std::vector<std::uint8_t>(bytes, 0);
}

}  // namespace facet
