// The blend pass against a CPU evaluation of out = c·α·(1−β) + β in linear light, and its
// promise to leave tiles with α = 1 and β = 0 untouched.
#include "facet/driver/blend_pass.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "gl_test_context.hpp"

namespace facet::driver {
namespace {

double srgb_decode(double e) {
  return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
}
double srgb_encode(double l) {
  return l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
}

constexpr glm::ivec2 kSize{70, 37};  // not a multiple of the tile, so edge tiles are partial

// Raw bytes in GL row order: a ramp that covers dark and bright values.
std::vector<std::uint8_t> test_colour() {
  std::vector<std::uint8_t> rgba(std::size_t(kSize.x) * kSize.y * 4);
  for (int y = 0; y < kSize.y; ++y)
    for (int x = 0; x < kSize.x; ++x)
      for (int c = 0; c < 4; ++c)
        rgba[(std::size_t(y) * kSize.x + x) * 4 + c] = std::uint8_t((x * 3 + y * 5 + c * 60) % 256);
  return rgba;
}

// Weights below 1 only in image columns >= 40 (a blend ramp), black level only in image rows < 5.
BlendMaps test_maps(int channels) {
  BlendMaps maps;
  maps.size = kSize;
  maps.channels = channels;
  const std::size_t n = std::size_t(kSize.x) * kSize.y * channels;
  maps.alpha.assign(n, 1.0f);
  maps.black.assign(n, 0.0f);
  for (int y = 0; y < kSize.y; ++y)
    for (int x = 0; x < kSize.x; ++x)
      for (int c = 0; c < channels; ++c) {
        const std::size_t i = (std::size_t(y) * kSize.x + x) * channels + c;
        if (x >= 40) maps.alpha[i] = float(1.0 - (x - 39) / 31.0 * (0.5 + 0.2 * c));
        if (y < 5) maps.black[i] = float(0.01 * (1 + c));
      }
  return maps;
}

Texture colour_texture(const std::vector<std::uint8_t>& rgba) {
  Texture colour = Texture::create_2d(GL_SRGB8_ALPHA8, kSize.x, kSize.y);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(colour.id(), 0, 0, 0, kSize.x, kSize.y, GL_RGBA, GL_UNSIGNED_BYTE,
                      rgba.data());
  return colour;
}

std::vector<std::uint8_t> read_raw(const Texture& colour) {
  std::vector<std::uint8_t> rgba(std::size_t(kSize.x) * kSize.y * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  // sRGB textures hand back their stored bytes: reads do not decode.
  glGetTextureImage(colour.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(rgba.size()), rgba.data());
  return rgba;
}

struct Difference {
  int max_lsb = 0;
  double mean_lsb = 0;
  int untouched_changed = 0;  // bytes that changed in tiles the pass must not touch
};

Difference compare(const std::vector<std::uint8_t>& before, const std::vector<std::uint8_t>& after,
                   const BlendMaps& maps, OutputEncoding encoding) {
  Difference d;
  long long sum = 0, count = 0;
  for (int gy = 0; gy < kSize.y; ++gy) {
    const int y = kSize.y - 1 - gy;  // image row of this GL row
    for (int x = 0; x < kSize.x; ++x) {
      const std::size_t p = (std::size_t(gy) * kSize.x + x) * 4;
      bool touched = encoding.gamma.has_value();
      for (int c = 0; c < 3; ++c) {
        const std::size_t m =
            (std::size_t(y) * kSize.x + x) * maps.channels + (maps.channels == 3 ? c : 0);
        const double alpha = maps.alpha[m], beta = maps.black[m];
        if (alpha < 1 || beta > 0) touched = true;
        const double linear = srgb_decode(before[p + c] / 255.0);
        const double composite = std::clamp(linear * alpha * (1 - beta) + beta, 0.0, 1.0);
        const double encoded =
            encoding.gamma ? std::pow(composite, 1 / *encoding.gamma) : srgb_encode(composite);
        const int lsb = std::abs(int(after[p + c]) - int(std::lround(encoded * 255.0)));
        d.max_lsb = std::max(d.max_lsb, lsb);
        sum += lsb;
        ++count;
      }
      EXPECT_EQ(after[p + 3], before[p + 3]) << "alpha channel changed at " << x << "," << y;
      if (!touched) {
        // A pixel with α = 1 and β = 0 keeps its bytes even in a tile that is processed (the sRGB
        // round trip is exact to the byte); in an unlisted tile nothing may run at all.
        for (int c = 0; c < 4; ++c) d.untouched_changed += after[p + c] != before[p + c];
      }
    }
  }
  d.mean_lsb = double(sum) / double(count);
  return d;
}

class BlendPassTest : public ::testing::TestWithParam<int> {};

TEST_P(BlendPassTest, MatchesLinearLightCompositeWithinOneLevel) {
  test::shared_context();
  const BlendMaps maps = test_maps(GetParam());
  const std::vector<std::uint8_t> before = test_colour();
  for (const OutputEncoding encoding : {OutputEncoding{}, OutputEncoding{2.2}}) {
    SCOPED_TRACE(encoding.gamma ? "gamma 2.2" : "sRGB");
    Texture colour = colour_texture(before);
    BlendPass pass(kSize, maps, encoding);
    pass.apply(colour);
    const Difference d = compare(before, read_raw(colour), maps, encoding);
    // The GPU evaluates in float and rounds once: at most one 8-bit level from the double
    // evaluation anywhere, and well under half a level on average.
    EXPECT_LE(d.max_lsb, 1);
    EXPECT_LE(d.mean_lsb, 0.25);
    if (!encoding.gamma) {
      EXPECT_EQ(d.untouched_changed, 0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Channels, BlendPassTest, ::testing::Values(1, 3));

TEST(BlendPass, ListsOnlyTilesThatNeedWork) {
  const BlendMaps maps = test_maps(1);
  const auto tiles = BlendPass::tiles_needing_work(kSize, maps, OutputEncoding{});
  // Image columns >= 40 fall in tile columns 2..4; image rows < 5 are GL rows 32..36, tile row 2.
  // Tile columns 0 and 1 of tile rows 0 and 1 hold neither.
  const int tiles_x = 5, tiles_y = 3;
  EXPECT_EQ(tiles.size(), std::size_t(tiles_x * tiles_y - 2 * 2));
  for (const glm::uvec2 origin : tiles)
    EXPECT_FALSE(origin.x < 32 && origin.y < 32) << origin.x << "," << origin.y;
  EXPECT_EQ(
      BlendPass::tiles_needing_work(kSize, BlendMaps{kSize, 1, {}, {}}, OutputEncoding{}).size(),
      0u);
  EXPECT_EQ(
      BlendPass::tiles_needing_work(kSize, BlendMaps{kSize, 1, {}, {}}, OutputEncoding{2.2}).size(),
      std::size_t(tiles_x * tiles_y));
}

TEST(BlendPass, UnlistedTilesKeepTheirBytes) {
  test::shared_context();
  // Only the top-right corner tile of the image needs work: a sentinel elsewhere must survive.
  BlendMaps maps{kSize, 1, std::vector<float>(std::size_t(kSize.x) * kSize.y, 1.0f), {}};
  maps.alpha[std::size_t(0) * kSize.x + (kSize.x - 1)] = 0.5f;
  BlendPass pass(kSize, maps, OutputEncoding{});
  EXPECT_EQ(pass.tiles_listed(), 1u);
  std::vector<std::uint8_t> before(std::size_t(kSize.x) * kSize.y * 4, 77);
  Texture colour = colour_texture(before);
  pass.apply(colour);
  const std::vector<std::uint8_t> after = read_raw(colour);
  int changed = 0;
  for (std::size_t i = 0; i < after.size(); ++i) changed += after[i] != before[i];
  EXPECT_EQ(changed, 3) << "only the RGB of the one weighted pixel may change";
}

}  // namespace
}  // namespace facet::driver
