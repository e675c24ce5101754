#include "facet/driver/bench.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <set>

#include "facet/driver/city.hpp"
#include "facet/driver/depth_image.hpp"
#include "facet/driver/display_outputs.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/perspective_image.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/reference.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/driver/scene_view.hpp"
#include "facet/projection/content_projection.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/facet_error.hpp"
#include "facet/projection/glc.hpp"
#include "facet/projection/rig.hpp"
#include "facet/projection/statistics.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "facet/projection_io/rig_file.hpp"

namespace facet::driver {
namespace {

std::string format(const char* pattern, auto... values) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, values...);
  return text;
}

std::string size_text(glm::ivec2 size) { return format("%dx%d", size.x, size.y); }

glm::ivec2 scaled(glm::ivec2 size, double scale) {
  return {std::max(16, int(std::lround(size.x * scale))),
          std::max(16, int(std::lround(size.y * scale)))};
}

// The view deformation of the seed paper's camera textures: a perspective base (90° × 73.7°,
// 4:3) and a smooth offset map of a few output-pixel-scaled waves, about 3% of the width at most,
// far from folding (the map's derivative stays below a third of the base's).
Warp deformation_warp(glm::ivec2 output_size, glm::ivec2 texture_cells) {
  Warp warp = Warp::analytic(BaseProjection::perspective(-1, 1, 0.75, -0.75), output_size,
                             texture_cells + 1);
  const double two_pi = 2 * std::numbers::pi;
  for (int j = 0; j < warp.grid_size.y; ++j) {
    for (int i = 0; i < warp.grid_size.x; ++i) {
      const double s = double(i) / (warp.grid_size.x - 1), t = double(j) / (warp.grid_size.y - 1);
      const double dx = 0.03 * std::sin(two_pi * (1.5 * s + 0.1)) * std::cos(two_pi * t) +
                        0.02 * (s - 0.5) * (t - 0.5);
      const double dy = 0.025 * std::sin(two_pi * (t + 0.2)) * std::cos(two_pi * 0.75 * s) +
                        0.015 * std::sin(two_pi * (s + t));
      warp.offset_px[warp.node_index(i, j)] =
          glm::vec2(float(dx * output_size.x), float(dy * output_size.y));
    }
  }
  warp.validate("builtin view deformation");
  return warp;
}

// The rig's projectors scaled by `scale` (sizes, focal lengths, principal points), so that the
// quick run and --size-scale shrink the dome rig as they shrink the other outputs.
std::vector<OutputSpec> rig_outputs(const std::filesystem::path& path, double scale) {
  Rig rig = load_rig(path.string());
  for (ProjectorModel& projector : rig.projectors) {
    const glm::ivec2 size = scaled(projector.size, scale);
    const glm::dvec2 ratio = glm::dvec2(size) / glm::dvec2(projector.size);
    projector.size = size;
    projector.focal_px *= ratio;
    projector.principal_px *= ratio;
  }
  std::vector<OutputSpec> outputs;
  TrueWarpOptions options;
  // 0.01 px, FORMATS.md's bound: the warp is the display here, not a simulation's ground truth.
  options.max_error_px = 0.01;
  for (std::size_t k = 0; k < rig.projectors.size(); ++k) {
    outputs.push_back({rig.projectors[k].name, true_warp(rig, k, options)});
  }
  return outputs;
}

std::string layout_label(const FacetLayout& layout) {
  if (const auto* strips = std::get_if<FacetStrips>(&layout)) {
    return format("pieces=%d", strips->count);
  }
  if (const auto* grid = std::get_if<FacetGrid>(&layout)) {
    return format("grid=%dx%d", grid->columns, grid->rows);
  }
  return format("tol=%gpx", std::get<FacetTolerance>(layout).px);
}

// The settings of one scenario: facets over `layouts`, facets-gs and tessellated at `gs_layout`
// (the geometry-shader and tessellator forms loop over facets per triangle, far slower on a
// software rasterizer than the compute form, so they get a small layout), naive over
// `naive_layouts` (naive issues one draw per facet and object run, so layouts of thousands of
// facets make it draw-call bound and are left out), cube faces of the given edge lengths, vertex
// with the given tessellation caps.
std::vector<BenchSetting> sweep(const std::vector<FacetLayout>& layouts,
                                const FacetLayout& gs_layout,
                                const std::vector<FacetLayout>& naive_layouts,
                                const std::vector<int>& faces,
                                const std::vector<int>& tessellation) {
  std::vector<BenchSetting> settings;
  for (const FacetLayout& layout : layouts) {
    BenchSetting s{"facets", layout_label(layout), {}, {}, {}};
    s.settings.facets.layout = layout;
    settings.push_back(s);
  }
  // The tessellator form takes the geometry-shader form's layout: it walks the same way.
  for (const char* method : {"facets-gs", "tessellated"}) {
    const std::string label = layout_label(gs_layout);
    BenchSetting s{method, label, {}, label, {}};
    s.settings.facets.layout = gs_layout;
    settings.push_back(s);
  }
  for (const FacetLayout& layout : naive_layouts) {
    BenchSetting s{"naive", layout_label(layout), {}, {}, {}};
    s.settings.facets.layout = layout;
    settings.push_back(s);
  }
  for (int face : faces) {
    BenchSetting s{"cubemap", format("face=%d", face), {}, {}, {}};
    s.settings.cube_face_size = face;
    settings.push_back(s);
  }
  for (int cap : tessellation) {
    BenchSetting s{"vertex", format("tess=%d", cap), {}, {}, {}};
    s.settings.max_tessellation = cap;
    settings.push_back(s);
  }
  return settings;
}

// Worst and RMS, in output pixels, of `displacement(q, preimage)` over the output's pixels
// (about 256² of them, evenly strided) that the warp covers.
template <class Displacement>
std::pair<double, double> over_output_pixels(const Warp& warp, const WarpInverse& inverse,
                                             const Displacement& displacement) {
  const glm::ivec2 size = warp.output_size;
  const int stride = std::max(1, int(std::sqrt(double(size.x) * size.y / 65536.0)));
  double max_px = 0, sum_sq = 0;
  std::size_t n = 0;
  for (int y = stride / 2; y < size.y; y += stride) {
    for (int x = stride / 2; x < size.x; x += stride) {
      const glm::dvec2 q(x + 0.5, y + 0.5);
      const auto inverted = inverse.invert(q);
      if (!inverted) continue;
      const double worst = displacement(q, *inverted);
      max_px = std::max(max_px, worst);
      sum_sq += worst * worst;
      ++n;
    }
  }
  return {max_px, n ? std::sqrt(sum_sq / double(n)) : 0.0};
}

