// The GLC rasterizer ("glc") against the accuracy oracle casting the same GLC rays: a cross-slit
// camera, a 360° circular cross-slit panorama of GLC strips and a mirror sphere of one GLC per
// reflector triangle, each rendering a small city.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>

#include "facet/driver/city.hpp"
#include "facet/driver/reference.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/glc.hpp"
#include "gl_test_context.hpp"

namespace facet::driver {
namespace {

struct Fixture {
  Scene scene = build_city({.blocks_per_side = 2, .texture_size = 16});
  glm::dmat4 T_eye_world = glm::inverse(CityCameraPath({.blocks_per_side = 2}).T_world_eye(3.0));
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

struct Result {
  std::vector<std::uint32_t> ids, reference;
  IdComparison comparison;
  RenderStats stats;
};

Result render_and_compare(const PiecewiseGlc& camera, const std::string& what) {
  test::shared_context();
  const Fixture& f = fixture();
  const GpuScene gpu_scene = upload_scene(f.scene);
  auto method = make_render_method("glc");
  OutputSpec output{"glc", Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), camera.size),
                    std::make_shared<const PiecewiseGlc>(camera)};
  const RenderSettings settings;
  method->prepare(f.scene, gpu_scene, {&output, 1}, settings);
  std::vector<OutputTarget> targets;
  targets.push_back(OutputTarget::create(camera.size));
  Result result;
  result.stats = method->render(f.T_eye_world, targets);
  result.ids = targets[0].read_ids();
  result.reference = ReferenceRaycaster(f.scene).ids(camera, f.T_eye_world, settings.z_near);
  result.comparison = compare_ids(result.reference, result.ids, camera.size);
  std::size_t seen = 0;
  for (std::uint32_t id : result.reference) seen += id != 0;
  std::printf(
      "%s %dx%d, %zu pieces: id_mismatch %.6f (%zu of %zu), %zu differing, %zu of %zu "
      "pixels see the city, %llu quads\n",
      what.c_str(), camera.size.x, camera.size.y, camera.pieces.size(),
      result.comparison.id_mismatch, result.comparison.mismatched_pixels,
      result.comparison.compared_pixels, result.comparison.differing_pixels, seen,
      result.reference.size(), static_cast<unsigned long long>(result.stats.replicas));
  return result;
}

// Both cast the same ray through every pixel centre: away from the reference's edges the IDs may
// differ only where float rounding picks another of two coinciding surfaces. The bound, 1e-3 of
// the pixels away from edges, leaves room for such ties; the measured figure is 0 on each camera
// (printed). A hole (a pixel whose ray meets a triangle left undrawn) would count here.
constexpr double kIdMismatchBound = 1e-3;

TEST(GlcRender, CrossSlitMatchesTheReferenceRays) {
  GlcFrame frame;
  frame.axes = glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1));
  const PiecewiseGlc camera =
      single_glc(cross_slit_glc(frame, {{0, 0, -1}, {0, 1, 0}}, {{0, 0, -4}, {1, 0, 0}}, {3.2, 2.0},
                                {256, 80}, "test", "camera"),
                 {256, 80});
  const Result r = render_and_compare(camera, "cross-slit");
  EXPECT_LE(r.comparison.id_mismatch, kIdMismatchBound);
  EXPECT_GT(r.comparison.compared_pixels, 12000u);
  EXPECT_GT(r.stats.replicas, 100u);
}

TEST(GlcRender, PanoramaStripsMatchTheReferenceRays) {
  const PiecewiseGlc camera = circular_panorama(360, 0.25, 120, 16, {200, 150}, "test", "camera");
  const Result r = render_and_compare(camera, "panorama 360");
  EXPECT_LE(r.comparison.id_mismatch, kIdMismatchBound);
  EXPECT_GT(r.comparison.compared_pixels, 15000u);
}

TEST(GlcRender, MirrorSphereMatchesTheReferenceRays) {
  const PiecewiseGlc camera = mirror_sphere({0, 0, -3}, 1.0, 50, 12, {160, 160}, "test", "camera");
  const Result r = render_and_compare(camera, "mirror sphere");
  EXPECT_LE(r.comparison.id_mismatch, kIdMismatchBound);
  // Pixels no piece covers stay empty in both.
  std::size_t uncovered_drawn = 0;
  for (std::size_t k = 0; k < r.ids.size(); ++k) {
    if (camera.piece_of_pixel[k] < 0 && r.ids[k] != 0) ++uncovered_drawn;
  }
  EXPECT_EQ(uncovered_drawn, 0u);
  EXPECT_GT(r.comparison.compared_pixels, 8000u);
}

TEST(GlcRender, WarpOutputIsRefused) {
  test::shared_context();
  const Fixture& f = fixture();
  const GpuScene gpu_scene = upload_scene(f.scene);
  auto method = make_render_method("glc");
  const OutputSpec outputs[1] = {
      {"display", Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {64, 48})}};
  EXPECT_THROW(method->prepare(f.scene, gpu_scene, outputs, RenderSettings{}), InputError);
}

TEST(GlcRender, EveryOtherMethodRefusesAGlcOutput) {
  test::shared_context();
  const Fixture& f = fixture();
  const GpuScene gpu_scene = upload_scene(f.scene);
  const PiecewiseGlc camera = circular_panorama(360, 0.25, 120, 16, {64, 48}, "test", "camera");
  const OutputSpec outputs[1] = {
      {"glc", Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), camera.size),
       std::make_shared<const PiecewiseGlc>(camera)}};
  for (const std::string_view name : render_method_names()) {
    if (name == "glc") continue;
    auto method = make_render_method(name);
    EXPECT_THROW(method->prepare(f.scene, gpu_scene, outputs, RenderSettings{}), InputError)
        << name;
  }
}

}  // namespace
}  // namespace facet::driver
