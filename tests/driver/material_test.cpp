// Materials (driver/material_shader.hpp): the built-ins and a user's FILE.frag compile against the
// interface, a broken one is an InputError naming its file and line, the triangle IDs do not
// depend on the material, and the solid wireframe's strokes keep their width in output pixels
// across facet seams, where the cube map's resampling changes it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "facet/driver/city.hpp"
#include "facet/driver/display_outputs.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/projection/errors.hpp"
#include "gl_test_context.hpp"
#include "support/facet_cli.hpp"
#include "test_scenes.hpp"

namespace facet::driver {
namespace {

namespace fs = std::filesystem;

// A scratch folder removed at the end of the test, and files written into it.
struct Scratch : facet::test::TempFolder {
  Scratch() : TempFolder("facet_material") {}
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path() / name) << text;
    return path() / name;
  }
};

struct Rendered {
  std::vector<std::vector<std::uint32_t>> ids;
  std::vector<std::vector<std::uint8_t>> colour;  // sRGB RGBA, top row first
};

Rendered render(std::string_view method, const Scene& scene, const std::vector<OutputSpec>& outputs,
                const RenderSettings& settings, const glm::dmat4& T_eye_world) {
  const GpuScene gpu = upload_scene(scene);
  auto renderer = make_render_method(method);
  renderer->prepare(scene, gpu, outputs, settings);
  std::vector<OutputTarget> targets;
  for (const auto& output : outputs)
    targets.push_back(OutputTarget::create(output.warp.output_size));
  renderer->render(T_eye_world, targets);
  Rendered result;
  for (const auto& target : targets) {
    result.ids.push_back(target.read_ids());
    result.colour.push_back(target.read_colour_rgba8());
  }
  check_gl_error("render");
  return result;
}

Scene small_city() {
  CityOptions options;
  options.blocks_per_side = 1;
  options.texture_size = 8;
  return build_city(options);
}

glm::dmat4 city_view(double t) {
  CityOptions options;
  options.blocks_per_side = 1;
  return glm::inverse(CityCameraPath(options).T_world_eye(t));
}

Scene unlit_sphere(int slices, int stacks, float radius) {
  Material white;
  white.unlit = true;
  return facet::test::background_sphere(slices, stacks, radius, white);
}

TEST(Materials, BuiltinsLoadAndUnknownNamesAreInputErrors) {
  ASSERT_EQ(builtin_material_names().size(), 4u);
  for (std::string_view name : builtin_material_names()) {
    const MaterialShader material = load_material_shader(name);
    EXPECT_EQ(material.name, name);
    EXPECT_NE(material.text.find("shade("), std::string::npos) << name;
  }
  EXPECT_THROW(load_material_shader("chalk"), InputError);
  EXPECT_THROW(load_material_shader("/no/such/material.frag"), InputError);
}

TEST(Materials, UserFilesCompileAndBrokenOnesNameTheirFileAndLine) {
  test::shared_context();
  const Scratch scratch;
  // Barycentric colours: uses the interface's inputs.
  const fs::path good =
      scratch.write("good.frag",
                    "// A user material.\nvec4 shade(MaterialInput m) {\n  return "
                    "vec4(m.barycentric * (m.edge_px.x > 1.0 ? 1.0 : 0.5), 1.0);\n}\n");
  EXPECT_NO_THROW(check_material_shader(load_material_shader(good.string())));
  for (std::string_view name : builtin_material_names())
    EXPECT_NO_THROW(check_material_shader(load_material_shader(name))) << name;

  const fs::path broken = scratch.write(
      "broken.frag", "// Line 1.\nvec4 shade(MaterialInput m) {\n  return m.colour;\n}\n");
  try {
    check_material_shader(load_material_shader(broken.string()));
    ADD_FAILURE() << "a broken material compiled";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(broken.string()), std::string::npos) << message;
    EXPECT_NE(message.find("line 3"), std::string::npos) << message;
    EXPECT_NE(message.find("colour"), std::string::npos) << message;
  }
  // No shade(): the link fails, named by the file.
  const fs::path empty = scratch.write("empty.frag", "const float unused = 1.0;\n");
  try {
    check_material_shader(load_material_shader(empty.string()));
    ADD_FAILURE() << "a material without shade() linked";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(empty.string()), std::string::npos) << e.what();
  }
  // discard and gl_FragDepth would change IDs and depth: refused before compiling; comments may
  // say them.
  const fs::path discards = scratch.write(
      "discards.frag",
      "// discard is mentioned here\nvec4 shade(MaterialInput m) {\n  if (m.uv.x > 0.5) "
      "discard;\n  return vec4(1.0);\n}\n");
  try {
    load_material_shader(discards.string());
    ADD_FAILURE() << "discard was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_material_shader(
                   scratch.write("depth.frag", "void f() { gl_FragDepth = 0.5; }").string()),
               InputError);
  EXPECT_THROW(load_material_shader(scratch.path().string() + "/good.glsl"), InputError);
}