// Largest displacement, in output pixels, that a nearest-texel lookup in a cube map of face edge
// `face` can cause, sampled over the output pixels (the half-diagonal of the texel holding each
// pixel's exact direction, mapped through the warp). Faces are the eye frame's axes, as in the
// cube-map method.
std::pair<double, double> cube_texel_error(const Warp& warp, const WarpInverse& inverse, int face) {
  const double half_texel = 1.0 / face;  // face coordinates span [-1, 1]
  return over_output_pixels(warp, inverse, [&](const glm::dvec2& q, const auto& inverted) {
    const glm::dvec3 v = inverted.v_eye;
    int m = 0;
    for (int k = 1; k < 3; ++k) {
      if (std::abs(v[k]) > std::abs(v[m])) m = k;
    }
    const int a = (m + 1) % 3, b = (m + 2) % 3;
    const glm::dvec3 on_face = v / std::abs(v[m]);
    double worst = 0;
    for (const double sb : {-1.0, 1.0}) {
      glm::dvec3 moved = on_face;
      moved[a] += half_texel;
      moved[b] += sb * half_texel;
      const auto projected = warp.project(moved, inverted.st.x);
      if (projected) worst = std::max(worst, glm::length(projected->q - q));
    }
    return worst;
  });
}

// The perspective baseline's rows ("perspective", the seed's IB row), one per image size,
// placed after the cube map's: for outputs one perspective image can hold (view deformation,
// dome4's projectors).
std::vector<BenchSetting> with_perspective_images(std::vector<BenchSetting> settings,
                                                  const std::vector<int>& sizes) {
  auto at = settings.end();
  for (auto it = settings.begin(); it != settings.end(); ++it)
    if (it->method == "cubemap") at = it + 1;
  std::vector<BenchSetting> rows;
  for (int size : sizes) {
    BenchSetting s{"perspective", format("image=%d", size), {}, {}, {}};
    s.settings.cube_face_size = size;
    rows.push_back(s);
  }
  settings.insert(at, rows.begin(), rows.end());
  return settings;
}

// As cube_texel_error for the perspective baseline's image of `larger_side` texels over the
// output's covering_frustum: the half-diagonal of the image texel holding each pixel's exact
// direction, mapped through the warp.
std::pair<double, double> perspective_texel_error(const Warp& warp, const WarpInverse& inverse,
                                                  int larger_side) {
  const Frustum frustum = covering_frustum(warp, "bench");
  const glm::ivec2 image = perspective_image_size(frustum, larger_side);
  const double half_u = (frustum.tan_extent[1] - frustum.tan_extent[0]) / (2.0 * image.x);
  const double half_v = (frustum.tan_extent[2] - frustum.tan_extent[3]) / (2.0 * image.y);
  return over_output_pixels(warp, inverse, [&](const glm::dvec2& q, const auto& inverted) {
    const glm::dvec3 v_view = glm::transpose(frustum.R_eye_frustum) * inverted.v_eye;
    if (!(v_view.z < 0)) return 0.0;
    const glm::dvec2 tangent = glm::dvec2(v_view) / -v_view.z;
    double worst = 0;
    for (const double su : {-1.0, 1.0})
      for (const double sv : {-1.0, 1.0}) {
        const glm::dvec3 moved(tangent.x + su * half_u, tangent.y + sv * half_v, -1.0);
        const auto projected = warp.project(frustum.R_eye_frustum * moved, inverted.st.x);
        if (projected) worst = std::max(worst, glm::length(projected->q - q));
      }
    return worst;
  });
}

struct Runner {
  BenchSetting setting;
  std::unique_ptr<RenderMethod> method;
  GpuTimer timer;
  std::vector<double> frame_ms;
  std::vector<double> reused_ms;   // facet pipelines: frames that skip passes 1 and 2
  std::vector<double> replace_ms;  // @lod scenes: taking each rebuilt scene (BenchRow)
  std::vector<RenderStats> stats;
  BenchRow row;
};

double wall_ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

std::vector<BenchSetting> with_matched_tolerance(const BenchScenario& scenario,
                                                 double cube_max_px) {
  std::vector<BenchSetting> settings = scenario.settings;
  const int face = scenario.matched_cube_face;
  const bool cube = std::any_of(settings.begin(), settings.end(), [face](const BenchSetting& s) {
    return s.method == "cubemap" && s.settings.cube_face_size == face;
  });
  const bool tolerance = std::any_of(settings.begin(), settings.end(), [](const BenchSetting& s) {
    return s.method == "facets" && std::holds_alternative<FacetTolerance>(s.settings.facets.layout);
  });
  const double px = std::floor(cube_max_px * 1000) / 1000;
  if (face <= 0 || !cube || !tolerance || !(px > 0)) return settings;
  const auto last_facets = std::find_if(settings.rbegin(), settings.rend(),
                                        [](const BenchSetting& s) { return s.method == "facets"; });
  BenchSetting matched{"facets", format("tol=%gpx (cube %d)", px, face), {}, {}, {}};
  matched.settings.facets.layout = FacetTolerance{px};
  settings.insert(last_facets.base(), matched);
  return settings;
}

namespace {

// What every scenario of one bench run shares: the size scale (--size-scale, and 1/8 for the
// quick run) and the cube faces, tessellation caps and matched face that follow from it.
struct ScenarioSizes {
  double scale = 1;
  bool quick = false;
  std::vector<int> tess;         // the vertex method's tessellation caps
  std::vector<int> faces_sweep;  // the cube map's face edges, scaled
  int matched_face = 0;          // the full sweeps' matched cube face (0 in the quick run)

