// The GLC rasterizer ("glc") against the accuracy oracle casting the same GLC rays: a cross-slit
// camera, a 360° circular cross-slit panorama of GLC strips and a mirror sphere of one GLC per
// reflector triangle, each rendering a small city. Its shading through the material interface:
// the IDs do not depend on the material, scene materials take their own shaders, and a pinhole
// GLC shows the textured city in the colours that `facets` gives the same perspective view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "facet/driver/city.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/reference.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/glc.hpp"
#include "gl_test_context.hpp"
#include "glc_test_city.hpp"
#include "support/files.hpp"

namespace facet::driver {
namespace {

using facet::test::glc_output;

struct Result {
  std::vector<std::uint32_t> ids, reference;
  IdComparison comparison;
  RenderStats stats;
};

Result render_and_compare(const PiecewiseGlc& camera, const std::string& what) {
  test::shared_context();
  const facet::test::GlcTestCity& f = facet::test::glc_test_city();
  const GpuScene gpu_scene = upload_scene(f.scene);
  auto method = make_render_method("glc");
  OutputSpec output = glc_output(camera);
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

struct Image {
  std::vector<std::uint32_t> ids;
  std::vector<std::uint8_t> colour;  // sRGB RGBA, top row first
};

Image render_image(std::string_view method, const Scene& scene, const OutputSpec& output,
                   const RenderSettings& settings, const glm::dmat4& T_eye_world) {
  const GpuScene gpu = upload_scene(scene);
  auto renderer = make_render_method(method);
  renderer->prepare(scene, gpu, {&output, 1}, settings);
  std::vector<OutputTarget> targets;
  targets.push_back(OutputTarget::create(output.warp.output_size));
  renderer->render(T_eye_world, targets);
  check_gl_error("render");
  return {targets[0].read_ids(), targets[0].read_colour_rgba8()};
}

// Whether pixel `at` and its 8 neighbours show one triangle (interior of a triangle's image).
bool one_triangle_about(const std::vector<std::uint32_t>& ids, glm::ivec2 size, int x, int y) {
  const std::uint32_t id = ids[std::size_t(y) * std::size_t(size.x) + std::size_t(x)];
  if (id == 0) return false;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (ids[std::size_t(y + dy) * std::size_t(size.x) + std::size_t(x + dx)] != id) return false;
  return true;
}

// The largest difference of the three colour channels (sRGB levels) at pixel `at`.
int channel_difference(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b,
                       std::size_t at) {
  int worst = 0;
  for (std::size_t c = 0; c < 3; ++c)
    worst = std::max(worst, std::abs(a[4 * at + c] - b[4 * at + c]));
  return worst;
}

// The material changes the colour only: through the panorama of GLC strips the IDs of every
// built-in and of a user's file equal the lit render's, and the colours do not.
TEST(GlcRender, MaterialsChangeColoursNotIds) {
  test::shared_context();
  const facet::test::TempFolder scratch("facet_glc_material");
  const std::filesystem::path user = scratch.path() / "bary.frag";
  std::ofstream(user) << "vec4 shade(MaterialInput m) {\n  return vec4(m.barycentric * "
                         "(m.edge_px.x > 1.0 ? 1.0 : 0.5), 1.0);\n}\n";
  const facet::test::GlcTestCity& f = facet::test::glc_test_city();
  const PiecewiseGlc camera = circular_panorama(360, 0.25, 120, 16, {200, 150}, "test", "camera");
  const OutputSpec output = glc_output(camera);
  const Image lit = render_image("glc", f.scene, output, RenderSettings{}, f.T_eye_world);
  std::size_t seen = 0;
  for (std::uint32_t id : lit.ids) seen += id != 0;
  EXPECT_GT(seen, 15000u);
  for (const std::string& name : {std::string("solid-wireframe"), std::string("pen-and-ink"),
                                  std::string("procedural"), user.string()}) {
    RenderSettings settings;
    settings.material = load_material_shader(name);
    const Image styled = render_image("glc", f.scene, output, settings, f.T_eye_world);
    EXPECT_EQ(styled.ids, lit.ids) << name;
    std::size_t changed = 0;
    for (std::size_t k = 0; k < lit.ids.size(); ++k)
      changed += lit.ids[k] != 0 && channel_difference(styled.colour, lit.colour, k) > 2;
    std::printf("glc, %s: %zu of %zu seen pixels change colour\n", name.c_str(), changed, seen);
    EXPECT_GT(changed, seen / 20) << name;
  }
}

// Scene materials bring their own shaders (Material::shader): even materials of the city paint
// magenta from a user's file, the others stay lit. Every pixel inside an even material's
// triangle is magenta, every one inside an odd material's has the all-lit render's colour, and
// the IDs are the all-lit render's.
TEST(GlcRender, EachSceneMaterialShadesWithItsOwnShader) {
  test::shared_context();
  const facet::test::TempFolder scratch("facet_glc_material");
  const std::filesystem::path magenta = scratch.path() / "magenta.frag";
  std::ofstream(magenta) << "vec4 shade(MaterialInput m) { return vec4(1, 0, 1, 1); }\n";
  const facet::test::GlcTestCity& f = facet::test::glc_test_city();
  Scene shaded = f.scene;
  for (std::size_t m = 0; m < shaded.materials.size(); m += 2)
    shaded.materials[m].shader = load_material_shader(magenta.string());
  std::vector<std::uint32_t> material_of_id{UINT32_MAX};
  for (const Object& object : f.scene.objects)
    for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
      const Primitive& primitive = f.scene.primitives[object.first_primitive + k];
      material_of_id.insert(material_of_id.end(), primitive.index_count / 3, primitive.material);
    }
  const PiecewiseGlc camera = circular_panorama(360, 0.25, 120, 16, {200, 150}, "test", "camera");
  const OutputSpec output = glc_output(camera);
  const Image lit = render_image("glc", f.scene, output, RenderSettings{}, f.T_eye_world);
  const Image own = render_image("glc", shaded, output, RenderSettings{}, f.T_eye_world);
  ASSERT_EQ(own.ids, lit.ids);
  std::size_t even = 0, even_magenta = 0, odd = 0, odd_lit = 0;
  for (int y = 1; y + 1 < camera.size.y; ++y)
    for (int x = 1; x + 1 < camera.size.x; ++x) {
      if (!one_triangle_about(own.ids, camera.size, x, y)) continue;
      const std::size_t at = std::size_t(y) * std::size_t(camera.size.x) + std::size_t(x);
      const std::uint8_t* c = &own.colour[4 * at];
      if (material_of_id.at(own.ids[at]) % 2 == 0) {
        ++even;
        even_magenta += c[0] == 255 && c[1] == 0 && c[2] == 255;
      } else {
        ++odd;
        odd_lit += std::equal(c, c + 3, &lit.colour[4 * at]);
      }
    }
  std::printf("glc: magenta %zu of %zu, lit %zu of %zu\n", even_magenta, even, odd_lit, odd);
  EXPECT_GT(even, 500u);
  EXPECT_EQ(even_magenta, even);
  EXPECT_GT(odd, 500u);
  EXPECT_EQ(odd_lit, odd);
}

// A pinhole GLC is a perspective camera: with its centre at the eye and its image plane 0.1 m
// ahead (0.2 m square, 256x256: tangents ±1), it sees what `facets` draws on the perspective
// output of the same tangents, and both shade the textured city (16-texel textures, lit) through
// the same material stage. Compared where both show one triangle over the pixel's 3x3
// neighbourhood and the same one: both take the same pixel centre's point on the triangle's plane
// (a ray cast here, perspective-correct interpolation there), so the colours differ by the
// float rounding of the texture coordinates, the level of detail and the normal only: measured,
// median and 99th percentile of the largest channel difference 0, worst 1 sRGB level. Asserted:
// 99th percentile at most 1, worst at most 4 (room for a texel edge that rounding puts on the
// other side of a pixel centre). Leaving the textures out of the facets render moves the 99th
// percentile to 192 (asserted over 8), so the comparison fails if glc did not sample them.
TEST(GlcRender, PinholeShowsTheTexturesFacetsShow) {
  test::shared_context();
  const facet::test::GlcTestCity& f = facet::test::glc_test_city();
  GlcFrame frame;
  frame.origin = glm::dvec3(0, 0, -0.1);
  frame.axes = glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1));
  const glm::ivec2 size(256, 256);
  const PiecewiseGlc camera =
      single_glc(pinhole_glc(frame, {0, 0, -0.1}, {0.2, 0.2}, size, "test", "camera"), size);
  const OutputSpec perspective{"perspective",
                               Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), size)};
  const Image glc =
      render_image("glc", f.scene, glc_output(camera), RenderSettings{}, f.T_eye_world);
  const Image facets =
      render_image("facets", f.scene, perspective, RenderSettings{}, f.T_eye_world);
  Scene untextured = f.scene;
  for (Material& m : untextured.materials) m.texture = -1;
  const Image plain =
      render_image("facets", untextured, perspective, RenderSettings{}, f.T_eye_world);
  std::vector<int> differences, untextured_differences;
  std::size_t same_id = 0, compared_ids = 0;
  for (int y = 1; y + 1 < size.y; ++y)
    for (int x = 1; x + 1 < size.x; ++x) {
      const std::size_t at = std::size_t(y) * std::size_t(size.x) + std::size_t(x);
      if (glc.ids[at] != 0 || facets.ids[at] != 0) {
        ++compared_ids;
        same_id += glc.ids[at] == facets.ids[at];
      }
      if (!one_triangle_about(glc.ids, size, x, y) || !one_triangle_about(facets.ids, size, x, y) ||
          glc.ids[at] != facets.ids[at])
        continue;
      differences.push_back(channel_difference(glc.colour, facets.colour, at));
      untextured_differences.push_back(channel_difference(plain.colour, facets.colour, at));
    }
  ASSERT_GT(differences.size(), 20000u);
  auto percentile = [](std::vector<int> v, double p) {
    std::sort(v.begin(), v.end());
    return v[std::size_t(p * double(v.size() - 1))];
  };
  const int p99 = percentile(differences, 0.99), worst = percentile(differences, 1.0);
  const int untextured_p99 = percentile(untextured_differences, 0.99);
  std::printf(
      "pinhole GLC against facets, 256x256: IDs equal at %zu of %zu pixels; colour difference "
      "over %zu interior pixels: median %d, 99th percentile %d, worst %d sRGB levels; facets "
      "without textures: 99th percentile %d\n",
      same_id, compared_ids, differences.size(), percentile(differences, 0.5), p99, worst,
      untextured_p99);
  EXPECT_GE(double(same_id), 0.995 * double(compared_ids));
  EXPECT_LE(p99, 1);
  EXPECT_LE(worst, 4);
  EXPECT_GT(untextured_p99, 8);
}