// A link error the material does not cause (a vertex stage calling a function nobody defines)
// stays facet's own ShaderError with the driver's whole log, not an error about the material.
TEST(Materials, LinkErrorsElsewhereStayShaderErrors) {
  test::shared_context();
  const MaterialShader material = load_material_shader("lit");
  ProgramBuilder builder;
  builder.define("WRITE_TRIANGLE_ID", "1");
  builder.source(ShaderStage::vertex, "broken vertex", R"(
out vec3 v_n_world;
out vec2 v_uv;
out vec3 v_p_world;
out vec3 v_p_eye;
out vec3 v_barycentric;
flat out uint v_triangle_id;
vec4 undefined_helper();
void main() {
  v_n_world = vec3(0.0, 1.0, 0.0);
  v_uv = vec2(0.0);
  v_p_world = vec3(0.0);
  v_p_eye = vec3(0.0, 0.0, -1.0);
  v_barycentric = vec3(1.0, 0.0, 0.0);
  v_triangle_id = 1u;
  gl_Position = undefined_helper();
}
)");
  add_material_stages(builder, material);
  try {
    link_with_material(builder, material);
    ADD_FAILURE() << "a program calling an undefined function linked";
  } catch (const InputError& e) {
    ADD_FAILURE() << "blamed on the material: " << e.what();
  } catch (const ShaderError& e) {
    EXPECT_NE(std::string(e.what()).find("undefined_helper"), std::string::npos) << e.what();
  }
}

// The material shades; the replication and the IDs never see it.
TEST(Materials, IdsDoNotDependOnTheMaterial) {
  test::shared_context();
  const Scene scene = small_city();
  const auto outputs = load_display_outputs("builtin:cylinder360", glm::ivec2(192, 144));
  RenderSettings settings;
  settings.facets.layout = FacetStrips{24};
  const glm::dmat4 view = city_view(3.0);
  for (std::string_view method : {"facets", "cubemap"}) {
    const Rendered lit = render(method, scene, outputs, settings, view);
    for (std::string_view name : {"solid-wireframe", "pen-and-ink", "procedural"}) {
      RenderSettings styled = settings;
      styled.material = load_material_shader(name);
      const Rendered r = render(method, scene, outputs, styled, view);
      EXPECT_EQ(r.ids[0], lit.ids[0]) << method << " " << name;
      EXPECT_NE(r.colour[0], lit.colour[0]) << method << " " << name;
    }
  }
}