  explicit ScenarioSizes(const BenchOptions& options)
      : scale(options.size_scale * (options.quick ? 0.125 : 1.0)), quick(options.quick) {
    tess = quick ? std::vector<int>{1, 16} : std::vector<int>{1, 4, 16};
    faces_sweep =
        faces(quick ? std::vector<int>{256, 1024} : std::vector<int>{256, 512, 1024, 2048});
    // The full sweeps match a facets build to the 512² cube map (the scale rows to their one cube).
    matched_face = quick ? 0 : 512;
  }
  // Cube face edges scaled, at least 8 texels.
  std::vector<int> faces(std::vector<int> edges) const {
    for (int& e : edges) e = std::max(8, int(std::lround(e * scale)));
    return edges;
  }
};

// The names of options.scenarios (cylinder, deformation and dome when empty), after the checks
// of every option that make_bench_scenarios refuses before any work.
std::vector<std::string> checked_scenario_names(const BenchOptions& options) {
  // "deformation" and "dome" are groups; their parts can be run alone.
  static const std::set<std::string> known = {"cylinder",
                                              "deformation",
                                              "deformation-80x60",
                                              "deformation-128x128",
                                              "dome",
                                              "dome-master",
                                              "dome4",
                                              "scale",
                                              "scale-scenes",
                                              "scale-facets",
                                              "scale-width",
                                              "glc",
                                              "glc-city",
                                              "glc-panorama",
                                              "glc-mirror",
                                              "depth"};
  std::vector<std::string> names = options.scenarios;
  if (names.empty()) names = {"cylinder", "deformation", "dome"};
  for (const std::string& name : names) {
    if (!known.contains(name)) {
      throw InputError("command line", OptionName{"scenarios"},
                       "expected cylinder, deformation, deformation-80x60, deformation-128x128, "
                       "dome, dome-master, dome4, scale (scale-scenes, scale-facets, scale-width), "
                       "glc (glc-city, glc-panorama, glc-mirror), depth or all; got '" +
                           name + "'");
    }
  }
  parse_scene_name(options.scene);  // InputError for a bad --scene before any work
  if (!(options.size_scale >= 1.0 / 64) || options.size_scale > 4) {
    throw InputError("command line", OptionName{"size_scale"}, "expected a scale in [1/64, 4]");
  }
  if (options.frames < 1)
    throw InputError("command line", OptionName{"frames"}, "expected at least 1");
  return names;
}

// A scenario of a built-in display (its default outputs at `size`, scaled), the city: `quick`'s
// settings in the quick run, else `full`'s; matched to the sweep's cube face.
void add_builtin_display_scenario(const std::string& name, const std::string& display,
                                  glm::ivec2 size, const std::string& what,
                                  const ScenarioSizes& sizes, std::vector<BenchSetting> quick,
                                  std::vector<BenchSetting> full,
                                  std::vector<BenchScenario>& scenarios) {
  BenchScenario s;
  s.name = name;
  s.outputs = load_display_outputs(display, scaled(size, sizes.scale));
  s.description = what + " at " + size_text(s.outputs[0].warp.output_size) + ", the city";
  s.settings = sizes.quick ? std::move(quick) : std::move(full);
  s.matched_cube_face = sizes.matched_face;
  scenarios.push_back(std::move(s));
}

// "cylinder": the seed's 360x90 cylinder.
void add_cylinder_scenario(const ScenarioSizes& sizes, std::vector<BenchScenario>& scenarios) {
  add_builtin_display_scenario(
      "cylinder", "builtin:cylinder360", {1600, 1200}, "the seed's 360x90 cylinder", sizes,
      sweep({FacetStrips{16}, FacetTolerance{1}}, FacetStrips{16}, {FacetStrips{16}},
            sizes.faces_sweep, sizes.tess),
      sweep({FacetStrips{160}, FacetStrips{40}, FacetStrips{80}, FacetTolerance{1},
             FacetTolerance{0.25}, FacetTolerance{0.1}},
            FacetStrips{160},
            {FacetStrips{160}, FacetStrips{40}, FacetTolerance{1}, FacetTolerance{0.25}},
            sizes.faces_sweep, sizes.tess),
      scenarios);
}

// "glc" (or one of its parts): the GLC cameras of Yu, Yu & McMillan's paper cases (configs/glc
// holds the same as files): the cross-slit city, the 360° circular cross-slit panorama and the
// mirror sphere, each drawn by the two GLC methods alone.
void add_glc_scenarios(const std::string& name, const ScenarioSizes& sizes,
                       std::vector<BenchScenario>& scenarios) {
  auto glc_scenario = [&](const std::string& part, const std::string& description,
                          PiecewiseGlc camera) {
    BenchScenario s;
    s.name = part;
    s.description = description + " at " + size_text(camera.size) + ", " +
                    std::to_string(camera.pieces.size()) + " GLCs, the city";
    const glm::ivec2 size = camera.size;
    s.outputs.push_back({part, Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), size),
                         std::make_shared<const PiecewiseGlc>(std::move(camera))});
    // The ray cast and the paper's two-pass rasterization, side by side.
    for (const char* method : {"glc", "glc-2pass"}) {
      BenchSetting setting;
      setting.method = method;
      setting.label = "camera";
      s.settings.push_back(setting);
    }
    scenarios.push_back(std::move(s));
  };
  const bool all_parts = name == "glc";
  if (all_parts || name == "glc-city") {
    const glm::ivec2 size = scaled({1024, 320}, sizes.scale);
    GlcFrame frame;
    frame.axes = glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1));
    glc_scenario("glc-city", "cross-slit camera (slits 1 and 4 m behind the image plane)",
                 single_glc(cross_slit_glc(frame, {{0, 0, -1}, {0, 1, 0}}, {{0, 0, -4}, {1, 0, 0}},
                                           {3.2, 2.0}, size, "bench", "glc-city"),
                            size));
  }
  if (all_parts || name == "glc-panorama") {
    const glm::ivec2 size = scaled({800, 600}, sizes.scale);
    glc_scenario(
        "glc-panorama", "360-degree circular cross-slit panorama",
        circular_panorama(360, 0.25, 120, std::min(40, size.x), size, "bench", "glc-panorama"));
  }
  if (all_parts || name == "glc-mirror") {
    const glm::ivec2 size = scaled({800, 800}, sizes.scale);
    glc_scenario("glc-mirror", "mirror sphere (32 rings)",
                 mirror_sphere({0, 0, -3}, 1.0, 50, 32, size, "bench", "glc-mirror"));
  }
}

// Scene size: every method at one setting each, on the cylinder and the dome master, over
// growing tiled cities (scene names and counts: scene_names.hpp). Ordered by scene, so run_bench
// builds each scene once.
void add_scale_scenes_scenarios(const ScenarioSizes& sizes, std::vector<BenchScenario>& scenarios) {
  const std::vector<std::string> scenes =
      sizes.quick ? std::vector<std::string>{"builtin:city", "builtin:city:2"}
                  : std::vector<std::string>{"builtin:city", "builtin:city:4", "builtin:city:8"};
  for (const std::string& scene : scenes) {
    const std::uint64_t triangles = builtin_scene_triangles(parse_scene_name(scene));
    for (const bool cylinder : {true, false}) {
      BenchScenario s;
      s.scale_group = cylinder ? "scale-cylinder" : "scale-dome";
      s.name = s.scale_group + ":" + scene.substr(std::string("builtin:").size());
      s.scene = scene;
      s.outputs =
          cylinder ? load_display_outputs("builtin:cylinder360", scaled({1600, 1200}, sizes.scale))
                   : load_display_outputs("builtin:dome180", scaled({2048, 2048}, sizes.scale));
      s.description = std::string(cylinder ? "the 360x90 cylinder" : "the 180-degree dome") +
                      " at " + size_text(s.outputs[0].warp.output_size) + ", " + scene + " (" +
                      std::to_string(triangles) + " triangles)";
      s.settings = sweep({FacetTolerance{0.25}}, FacetTolerance{0.25}, {FacetTolerance{0.25}},
                         sizes.faces({512}), {1});
      s.matched_cube_face = sizes.quick ? 0 : sizes.faces({512})[0];
      scenarios.push_back(std::move(s));
    }
  }
}

