#include "facet/interop/lookup.hpp"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>

#include "test_util.hpp"

namespace facet::interop {
namespace {

TEST(Lookup, EveryPixelHoldsTheStAndDirectionThatMapToItsCentre) {
  test::TempFolder scratch("facet-interop-lookup");
  const Warp warp = test::calibrated_like_warp({160, 100}, {9, 7});
  const auto path = scratch.path() / "l.exr";
  write_lookup(warp, path);
  auto in = OIIO::ImageInput::open(path.string());
  ASSERT_TRUE(in);
  const OIIO::ImageSpec spec = in->spec();
  ASSERT_EQ(spec.width, 160);
  ASSERT_EQ(spec.height, 100);
  ASSERT_EQ(spec.nchannels, 7);
  EXPECT_NE(spec.get_string_attribute("facet:lookup").find("facet-lookup/1"), std::string::npos);
  std::vector<float> pixels(std::size_t(160) * 100 * 7);
  ASSERT_TRUE(in->read_image(0, 0, 0, 7, OIIO::TypeDesc::FLOAT, pixels.data()));
  const auto channel = [&](const char* name) {
    for (int c = 0; c < spec.nchannels; ++c) {
      if (spec.channelnames[c] == name) return c;
    }
    return -1;
  };
  const int R = channel("R"), G = channel("G"), A = channel("A"), X = channel("X"),
            Y = channel("Y"), Z = channel("Z");
  ASSERT_TRUE(R >= 0 && G >= 0 && A >= 0 && X >= 0 && Y >= 0 && Z >= 0);
  double worst_px = 0, worst_direction = 0;
  int covered = 0, uncovered = 0;
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 160; ++x) {
      const float* p = &pixels[(std::size_t(y) * 160 + x) * 7];
      if (p[A] == 0) {
        EXPECT_TRUE(std::isnan(p[R]) && std::isnan(p[X]));
        ++uncovered;
        continue;
      }
      ++covered;
      const glm::dvec2 st{p[R], p[G]};
      worst_px = std::max(worst_px, glm::length(warp.q_from_st(st) - glm::dvec2(x + 0.5, y + 0.5)));
      worst_direction = std::max(
          worst_direction, glm::length(glm::dvec3(p[X], p[Y], p[Z]) - warp.v_eye_from_st(st)));
    }
  }
  // float32 st: about 1e-7 of the image, so well under 1e-3 px; directions to float precision.
  EXPECT_GT(covered, 15000);
  EXPECT_LT(worst_px, 1e-3);
  EXPECT_LT(worst_direction, 1e-6);
  std::printf("lookup: %d covered, %d uncovered, worst %.2e px\n", covered, uncovered, worst_px);
}

}  // namespace
}  // namespace facet::interop