// Scene materials may each bring their own shader (Material::shader): every method links one
// program per distinct shader and draws each material with its own, leaving the IDs as they are.
// Even materials of the small city take a user's file that paints magenta, material 1 the
// built-in procedural material, the others the render's lit one. Checked on every pixel whose
// 3x3 neighbourhood shows one triangle: magenta exactly where an even material is seen, the
// lit render's colour where an odd one from 3 on is, and some other colour for material 1.
TEST(Materials, EachSceneMaterialShadesWithItsOwnShader) {
  test::shared_context();
  const Scratch scratch;
  const fs::path magenta =
      scratch.write("magenta.frag", "vec4 shade(MaterialInput m) { return vec4(1, 0, 1, 1); }\n");
  const Scene scene = small_city();
  Scene shaded = scene;
  ASSERT_GE(shaded.materials.size(), 4u);
  for (std::size_t m = 0; m < shaded.materials.size(); m += 2)
    shaded.materials[m].shader = load_material_shader(magenta.string());
  shaded.materials[1].shader = load_material_shader("procedural");
  // The material of each triangle ID (0: no triangle).
  std::vector<std::uint32_t> material_of_id{UINT32_MAX};
  for (const Object& object : scene.objects)
    for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
      const Primitive& primitive = scene.primitives[object.first_primitive + k];
      material_of_id.insert(material_of_id.end(), primitive.index_count / 3, primitive.material);
    }
  const auto outputs = load_display_outputs("builtin:cylinder360", glm::ivec2(192, 144));
  RenderSettings settings;
  settings.facets.layout = FacetStrips{24};
  const glm::dmat4 view = city_view(3.0);
  for (std::string_view method :
       {"facets", "facets-gs", "naive", "tessellated", "cubemap", "vertex"}) {
    const Rendered lit = render(method, scene, outputs, settings, view);
    const Rendered own = render(method, shaded, outputs, settings, view);
    ASSERT_EQ(own.ids[0], lit.ids[0]) << method;
    const auto& ids = own.ids[0];
    const int w = 192, h = 144;
    std::size_t even = 0, even_magenta = 0, odd = 0, odd_lit = 0, procedural = 0,
                procedural_changed = 0;
    for (int y = 1; y + 1 < h; ++y)
      for (int x = 1; x + 1 < w; ++x) {
        const std::size_t at = std::size_t(y) * w + x;
        const std::uint32_t id = ids[at];
        if (id == 0 || id >= material_of_id.size()) continue;
        bool one_triangle = true;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            one_triangle = one_triangle && ids[std::size_t(y + dy) * w + x + dx] == id;
        if (!one_triangle) continue;
        const std::uint8_t* c = &own.colour[0][4 * at];
        const std::uint8_t* c_lit = &lit.colour[0][4 * at];
        const std::uint32_t m = material_of_id[id];
        if (m % 2 == 0) {
          ++even;
          even_magenta += c[0] == 255 && c[1] == 0 && c[2] == 255;
        } else if (m == 1) {
          ++procedural;
          procedural_changed += !std::equal(c, c + 3, c_lit);
        } else {
          ++odd;
          odd_lit += std::equal(c, c + 3, c_lit);
        }
      }
    std::printf("%s: magenta %zu of %zu, lit %zu of %zu, procedural changed %zu of %zu\n",
                std::string(method).c_str(), even_magenta, even, odd_lit, odd, procedural_changed,
                procedural);
    EXPECT_GT(even, 500u) << method;
    EXPECT_EQ(even_magenta, even) << method;
    EXPECT_GT(odd, 500u) << method;
    EXPECT_EQ(odd_lit, odd) << method;
    if (procedural > 0) {
      EXPECT_GT(procedural_changed, 0u) << method;
    }
  }
}

double linear_from_srgb(std::uint8_t value) {
  const double c = value / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

struct StrokeWidths {
  std::vector<double> width_px;  // per column; NaN where another stroke crosses
  double row = 0;                // the stroke's middle row
};

// The width of the horizon's stroke in every column of an unlit white image: the ink summed over
// the rows within 8 px of it (solid-wireframe's stroke is antialiased over one pixel, so its ink
// sums to its width). Columns near other strokes (meridians and diagonals of the sphere) are NaN.
StrokeWidths horizon_stroke(const std::vector<std::uint8_t>& rgba, glm::ivec2 size) {
  const double ink_luminance = 0.0207;  // solid-wireframe.frag's kInk
  auto ink = [&](int x, int y) {
    const std::size_t at = 4 * (std::size_t(y) * std::size_t(size.x) + std::size_t(x));
    const double l = 0.2126 * linear_from_srgb(rgba[at]) + 0.7152 * linear_from_srgb(rgba[at + 1]) +
                     0.0722 * linear_from_srgb(rgba[at + 2]);
    return std::clamp((1.0 - l) / (1.0 - ink_luminance), 0.0, 1.0);
  };
  // The horizon's row: the most ink summed over all columns.
  std::vector<double> row_ink(std::size_t(size.y), 0.0);
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) row_ink[std::size_t(y)] += ink(x, y);
  const int middle = int(std::max_element(row_ink.begin(), row_ink.end()) - row_ink.begin());
  StrokeWidths result;
  result.row = middle;
  std::vector<double> width(std::size_t(size.x), 0.0);
  std::vector<bool> crossed(std::size_t(size.x), false);
  for (int x = 0; x < size.x; ++x) {
    for (int y = std::max(0, middle - 8); y <= std::min(size.y - 1, middle + 8); ++y) {
      width[std::size_t(x)] += ink(x, y);
      // Ink at the window's border is another stroke crossing.
      if ((y == middle - 8 || y == middle + 8) && ink(x, y) > 0.01) crossed[std::size_t(x)] = true;
    }
  }
  result.width_px.assign(std::size_t(size.x), std::nan(""));
  for (int x = 0; x < size.x; ++x) {
    bool near_crossing = false;
    for (int k = -6; k <= 6; ++k) near_crossing |= crossed[std::size_t((x + k + size.x) % size.x)];
    if (!near_crossing) result.width_px[std::size_t(x)] = width[std::size_t(x)];
  }
  return result;
}