// Facet count: the facet methods over the seed's strips on the cylinder, the city, one output
// size; each method's rows fitted together.
void add_scale_facets_scenario(const ScenarioSizes& sizes, std::vector<BenchScenario>& scenarios) {
  BenchScenario s;
  s.scale_group = "scale-facets-cylinder";
  s.name = s.scale_group;
  s.scene = "builtin:city";
  s.outputs = load_display_outputs("builtin:cylinder360", scaled({1600, 1200}, sizes.scale));
  s.description = "the 360x90 cylinder at " + size_text(s.outputs[0].warp.output_size) +
                  ", builtin:city, the facet methods over strip counts";
  const std::vector<int> counts =
      sizes.quick ? std::vector<int>{20, 40} : std::vector<int>{40, 80, 160, 320};
  for (const char* method : {"facets", "facets-gs", "naive"}) {
    for (const int count : counts) {
      BenchSetting setting{method, layout_label(FacetStrips{count}), {}, {}, "pieces=N"};
      setting.settings.facets.layout = FacetStrips{count};
      if (std::string(method) == "facets-gs") setting.same_ids_as = setting.label;
      s.settings.push_back(setting);
    }
  }
  scenarios.push_back(std::move(s));
}

// Output width: every method at one setting (fixed strips, so the facet count stays) on the
// cylinder at three sizes of one aspect, the city.
void add_scale_width_scenarios(const ScenarioSizes& sizes, std::vector<BenchScenario>& scenarios) {
  const std::vector<double> widths =
      sizes.quick ? std::vector<double>{0.5, 1.0} : std::vector<double>{0.5, 0.7071, 1.0};
  for (const double width : widths) {
    BenchScenario s;
    s.scale_group = "scale-width-cylinder";
    s.scene = "builtin:city";
    s.outputs =
        load_display_outputs("builtin:cylinder360", scaled({1600, 1200}, sizes.scale * width));
    s.name = s.scale_group + ":" + size_text(s.outputs[0].warp.output_size);
    s.description = "the 360x90 cylinder at " + size_text(s.outputs[0].warp.output_size) +
                    ", builtin:city, every method at one setting";
    s.settings =
        sweep({FacetStrips{80}}, FacetStrips{80}, {FacetStrips{80}}, sizes.faces({512}), {1});
    scenarios.push_back(std::move(s));
  }
}

// "scale" (or one of its parts): frame cost against what grows, each in a scale group of its own
// (bench_scale_fits).
void add_scale_scenarios(const std::string& name, const ScenarioSizes& sizes,
                         std::vector<BenchScenario>& scenarios) {
  const bool all_parts = name == "scale";
  if (all_parts || name == "scale-scenes") add_scale_scenes_scenarios(sizes, scenarios);
  if (all_parts || name == "scale-facets") add_scale_facets_scenario(sizes, scenarios);
  if (all_parts || name == "scale-width") add_scale_width_scenarios(sizes, scenarios);
}

// "depth": Liu, Liu & Wu's comparison of polygons against depth images (their Table 1) on the
// 180-degree dome master: the city's polygons, the same surfaces cut into 64 times the triangles
// (city-fine:8), and DPCIs of the city at 512 and 256, every method but naive (quick: the city and
// its DPCIs at 64 and 32, facets at 1 px and the cube map), all from the DPCI's eye. naive draws
// every object whole into each piece it meets, and a DPCI is one or two objects: its 857 k
// triangles into each of the 1,860 pieces took 90 s a frame at a quarter of the size.
void add_depth_scenarios(const ScenarioSizes& sizes, std::vector<BenchScenario>& scenarios) {
  const std::string source = "builtin:city";
  const std::vector<std::string> polygons =
      sizes.quick ? std::vector<std::string>{source}
                  : std::vector<std::string>{source, "builtin:city-fine:8"};
  const std::vector<int> image_sizes =
      sizes.quick ? std::vector<int>{64, 32} : std::vector<int>{512, 256};
  auto add = [&](const std::string& scene, int image_size) {
    BenchScenario s;
    s.scene = scene;
    s.depth_image_eye = true;
    s.depth_image_size = glm::ivec2(image_size);
    s.outputs = load_display_outputs("builtin:dome180", scaled({2048, 2048}, sizes.scale));
    const std::string drawn = image_size > 0
                                  ? "a " + size_text(s.depth_image_size) + " DPCI of " + scene
                                  : scene + "'s polygons";
    s.name = "depth:" + scene.substr(std::string("builtin:").size()) +
             (image_size > 0 ? "@dpci" + std::to_string(image_size) : "");
    s.description = "the 180-degree dome at " + size_text(s.outputs[0].warp.output_size) + ", " +
                    drawn + ", from the DPCI's eye";
    const FacetTolerance tolerance{sizes.quick ? 1.0 : 0.25};
    s.settings = sweep({tolerance}, tolerance, {}, sizes.faces({512}), {1});
    if (sizes.quick)
      std::erase_if(s.settings, [](const BenchSetting& setting) {
        return setting.method != "facets" && setting.method != "cubemap";
      });
    s.matched_cube_face = sizes.quick ? 0 : sizes.faces({512})[0];
    scenarios.push_back(std::move(s));
  };
  for (const std::string& scene : polygons) add(scene, 0);
  for (const int image_size : image_sizes) add(source, image_size);
}