TEST(GlcRender, WarpOutputIsRefused) {
  test::shared_context();
  const facet::test::GlcTestCity& f = facet::test::glc_test_city();
  const GpuScene gpu_scene = upload_scene(f.scene);
  auto method = make_render_method("glc");
  const OutputSpec outputs[1] = {
      {"display", Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {64, 48})}};
  EXPECT_THROW(method->prepare(f.scene, gpu_scene, outputs, RenderSettings{}), InputError);
}

TEST(GlcRender, EveryOtherMethodRefusesAGlcOutput) {
  test::shared_context();
  const facet::test::GlcTestCity& f = facet::test::glc_test_city();
  const GpuScene gpu_scene = upload_scene(f.scene);
  const PiecewiseGlc camera = circular_panorama(360, 0.25, 120, 16, {64, 48}, "test", "camera");
  const OutputSpec outputs[1] = {
      {"glc", Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), camera.size),
       std::make_shared<const PiecewiseGlc>(camera)}};
  for (const std::string_view name : render_method_names()) {
    if (is_glc_method(name)) continue;
    auto method = make_render_method(name);
    EXPECT_THROW(method->prepare(f.scene, gpu_scene, outputs, RenderSettings{}), InputError)
        << name;
  }
}

}  // namespace
}  // namespace facet::driver