// Largest spread (max - min) of the stroke width over the 4 columns about each seam column
// (the seam between columns s - 1 and s), skipping seams where a column is NaN; and how many
// seams were measured.
std::pair<double, int> spread_across_seams(const std::vector<double>& width,
                                           const std::vector<int>& seams) {
  double worst = 0;
  int measured = 0;
  const int n = int(width.size());
  for (int s : seams) {
    double lo = 1e9, hi = -1e9;
    bool ok = true;
    for (int x = s - 2; x <= s + 1; ++x) {
      const double w = width[std::size_t((x + n) % n)];
      if (std::isnan(w)) ok = false;
      lo = std::min(lo, w);
      hi = std::max(hi, w);
    }
    if (!ok) continue;
    worst = std::max(worst, hi - lo);
    ++measured;
  }
  return {worst, measured};
}

std::pair<double, double> range_of(const std::vector<double>& width) {
  double lo = 1e9, hi = -1e9;
  for (double w : width)
    if (!std::isnan(w)) lo = std::min(lo, w), hi = std::max(hi, w);
  return {lo, hi};
}

// The solid wireframe's horizon at 15 m (2 px wide: 30 / distance) on the 360° cylinder,
// 512x384. Facets (32 strips) draw it with each facet's own projection and keep it 2 px wide
// across every seam; the cube map (384-px faces: a face texel is an output row at the face's
// centre) draws it 2 face texels wide and resamples it, so its width follows the faces'
// magnification, 2 cos(azimuth from the face's centre) output px. Reported for both; asserted for
// facets: the width varies by at most 0.5 px across each seam (and along the whole stroke).
TEST(Materials, WireframeStrokesKeepTheirWidthAcrossFacetSeams) {
  test::shared_context();
  const Scene sphere = unlit_sphere(12, 6, 15.0f);
  const glm::ivec2 size(512, 384);
  const auto outputs = load_display_outputs("builtin:cylinder360", size);
  const Warp& warp = outputs[0].warp;
  RenderSettings settings;
  const int strips = 32;
  settings.facets.layout = FacetStrips{strips};
  settings.material = load_material_shader("solid-wireframe");
  settings.cube_face_size = 384;

  std::vector<int> facet_seams;
  for (int k = 1; k < strips; ++k) facet_seams.push_back(int(std::lround(k * size.x / strips)));
  // The cube's faces meet round the horizon at the eye frame's diagonals.
  std::vector<int> cube_seams;
  for (const glm::dvec3 v :
       {glm::dvec3(1, 0, 1), glm::dvec3(1, 0, -1), glm::dvec3(-1, 0, 1), glm::dvec3(-1, 0, -1)}) {
    const auto projected = warp.project(v);
    if (projected) cube_seams.push_back(int(std::lround(projected->q.x)));
  }
  ASSERT_EQ(cube_seams.size(), 4u);

  const Rendered facets = render("facets", sphere, outputs, settings, glm::dmat4(1.0));
  const Rendered cube = render("cubemap", sphere, outputs, settings, glm::dmat4(1.0));
  const StrokeWidths f = horizon_stroke(facets.colour[0], size);
  const StrokeWidths c = horizon_stroke(cube.colour[0], size);
  const auto [f_seam, f_seams] = spread_across_seams(f.width_px, facet_seams);
  const auto [c_seam, c_seams] = spread_across_seams(c.width_px, cube_seams);
  const auto [f_lo, f_hi] = range_of(f.width_px);
  const auto [c_lo, c_hi] = range_of(c.width_px);
  std::printf(
      "solid wireframe, 2 px stroke at 15 m, cylinder 512x384: facets (32 strips) width %.3f to "
      "%.3f px, worst spread across %d facet seams %.3f px; cube map (384 px faces) width %.3f "
      "to %.3f px, worst spread across %d cube seams %.3f px\n",
      f_lo, f_hi, f_seams, f_seam, c_lo, c_hi, c_seams, c_seam);
  EXPECT_GE(f_seams, strips / 4);  // seams clear of the sphere's meridians and diagonals
  EXPECT_LE(f_seam, 0.5);
  EXPECT_LE(f_hi - f_lo, 0.5);
  EXPECT_NEAR(0.5 * (f_lo + f_hi), 2.0, 0.25);
  EXPECT_GT(c_hi, 0.0);  // the cube map drew the stroke (its width is reported, not asserted)
}