// "deformation" (or one of its parts): the view deformation on an 80x60 and (full sweep only) a
// 128x128 camera texture.
void add_deformation_scenarios(const std::string& name, const ScenarioSizes& sizes,
                               std::vector<BenchScenario>& scenarios) {
  for (const glm::ivec2 cells : {glm::ivec2(80, 60), glm::ivec2(128, 128)}) {
    if (sizes.quick && cells.x == 128) continue;
    if (name != "deformation" && name != "deformation-" + size_text(cells)) continue;
    BenchScenario s;
    s.name = "deformation-" + size_text(cells);
    const glm::ivec2 size = scaled({1024, 768}, sizes.scale);
    s.outputs.push_back({"deformation", deformation_warp(size, cells)});
    s.description = "view deformation: perspective base, built-in smooth offset map on a " +
                    size_text(cells) + " camera texture, " + size_text(size);
    if (sizes.quick) {
      s.settings = sweep({FacetGrid{8, 6}, FacetTolerance{1}}, FacetGrid{8, 6}, {FacetGrid{8, 6}},
                         sizes.faces_sweep, sizes.tess);
    } else {
      // The seed's facets are the camera texture's cells.
      const FacetGrid quarter{cells.x / 4, cells.y / 4};
      s.settings = sweep({FacetGrid{cells.x, cells.y}, quarter, FacetTolerance{1}}, quarter,
                         {quarter, FacetTolerance{1}}, sizes.faces_sweep, sizes.tess);
    }
    s.settings = with_perspective_images(std::move(s.settings), sizes.faces_sweep);
    s.matched_cube_face = sizes.matched_face;
    scenarios.push_back(std::move(s));
  }
}

// "dome-master": the 180-degree dome master.
void add_dome_master_scenario(const ScenarioSizes& sizes, std::vector<BenchScenario>& scenarios) {
  add_builtin_display_scenario("dome", "builtin:dome180", {2048, 2048}, "180-degree dome master",
                               sizes,
                               sweep({FacetTolerance{1}, FacetGrid{4, 4}}, FacetGrid{4, 4},
                                     {FacetGrid{4, 4}}, sizes.faces_sweep, sizes.tess),
                               sweep({FacetTolerance{0.25}, FacetGrid{16, 16}, FacetTolerance{1},
                                      FacetTolerance{0.5}, FacetTolerance{0.1}},
                                     FacetGrid{16, 16}, {FacetGrid{16, 16}, FacetTolerance{1}},
                                     sizes.faces_sweep, sizes.tess),
                               scenarios);
}

// "dome4": the multi-projector dome rig of options.dome_rig, true warps.
void add_dome_rig_scenario(const std::filesystem::path& dome_rig, const ScenarioSizes& sizes,
                           std::vector<BenchScenario>& scenarios) {
  BenchScenario s;
  s.name = "dome4";
  s.outputs = rig_outputs(dome_rig, sizes.scale);
  s.description = "multi-projector dome rig " + dome_rig.filename().string() + ": " +
                  std::to_string(s.outputs.size()) + " projectors at " +
                  size_text(s.outputs[0].warp.output_size) + ", true warps";
  if (sizes.quick) {
    s.settings = sweep({FacetTolerance{1}}, FacetTolerance{1}, {FacetTolerance{1}},
                       sizes.faces_sweep, sizes.tess);
  } else {
    s.settings =
        sweep({FacetTolerance{0.25}, FacetTolerance{1}, FacetTolerance{0.5}, FacetTolerance{0.1}},
              FacetTolerance{1}, {FacetTolerance{1}, FacetTolerance{0.25}}, sizes.faces_sweep,
              sizes.tess);
  }
  s.settings = with_perspective_images(std::move(s.settings), sizes.faces_sweep);
  s.matched_cube_face = sizes.matched_face;
  scenarios.push_back(std::move(s));
}

}  // namespace

std::vector<BenchScenario> make_bench_scenarios(const BenchOptions& options) {
  const std::vector<std::string> names = checked_scenario_names(options);
  const ScenarioSizes sizes(options);
  std::vector<BenchScenario> scenarios;
  for (const std::string& name : names) {
    if (name == "cylinder") {
      add_cylinder_scenario(sizes, scenarios);
    } else if (name.starts_with("glc")) {
      add_glc_scenarios(name, sizes, scenarios);
    } else if (name.starts_with("scale")) {
      add_scale_scenarios(name, sizes, scenarios);
    } else if (name == "depth") {
      add_depth_scenarios(sizes, scenarios);
    } else if (name.starts_with("deformation")) {
      add_deformation_scenarios(name, sizes, scenarios);
    } else {
      // "dome" is the dome master and the rig; "dome-master" and "dome4" one of them.
      if (name != "dome4") add_dome_master_scenario(sizes, scenarios);
      if (name != "dome-master") add_dome_rig_scenario(options.dome_rig, sizes, scenarios);
    }
  }
  return scenarios;
}

namespace {

using Say = std::function<void(const std::string&)>;

// A scenario's scene with its oracle and views. Scenarios with one scene follow each other (the
// scale scenarios) or share BenchOptions::scene, so each scene is built once.
struct LoadedScene {
  std::string name;
  Scene fixed;  // the scene, unless `lod` holds it
  // A scene with @lod depth images: rebuilt as the eye moves (follow), the reference built from
  // the first view's.
  std::unique_ptr<ViewDependentScene> lod;
  GpuScene gpu;
  std::unique_ptr<ReferenceRaycaster> raycaster;
  std::unique_ptr<FrameViews> views;

