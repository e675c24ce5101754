// The display preview: solid angles against closed forms, overlap and blend sums from the alpha
// maps, and the shipped dome4 display covered above its spring line with blends summing to 1.
#include "facet/projection/display_preview.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <vector>

#include "facet/projection/errors.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;

// A 90°×90° perspective projector (tangents ±1), looking along R_eye_base's −z. Its frustum's
// solid angle is 4·asin(sin 45°·sin 45°) = 2π/3 sr.
Warp square_frustum(const glm::dmat3& R_eye_base = glm::dmat3(1.0)) {
  return Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), {64, 64}, {2, 2}, R_eye_base);
}

// −z (ahead) turned to +y (the zenith): a rotation of +90° about x.
const glm::dmat3 kLookUp(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0));

TEST(DisplayPreview, ASquareFrustumCoversItsClosedFormSolidAngle) {
  const Warp ahead = square_frustum(), up = square_frustum(kLookUp);
  const double exact_sr = 2 * kPi / 3;
  // Within 0.5% at 512 rows: the frustum's edge crosses about 1,000 pixels of 0.35°.
  {
    PreviewOptions options;
    options.view = equirect_content();
    options.height_px = 512;
    const PreviewProjector projectors[] = {{"ahead", &ahead, {0, 0}, {}, 1}};
    const DisplayPreview preview = preview_display(projectors, options, "test");
    EXPECT_EQ(preview.size, glm::ivec2(1024, 512));
    EXPECT_NEAR(preview.figures.view_sr, 4 * kPi, 4 * kPi * 1e-3);
    EXPECT_NEAR(preview.figures.covered_sr, exact_sr, exact_sr * 0.005);
    EXPECT_NEAR(preview.figures.uncovered_sr, 4 * kPi - exact_sr, exact_sr * 0.005);
    EXPECT_NEAR(preview.figures.projector_sr[0], preview.figures.covered_sr, 1e-9);
    EXPECT_EQ(preview.figures.overlap_sr, 0);
  }
  {
    PreviewOptions options;
    options.view = fisheye_content(180);
    options.height_px = 512;
    const PreviewProjector projectors[] = {{"up", &up, {0, 0}, {}, 1}};
    const DisplayPreview preview = preview_display(projectors, options, "test");
    EXPECT_NEAR(preview.figures.view_sr, 2 * kPi, 2 * kPi * 2e-3);
    EXPECT_NEAR(preview.figures.covered_sr, exact_sr, exact_sr * 0.005);
    // The zenith is the fisheye's centre pixel.
    EXPECT_EQ(preview.count[std::size_t(256) * 512 + 256], 1);
    EXPECT_EQ(preview.count[std::size_t(256) * 512 + 2], 0);
  }
}

TEST(DisplayPreview, OverlapAndBlendSumsFollowTheAlphaMaps) {
  const Warp ahead = square_frustum();
  const std::vector<float> half(64 * 64, 0.5f), quarter(64 * 64, 0.25f);
  PreviewOptions options;
  options.view = equirect_content();
  options.height_px = 128;
  {
    const PreviewProjector projectors[] = {{"a", &ahead, {64, 64}, half, 1},
                                           {"b", &ahead, {64, 64}, half, 1}};
    const DisplayPreview preview = preview_display(projectors, options, "test");
    EXPECT_GT(preview.figures.covered_sr, 2.0);
    EXPECT_DOUBLE_EQ(preview.figures.overlap_sr, preview.figures.covered_sr);
    EXPECT_LE(preview.figures.blend_worst, 1e-6);
    EXPECT_EQ(preview.figures.blend_off_sr, 0);
  }
  {
    const PreviewProjector projectors[] = {{"a", &ahead, {64, 64}, half, 1},
                                           {"b", &ahead, {64, 64}, quarter, 1}};
    const DisplayPreview preview = preview_display(projectors, options, "test");
    EXPECT_NEAR(preview.figures.blend_worst, 0.25, 1e-6);
    EXPECT_NEAR(preview.figures.blend_p99, 0.25, 1e-6);
    EXPECT_DOUBLE_EQ(preview.figures.blend_off_sr, preview.figures.covered_sr);
  }
  // A map of the wrong size is refused, naming the projector's blend.
  const std::vector<float> small(32 * 32, 1.0f);
  const PreviewProjector wrong[] = {{"a", &ahead, {32, 32}, small, 1}};
  try {
    preview_display(wrong, options, "display.json");
    ADD_FAILURE() << "a 32x32 blend map for a 64x64 output was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "a.blend");
  }
  options.height_px = 4;
  EXPECT_THROW(preview_display(wrong, options, "display.json"), InputError);
}

// configs/displays/dome4 is calibrated on a dome tilted forward by 30°: seen about that dome's
// zenith, every direction above its spring line is covered and the blends sum to 1 within 0.005
// (worst case over the 256×256 fisheye's pixel centres). Untilted, the back of the view (above the
// tilted spring line's low side) is uncovered.
TEST(DisplayPreview, Dome4IsCoveredAboveItsSpringLineAndBlendsToOne) {
  const std::filesystem::path file =
      std::filesystem::path(FACET_SOURCE_DIR) / "configs/displays/dome4/display.json";
  const projection_io::DisplayConfig config = projection_io::read_display_config(file);
  std::vector<Warp> warps;
  std::vector<projection_io::BlendMap> blends;
  for (const auto& projector : config.projectors) {
    warps.push_back(read_warp(config.resolve(projector.warp).string()));
    ASSERT_TRUE(projector.blend) << projector.name;
    blends.push_back(projection_io::read_blend_map(config.resolve(*projector.blend).string()));
  }
  std::vector<PreviewProjector> projectors;
  for (std::size_t p = 0; p < warps.size(); ++p)
    projectors.push_back({config.projectors[p].name, &warps[p], blends[p].size, blends[p].values,
                          blends[p].channels});
  PreviewOptions options;
  options.height_px = 256;
  options.view = fisheye_content(180, DomeOrientation{30, 0});
  const DisplayPreview tilted = preview_display(projectors, options, file.string());
  EXPECT_EQ(tilted.figures.uncovered_sr, 0);
  EXPECT_LE(tilted.figures.blend_worst, 0.005);
  EXPECT_GT(tilted.figures.overlap_sr, 0.5);
  options.view = fisheye_content(180);
  const DisplayPreview untilted = preview_display(projectors, options, file.string());
  EXPECT_GT(untilted.figures.uncovered_sr, 0.1);
  // The uncovered directions are behind the viewer: the fisheye's top rows (its bottom is the
  // front).
  const std::size_t back = std::size_t(5) * 256 + 128, front = std::size_t(250) * 256 + 128;
  EXPECT_TRUE(untilted.in_view[back]);
  EXPECT_EQ(untilted.count[back], 0);
  EXPECT_GE(untilted.count[front], 1);
}

}  // namespace
}  // namespace facet