// Direction of the hatching in a window of an image, degrees in [0, 180): the lines run across
// the dominant gradient of the ink (structure tensor of central differences).
double hatch_direction_deg(const std::vector<std::uint8_t>& rgba, glm::ivec2 size, int x0, int x1,
                           int y0, int y1) {
  auto value = [&](int x, int y) {
    return double(rgba[4 * (std::size_t(y) * std::size_t(size.x) + std::size_t(x)) + 1]);
  };
  double jxx = 0, jyy = 0, jxy = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const double gx = value(x + 1, y) - value(x - 1, y), gy = value(x, y + 1) - value(x, y - 1);
      jxx += gx * gx;
      jyy += gy * gy;
      jxy += gx * gy;
    }
  const double gradient = 0.5 * std::atan2(2 * jxy, jxx - jyy) * 180 / M_PI;
  return std::fmod(gradient + 90 + 360, 180.0);
}

// Difference of two line directions, degrees in [0, 90].
double direction_change_deg(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 180.0);
  return std::min(d, 180 - d);
}

// Pen-and-ink on a grey sphere (one layer of diagonal hatching): facets lay the lines out in
// output pixels on both sides of every seam; the cube map lays them out in each face's pixels,
// so they take the faces' magnification (and turn where two faces do not mirror each other).
// Direction in 24x24 windows either side of each cube seam at the horizon, cylinder 512x384;
// asserted for facets (45 degrees on both sides, within 2), reported for the cube map.
TEST(Materials, HatchingRunsOnAcrossSeams) {
  test::shared_context();
  Scene sphere = unlit_sphere(12, 6, 15.0f);
  sphere.materials[0].base_colour = glm::vec4(0.1f, 0.1f, 0.1f, 1.0f);  // tone 0.68: one layer
  const glm::ivec2 size(512, 384);
  const auto outputs = load_display_outputs("builtin:cylinder360", size);
  RenderSettings settings;
  settings.facets.layout = FacetStrips{32};
  settings.material = load_material_shader("pen-and-ink");
  settings.cube_face_size = 384;
  const Rendered facets = render("facets", sphere, outputs, settings, glm::dmat4(1.0));
  const Rendered cube = render("cubemap", sphere, outputs, settings, glm::dmat4(1.0));
  const int row = size.y / 2;
  double worst[2] = {0, 0};
  for (const glm::dvec3 v :
       {glm::dvec3(1, 0, 1), glm::dvec3(1, 0, -1), glm::dvec3(-1, 0, 1), glm::dvec3(-1, 0, -1)}) {
    const auto projected = outputs[0].warp.project(v);
    ASSERT_TRUE(projected);
    const int s = int(std::lround(projected->q.x));
    if (s < 30 || s > size.x - 30) continue;
    for (int k = 0; k < 2; ++k) {
      const auto& image = (k == 0 ? facets : cube).colour[0];
      const double left = hatch_direction_deg(image, size, s - 28, s - 4, row - 12, row + 12);
      const double right = hatch_direction_deg(image, size, s + 4, s + 28, row - 12, row + 12);
      worst[k] = std::max(worst[k], direction_change_deg(left, right));
      // Facets: the material's 45 degrees in output pixels on both sides.
      if (k == 0) {
        EXPECT_LE(direction_change_deg(left, 45.0), 2.0) << s;
      }
      std::printf("%s, cube seam at column %d: hatching at %.1f and %.1f degrees\n",
                  k == 0 ? "facets" : "cubemap", s, left, right);
    }
  }
  std::printf(
      "hatching turns across a cube seam by at most %.1f degrees with facets, %.1f with "
      "the cube map\n",
      worst[0], worst[1]);
  EXPECT_LE(worst[0], 2.0);
}