  const Scene& scene() const { return lod ? lod->scene() : fixed; }
  // With `lod`: chooses the levels for frame k's eye; where the scene was rebuilt, replaces the
  // GPU scene's geometry and returns true.
  bool follow(int k) {
    if (!lod || !lod->update(glm::dvec3(views->T_world_eye(k)[3]))) return false;
    replace_geometry(gpu, lod->scene());
    return true;
  }
};

// A depth-image scenario's scene (BenchScenario::depth_image_eye): the polygons with the eye of
// their DPCI as a camera, or that DPCI's grid mesh.
Scene depth_scenario_scene(Scene polygons, const SceneName& name, glm::ivec2 image_size) {
  const glm::dmat4 T_world_image =
      depth_image_pose(polygons, name.builtin_city(), DepthImageKind::dpci, std::nullopt);
  if (image_size.x > 0) {
    return depth_image_mesh(render_depth_image(polygons, {.kind = DepthImageKind::dpci,
                                                          .size = image_size,
                                                          .T_world_image = T_world_image}))
        .scene;
  }
  SceneCamera eye;
  eye.name = kDepthImageEyeCamera;
  eye.T_world_camera = T_world_image;
  polygons.cameras.push_back(eye);
  return polygons;
}

// Makes `loaded` hold the scenario's scene, `scene_text` unless the scenario draws a depth
// image, building it unless it holds it already (the last scene's GPU and CPU memory freed
// first).
void load_scene_once(std::unique_ptr<LoadedScene>& loaded, const std::string& scene_text,
                     const BenchScenario& scenario, const BenchOptions& options, const Say& say) {
  const std::string name =
      !scenario.depth_image_eye ? scene_text
      : scenario.depth_image_size.x > 0
          ? "DPCI " + size_text(scenario.depth_image_size) + " of " + scene_text
          : scene_text + " from its DPCI's eye";
  if (loaded && loaded->name == name) return;
  loaded.reset();
  const auto start = std::chrono::steady_clock::now();
  const SceneName scene_name = parse_scene_name(scene_text);
  auto next = std::make_unique<LoadedScene>();
  next->name = name;
  next->fixed = load_scene(scene_name);
  if (scenario.depth_image_eye)
    next->fixed =
        depth_scenario_scene(std::move(next->fixed), scene_name, scenario.depth_image_size);
  // The view facet render takes by default: outside a closed model, else at its centre.
  const SceneView view = choose_scene_view(
      next->fixed,
      !scenario.depth_image_eye && scene_text == options.scene ? options.view : ViewRequest{},
      scene_name.builtin_city());
  next->views = std::make_unique<FrameViews>(view, kBenchFrameStepS, options.static_view);
  if (uses_depth_lod(scene_name)) {
    next->lod = std::make_unique<ViewDependentScene>(scene_name,
                                                     glm::dvec3(next->views->T_world_eye(0)[3]));
    next->fixed = Scene{};
  }
  next->gpu = upload_scene(next->scene());
  next->raycaster = std::make_unique<ReferenceRaycaster>(next->scene());
  loaded = std::move(next);
  say(format("scene %s: %zu triangles, %zu objects, ready in %.0f ms", name.c_str(),
             loaded->scene().triangle_count(), loaded->scene().objects.size(),
             wall_ms_since(start)));
  if (!view.message.empty()) say("scene " + name + ": " + view.message);
}

// One scenario's bench, in the order run_bench calls it: the setup (each output's warp inverse,
// reference IDs at the first view and target), then per setting a runner prepared and measured
// for accuracy on its warm-up frame, then the timed frames of all runners interleaved, then a
// report row per runner.
class ScenarioBench {
 public:
  ScenarioBench(const BenchScenario& scenario, std::string scene_text, LoadedScene& loaded,
                const BenchOptions& options, const Say& say)
      : scenario_(scenario),
        scene_text_(std::move(scene_text)),
        loaded_(loaded),
        options_(options),
        say_(say),
        T0_(loaded.views->T_eye_world(0)) {
    const OutputSpec& first = scenario.outputs[0];
    wrap_x_ = first.glc ? first.glc->wraps_horizontally : first.warp.base.wraps_horizontally();
    for (const OutputSpec& output : scenario.outputs) {
      inverses_.emplace_back(output.warp);
      // A GLC camera's pixels cast its own rays (the default near distance of RenderSettings).
      reference_.push_back(output.glc
                               ? loaded.raycaster->ids(*output.glc, T0_, RenderSettings{}.z_near)
                               : loaded.raycaster->ids(inverses_.back(), T0_));
    }
    for (const OutputSpec& output : scenario.outputs) {
      targets_.push_back(OutputTarget::create(output.warp.output_size));
    }
  }

  // The cube map's geometric max error at the scenario's matched face edge, worst over the
  // outputs (0 without one): with_matched_tolerance's argument.
  double matched_cube_max_px() const {
    double cube_max_px = 0;
    for (std::size_t i = 0; scenario_.matched_cube_face > 0 && i < scenario_.outputs.size(); ++i) {
      cube_max_px = std::max(cube_max_px, cube_texel_error(scenario_.outputs[i].warp, inverses_[i],
                                                           scenario_.matched_cube_face)
                                              .first);
    }
    return cube_max_px;
  }

  // Prepares `setting`'s method and measures its accuracy on the warm-up frame; a setting whose
  // prepare throws InputError or ShaderError keeps a row with the error and is not timed.
  void prepare(const BenchSetting& setting) {
    Runner runner;
    runner.setting = setting;
    runner.row = first_columns(setting);
    BenchRow& row = runner.row;
    // InputError: the setting does not apply here; ShaderError: this GL driver refuses the
    // method's shaders (the driver's log is in the row). The other settings still run.
    const auto not_run = [&](const std::exception& error) {
      row.error = error.what();
      say_("  " + setting.method + " " + setting.label + ": not run: " + row.error);
      runner.method.reset();
      runners_.push_back(std::move(runner));
    };
    const auto start = std::chrono::steady_clock::now();
    try {
      runner.method = make_render_method(setting.method);
      runner.method->prepare(loaded_.scene(), loaded_.gpu, scenario_.outputs, setting.settings);
    } catch (const InputError& error) {
      return not_run(error);
    } catch (const ShaderError& error) {
      return not_run(error);
    }
    const double prepare_ms = wall_ms_since(start);
    const auto measure_start = std::chrono::steady_clock::now();
    measure_ids(runner);
    measure_geometric_error(setting, row);
    const std::string sampled =
        row.edge_searched_pixels < row.edge_differing_pixels
            ? format(" (edges over %llu of %llu differing pixels)",
                     static_cast<unsigned long long>(row.edge_searched_pixels),
                     static_cast<unsigned long long>(row.edge_differing_pixels))
            : std::string();
    say_(format(
        "  %-11s %-12s prepared in %7.0f ms, measured in %6.0f ms: id_mismatch %.5f, edges max "
        "%.2f px (output %zu pixel %d,%d) p99 %.2f px, %llu depth ties, %llu drawn outside the "
        "display (up to %.2f px), geometric max %.3f px%s",
        setting.method.c_str(), setting.label.c_str(), prepare_ms, wall_ms_since(measure_start),
        row.id_mismatch, row.max_edge_px, row.worst_edge_output, row.worst_edge_pixel.x,
        row.worst_edge_pixel.y, row.p99_edge_px,
        static_cast<unsigned long long>(row.depth_tie_pixels),
        static_cast<unsigned long long>(row.outside_display_pixels), row.outside_display_max_px,
        row.geometric_max_px, sampled.c_str()));
    runners_.push_back(std::move(runner));
  }

