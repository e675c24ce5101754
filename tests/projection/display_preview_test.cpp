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

// A projector showing `warp` with blend weights `alpha` (output-sized, one channel; empty: 1).
PreviewProjector projector(const std::string& name, const Warp& warp,
                           std::span<const float> alpha = {}) {
  PreviewProjector result;
  result.name = name;
  result.warp = &warp;
  if (!alpha.empty()) {
    result.alpha_size = warp.output_size;
    result.alpha = alpha;
  }
  return result;
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
    const PreviewProjector projectors[] = {projector("ahead", ahead)};
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
    const PreviewProjector projectors[] = {projector("up", up)};
    const DisplayPreview preview = preview_display(projectors, options, "test");
    EXPECT_NEAR(preview.figures.view_sr, 2 * kPi, 2 * kPi * 2e-3);
    EXPECT_NEAR(preview.figures.covered_sr, exact_sr, exact_sr * 0.005);
    // The zenith is the fisheye's centre pixel.
    EXPECT_EQ(preview.count[std::size_t(256) * 512 + 256], 1);
    EXPECT_EQ(preview.count[std::size_t(256) * 512 + 2], 0);
  }
}

// The fitted view of a frustum looks along it, wide enough for its corners (54.7° off axis: a
// 110° fisheye); a 360° cylinder gets the equirect panorama.
TEST(DisplayPreview, TheFittedViewHoldsEveryCoveredDirection) {
  const Warp ahead = square_frustum(kLookUp);
  const PreviewProjector frustum[] = {projector("up", ahead)};
  const ContentProjection view = fitted_preview_view(frustum);
  ASSERT_EQ(view.format, ContentFormat::fisheye);
  EXPECT_EQ(view.fov_deg, 110);
  const glm::dvec3 centre = view.v_eye_from_point({0, {0.5, 0.5}});
  EXPECT_NEAR(centre.y, 1, 1e-9);
  PreviewOptions options;
  options.view = view;
  options.height_px = 256;
  EXPECT_NEAR(preview_display(frustum, options, "test").figures.covered_sr, 2 * kPi / 3,
              2 * kPi / 3 * 0.01);
  const Warp cylinder = Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {256, 64});
  const PreviewProjector around[] = {projector("cylinder", cylinder)};
  EXPECT_EQ(fitted_preview_view(around).format, ContentFormat::equirect);
}

TEST(DisplayPreview, OverlapAndBlendSumsFollowTheAlphaMaps) {
  const Warp ahead = square_frustum();
  const std::vector<float> half(64 * 64, 0.5f), quarter(64 * 64, 0.25f);
  PreviewOptions options;
  options.view = equirect_content();
  options.height_px = 128;
  {
    const PreviewProjector projectors[] = {projector("a", ahead, half),
                                           projector("b", ahead, half)};
    const DisplayPreview preview = preview_display(projectors, options, "test");
    EXPECT_GT(preview.figures.covered_sr, 2.0);
    EXPECT_DOUBLE_EQ(preview.figures.overlap_sr, preview.figures.covered_sr);
    EXPECT_LE(preview.figures.blend_worst, 1e-6);
    EXPECT_EQ(preview.figures.blend_off_sr, 0);
  }
  {
    const PreviewProjector projectors[] = {projector("a", ahead, half),
                                           projector("b", ahead, quarter)};
    const DisplayPreview preview = preview_display(projectors, options, "test");
    EXPECT_NEAR(preview.figures.blend_worst, 0.25, 1e-6);
    EXPECT_NEAR(preview.figures.blend_p99, 0.25, 1e-6);
    EXPECT_DOUBLE_EQ(preview.figures.blend_off_sr, preview.figures.covered_sr);
  }
  {
    // A calibration's residual, 0.25 px on the left half of the output and 1.5 px on the right:
    // the solid-angle median is either, the worst 1.5 px.
    std::vector<float> residual(8 * 8);
    for (int by = 0; by < 8; ++by)
      for (int bx = 0; bx < 8; ++bx) residual[std::size_t(by * 8 + bx)] = bx < 4 ? 0.25f : 1.5f;
    PreviewProjector with_residual = projector("a", ahead, half);
    with_residual.residual_blocks = {8, 8};
    with_residual.residual_px = residual;
    const PreviewProjector projectors[] = {with_residual};
    const DisplayPreview preview = preview_display(projectors, options, "test");
    EXPECT_EQ(preview.figures.residual_worst_px, 1.5);
    EXPECT_EQ(preview.figures.residual_p99_px, 1.5);
    EXPECT_TRUE(preview.figures.residual_p50_px == 0.25 || preview.figures.residual_p50_px == 1.5);
    // The image: the residual's heat colour where covered.
    const std::vector<std::uint8_t> rgba =
        render_preview(preview, PreviewShow::residual, options.view);
    const glm::u8vec3 red = residual_heat_srgb(2.0), blue = residual_heat_srgb(0.0);
    EXPECT_EQ(red, glm::u8vec3(255, 0, 0));
    EXPECT_EQ(blue, glm::u8vec3(0, 0, 255));
    EXPECT_EQ(residual_heat_srgb(0.25), glm::u8vec3(0, 128, 128));
    std::size_t heat = 0;
    for (std::size_t i = 0; i < rgba.size(); i += 4)
      heat += glm::u8vec3(rgba[i], rgba[i + 1], rgba[i + 2]) == residual_heat_srgb(0.25);
    EXPECT_GT(heat, 100u);
  }
  // A map of the wrong size is refused, naming the projector's blend.
  const std::vector<float> small(32 * 32, 1.0f);
  PreviewProjector wrong_size = projector("a", ahead);
  wrong_size.alpha_size = {32, 32};
  wrong_size.alpha = small;
  const PreviewProjector wrong[] = {wrong_size};
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
    projectors.push_back(projector(config.projectors[p].name, warps[p], blends[p].values));
  PreviewOptions options;
  options.height_px = 256;
  options.view = fisheye_content(180, DomeOrientation{30, 0});
  const DisplayPreview tilted = preview_display(projectors, options, file.string());
  EXPECT_EQ(tilted.figures.uncovered_sr, 0);
  EXPECT_LE(tilted.figures.blend_worst, 0.005);
  EXPECT_GT(tilted.figures.overlap_sr, 0.5);
  options.view = fisheye_content(180);
  const DisplayPreview untilted = preview_display(projectors, options, file.string());
  // The fitted view is a fisheye about the tilted zenith (0, cos 30°, −sin 30°), within 3°.
  const ContentProjection fitted = fitted_preview_view(projectors);
  ASSERT_EQ(fitted.format, ContentFormat::fisheye);
  const glm::dvec3 centre = fitted.v_eye_from_point({0, {0.5, 0.5}});
  EXPECT_LT(std::acos(glm::dot(centre, glm::dvec3(0, std::cos(kPi / 6), -std::sin(kPi / 6)))),
            3 * kPi / 180);
  EXPECT_GE(fitted.fov_deg, 180);
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