// The stroke's width depends on depth: 3 px at 8 m (capped), 1.5 px at 20 m, 1 px at 40 m (the
// floor), the horizon of spheres of those radii through facets.
TEST(Materials, WireframeWidthFallsWithDistance) {
  test::shared_context();
  const glm::ivec2 size(512, 384);
  const auto outputs = load_display_outputs("builtin:cylinder360", size);
  RenderSettings settings;
  settings.facets.layout = FacetStrips{16};
  settings.material = load_material_shader("solid-wireframe");
  for (const auto& [radius, expected_px] :
       {std::pair{8.0f, 3.0}, std::pair{20.0f, 1.5}, std::pair{40.0f, 1.0}}) {
    const Rendered r =
        render("facets", unlit_sphere(12, 6, radius), outputs, settings, glm::dmat4(1.0));
    const auto [lo, hi] = range_of(horizon_stroke(r.colour[0], size).width_px);
    std::printf("solid wireframe at %.0f m: %.3f to %.3f px (expected %.1f)\n", double(radius), lo,
                hi, expected_px);
    EXPECT_NEAR(lo, expected_px, 0.15) << radius << " m";
    EXPECT_NEAR(hi, expected_px, 0.15) << radius << " m";
  }
}

// facet render --material: a user's file that does not compile exits 2 naming the file and the
// line; a built-in renders; --reference reports the same id_mismatch whatever the material;
// facet run refuses the broken file too.
TEST(Materials, RenderCliTakesMaterials) {
  const Scratch scratch;
  const fs::path broken =
      scratch.write("broken.frag", "vec4 shade(MaterialInput m) {\n  return vec3(1.0);\n}\n");
  std::string output;
  EXPECT_EQ(facet::test::run_facet(
                "render --display builtin:cylinder360 --size 64x48 --material " + broken.string(),
                &output),
            2)
      << output;
  EXPECT_NE(output.find(broken.string()), std::string::npos) << output;
  EXPECT_NE(output.find("line 2"), std::string::npos) << output;
  EXPECT_EQ(facet::test::run_facet(
                "render --display builtin:cylinder360 --size 64x48 --material pen-and-ink "
                "--out " +
                    (scratch.path() / "out").string(),
                &output),
            0)
      << output;
  EXPECT_TRUE(fs::exists(scratch.path() / "out" / "cylinder360.png"));
  EXPECT_EQ(facet::test::run_facet(
                "render --display builtin:cylinder360 --size 64x48 --material chalk", &output),
            2)
      << output;  // The reference compares IDs, which the material does not touch.
  double mismatch[2] = {-1, -2};
  for (int k = 0; k < 2; ++k) {
    const std::string material = k == 0 ? "lit" : "solid-wireframe";
    ASSERT_EQ(facet::test::run_facet("render --display builtin:dome180 --size 64x64 --reference "
                                     "--json --material " +
                                         material,
                                     &output),
              0)
        << output;
    const auto json = nlohmann::json::parse(output.substr(output.find('{')));
    mismatch[k] = json["reference"]["id_mismatch"].get<double>();
  }
  EXPECT_EQ(mismatch[0], mismatch[1]);
  // facet run reports a broken material the same way, and writes nothing.
  EXPECT_EQ(
      facet::test::run_facet("run builtin:cylinder360 --size 64x48 --headless --frames 1 "
                             "--material " +
                                 broken.string() + " --out " + (scratch.path() / "run").string(),
                             &output),
      2)
      << output;
  EXPECT_NE(output.find(broken.string()), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(scratch.path() / "run"));
}

}  // namespace
}  // namespace facet::driver