  // Timed frames, interleaved: every setting once per frame, the starting setting rotating.
  void time_frames() {
    const std::size_t rebuilds_before = loaded_.lod ? loaded_.lod->stats().build_ms.size() : 0;
    for (int k = 1; k <= options_.frames; ++k) {
      const glm::dmat4 T = loaded_.views->T_eye_world(k);
      if (loaded_.follow(k)) take_rebuilt_scene();
      for (std::size_t j = 0; j < runners_.size(); ++j) {
        Runner& runner = runners_[(j + std::size_t(k)) % runners_.size()];
        if (!runner.method) continue;
        const auto start = std::chrono::steady_clock::now();
        runner.stats.push_back(runner.method->render(T, targets_, &runner.timer));
        glFinish();
        runner.frame_ms.push_back(wall_ms_since(start));
        if (runner.setting.method == "facets" || runner.setting.method == "facets-gs") {
          // The same view again: the pipeline keeps passes 1 and 2 and draws only.
          const auto again = std::chrono::steady_clock::now();
          const RenderStats reused = runner.method->render(T, targets_);
          glFinish();
          if (reused.reused_replication) runner.reused_ms.push_back(wall_ms_since(again));
        }
      }
      say_(format("  timed frame %d of %d done", k, options_.frames));
    }
    if (loaded_.lod) {
      const ViewDependentScene::Stats& stats = loaded_.lod->stats();
      const std::vector<double> build_ms(stats.build_ms.begin() + std::ptrdiff_t(rebuilds_before),
                                         stats.build_ms.end());
      for (Runner& runner : runners_) {
        runner.row.scene_rebuilds = build_ms.size();
        if (!build_ms.empty()) runner.row.scene_rebuild_ms = median(build_ms);
        if (!runner.replace_ms.empty()) runner.row.scene_replace_ms = median(runner.replace_ms);
      }
      say_(format("  depth image level of detail: %zu rebuilds in %d frames, %.1f ms each",
                  build_ms.size(), options_.frames, median(build_ms)));
      // The next scenario starts from the first view's scene, which its reference shows.
      if (loaded_.follow(0)) say_("  scene back at the first view's levels");
    }
  }

  // Every prepared runner's method takes the scene rebuilt for a new view (timed in replace_ms).
  void take_rebuilt_scene() {
    for (Runner& runner : runners_) {
      if (!runner.method) continue;
      const auto start = std::chrono::steady_clock::now();
      runner.method->replace_scene(loaded_.scene(), loaded_.gpu, scenario_.outputs,
                                   runner.setting.settings);
      glFinish();
      runner.replace_ms.push_back(wall_ms_since(start));
    }
  }

  // Appends each runner's row, with its timings and last frame's figures when it ran.
  void add_rows(std::vector<BenchRow>& rows) {
    for (Runner& runner : runners_) {
      if (runner.method) summarize_timing(runner);
      rows.push_back(runner.row);
    }
  }

 private:
  // The columns a row has whether or not its setting runs.
  BenchRow first_columns(const BenchSetting& setting) const {
    BenchRow row;
    row.scenario = scenario_.name;
    row.scene = scene_text_;
    row.scale_group = scenario_.scale_group;
    row.triangles_scene = loaded_.scene().triangle_count();
    row.method = setting.method;
    row.setting = setting.label;
    row.fit_label = setting.fit_label.empty() ? setting.label : setting.fit_label;
    row.outputs = int(scenario_.outputs.size());
    row.output_size = size_text(scenario_.outputs[0].warp.output_size);
    row.frames = options_.frames;
    return row;
  }

  // Renders the accuracy frame (also the warm-up) and compares its IDs with the reference:
  // mismatch, edge displacement, and the pixels differing from a facets setting's IDs.
  void measure_ids(Runner& runner) {
    const BenchSetting& setting = runner.setting;
    BenchRow& row = runner.row;
    const ReferenceRaycaster& raycaster = *loaded_.raycaster;
    runner.method->render(T0_, targets_);
    glFinish();
    IdComparison pooled;
    std::vector<std::vector<std::uint32_t>> ids;
    for (std::size_t i = 0; i < targets_.size(); ++i) {
      ids.push_back(targets_[i].read_ids());
      const IdComparison c =
          compare_ids(reference_[i], ids.back(), targets_[i].size(), {.wrap_x = wrap_x_});
      const EdgeDisplacement e =
          scenario_.outputs[i].glc
              ? raycaster.edge_displacement(*scenario_.outputs[i].glc, T0_, RenderSettings{}.z_near,
                                            reference_[i], ids.back(), {.wrap_x = wrap_x_})
              : raycaster.edge_displacement(inverses_[i], T0_, reference_[i], ids.back(),
                                            {.wrap_x = wrap_x_});
      pooled.compared_pixels += c.compared_pixels;
      pooled.mismatched_pixels += c.mismatched_pixels;
      if (e.max_px > pooled.max_edge_px) {
        pooled.max_edge_px = e.max_px;
        row.worst_edge_pixel = e.worst_pixel;
        row.worst_edge_output = i;
      }
      pooled.p99_edge_px = std::max(pooled.p99_edge_px, e.p99_px);
      row.edge_beyond_window_pixels += e.beyond_window;
      row.edge_differing_pixels += e.differing_pixels;
      row.edge_searched_pixels += e.searched_pixels;
      row.depth_tie_pixels += e.depth_ties;
      row.outside_display_pixels += e.outside_display;
      row.outside_display_max_px = std::max(row.outside_display_max_px, e.outside_display_max_px);
    }
    row.id_mismatch = pooled.compared_pixels
                          ? double(pooled.mismatched_pixels) / double(pooled.compared_pixels)
                          : 0.0;
    row.max_edge_px = pooled.max_edge_px;
    row.p99_edge_px = pooled.p99_edge_px;
    if (setting.method == "facets") facet_ids_[setting.label] = ids;
    if (!setting.same_ids_as.empty()) {
      const auto match = facet_ids_.find(setting.same_ids_as);
      if (match != facet_ids_.end()) {
        std::uint64_t differing = 0;
        for (std::size_t i = 0; i < ids.size(); ++i) {
          for (std::size_t p = 0; p < ids[i].size(); ++p) {
            differing += ids[i][p] != match->second[i][p];
          }
        }
        row.id_pixels_differing_from_facets = differing;
      }
    }
  }

  // The geometric error of the method's approximation, by the method's kind: facet error,
  // intermediate image texels, none (exact rays), else the reference edges.
  void measure_geometric_error(const BenchSetting& setting, BenchRow& row) {
    if (setting.method == "facets" || setting.method == "facets-gs" ||
        setting.method == "tessellated" || setting.method == "naive") {
      std::tie(row.geometric_max_px, row.geometric_rms_px) = facet_error_of(setting);
      row.geometric_source = "facet error";
    } else if (setting.method == "cubemap" || setting.method == "perspective") {
      // The texel error of the intermediate image, worst and RMS pooled over the outputs.
      const bool cube = setting.method == "cubemap";
      double max_px = 0, sum_sq = 0;
      for (std::size_t i = 0; i < scenario_.outputs.size(); ++i) {
        const Warp& warp = scenario_.outputs[i].warp;
        const int size = setting.settings.cube_face_size;
        const auto [m, rms] = cube ? cube_texel_error(warp, inverses_[i], size)
                                   : perspective_texel_error(warp, inverses_[i], size);
        max_px = std::max(max_px, m);
        sum_sq += rms * rms;
      }
      row.geometric_max_px = max_px;
      row.geometric_rms_px = std::sqrt(sum_sq / double(scenario_.outputs.size()));
      row.geometric_source = cube ? "cube texel" : "image texel";
    } else if (setting.method == "glc") {
      // Each pixel's own ray is cast at the triangles: no geometric approximation.
      row.geometric_source = "exact rays";
    } else {
      row.geometric_max_px = row.max_edge_px;
      row.geometric_rms_px = row.p99_edge_px;
      row.geometric_source = "reference edges";
    }
  }

  // Worst and RMS facet error over the outputs at `setting`'s layout: they depend only on the
  // outputs and the layout, so the facet methods at one layout share them.
  std::pair<double, double> facet_error_of(const BenchSetting& setting) {
    auto found = facet_errors_.find(setting.label);
    if (found != facet_errors_.end()) return found->second;
    double max_px = 0, sum_sq = 0;
    std::size_t n = 0;
    for (const OutputSpec& output : scenario_.outputs) {
      const FacetMesh mesh = build_facets(output.warp, setting.settings.facets);
      const FacetError error = evaluate_facet_error(output.warp, mesh);
      max_px = std::max(max_px, error.max_px);
      sum_sq += error.rms_px * error.rms_px * double(error.samples);
      n += error.samples;
    }
    const std::pair<double, double> result{max_px, n ? std::sqrt(sum_sq / double(n)) : 0.0};
    facet_errors_.emplace(setting.label, result);
    return result;
  }

  // The row's timings (medians over the timed frames, per pass from the GPU timer) and the last
  // frame's figures.
  void summarize_timing(Runner& runner) const {
    BenchRow& row = runner.row;
    row.frame_ms = median(runner.frame_ms);
    row.frame_ms_min = *std::min_element(runner.frame_ms.begin(), runner.frame_ms.end());
    row.frame_ms_max = *std::max_element(runner.frame_ms.begin(), runner.frame_ms.end());
    std::map<std::string, std::vector<double>> passes;
    std::vector<double> totals, shares;
    while (auto frame = runner.timer.poll(true)) {
      std::map<std::string, double> sums;
      double total = 0;
      for (const PassTime& pass : *frame) {
        sums[pass.pass] += pass.milliseconds;
        total += pass.milliseconds;
      }
      for (const auto& [pass, ms] : sums) passes[pass].push_back(ms);
      totals.push_back(total);
      if (sums.contains("pass1 coverage") && total > 0) {
        shares.push_back((sums["pass1 coverage"] + sums["pass2 replicate"]) / total);
      }
    }
    for (const auto& [pass, times] : passes) row.pass_ms[pass] = median(times);
    row.gpu_ms = median(totals);
    if (!shares.empty()) row.passes12_share_gpu = median(shares);
    if (!runner.reused_ms.empty() && row.frame_ms > 0) {
      row.pass3_only_ms = median(runner.reused_ms);
      row.passes12_share = std::max(0.0, 1.0 - *row.pass3_only_ms / row.frame_ms);
    }
    double ratio_sum = 0;
    for (const RenderStats& s : runner.stats) ratio_sum += s.replication_ratio();
    row.replication_ratio = ratio_sum / double(runner.stats.size());
    const RenderStats& last = runner.stats.back();
    row.facets = last.facets;
    row.triangles_in = last.triangles_in;
    row.triangles_visible = last.triangles_visible;
    row.replicas = last.replicas;
    row.dropped_triangles = last.dropped_triangles;
    row.seam_copies = last.seam_copies;
    row.gpu_buffer_bytes = last.gpu_buffer_bytes;
    say_(
        format("  %-11s %-12s %9.2f ms/frame (median of %d), GPU %8.2f ms, ratio %.3f, "
               "%.1f MiB buffers",
               row.method.c_str(), row.setting.c_str(), row.frame_ms, options_.frames, row.gpu_ms,
               row.replication_ratio, double(row.gpu_buffer_bytes) / (1024.0 * 1024.0)));
  }

  const BenchScenario& scenario_;
  const std::string scene_text_;
  LoadedScene& loaded_;
  const BenchOptions& options_;
  const Say& say_;
  const glm::dmat4 T0_;  // the first view: the accuracy frame's
  bool wrap_x_ = false;  // the first output wraps horizontally (compare_ids, edge_displacement)
  std::vector<WarpInverse> inverses_;
  std::vector<std::vector<std::uint32_t>> reference_;  // per output: the oracle's IDs at T0_
  std::vector<OutputTarget> targets_;
  std::vector<Runner> runners_;
  // The facets settings' IDs by label (BenchSetting::same_ids_as), and the facet errors by
  // layout label (facet_error_of).
  std::map<std::string, std::vector<std::vector<std::uint32_t>>> facet_ids_;
  std::map<std::string, std::pair<double, double>> facet_errors_;
};

}  // namespace

BenchReport run_bench(const BenchOptions& options, const std::string& renderer,
                      const std::function<void(const std::string&)>& progress) {
  const Say say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  const std::vector<BenchScenario> scenarios = make_bench_scenarios(options);
  BenchReport report;
  report.renderer = renderer;
  report.frames = options.frames;
  report.size_scale = options.size_scale;
  report.quick = options.quick;
  std::unique_ptr<LoadedScene> loaded;
  for (const BenchScenario& scenario : scenarios) {
    const std::string scene_text = scenario.scene.empty() ? options.scene : scenario.scene;
    load_scene_once(loaded, scene_text, scenario, options, say);
    say("scenario " + scenario.name + ": " + scenario.description);
    ScenarioBench bench(scenario, loaded->name, *loaded, options, say);
    for (const BenchSetting& setting :
         with_matched_tolerance(scenario, bench.matched_cube_max_px()))
      bench.prepare(setting);
    bench.time_frames();
    bench.add_rows(report.rows);
  }
  report.scale_fits = bench_scale_fits(report.rows);
  report.notes = bench_notes(report.rows, renderer);
  return report;
}

}  // namespace facet::driver
