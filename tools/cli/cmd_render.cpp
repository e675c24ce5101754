// facet render: renders a scene into every output of a display with one of the render methods,
// and reports the replication ratio and timings.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/driver/display_outputs.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/output_images.hpp"
#include "facet/driver/reference.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "facet/projection/statistics.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "frames_flag.hpp"
#include "option_flags.hpp"
#include "view_flags.hpp"

namespace facet::cli {
namespace {

using namespace facet::driver;

// Frame k shows the city camera path at k times this step (seconds): 30 frames per second. Other
// views turn 3 degrees a frame, on the spot or about the point looked at (FrameViews).
constexpr double kFrameStepS = 1.0 / 30.0;

struct RenderOptions {
  std::string display, scene = "builtin:city", method = "facets", size, out, reference_scene;
  LayoutFlags layout;
  ViewFlags view;
  std::optional<int> face_size;
  std::int64_t frames = 1;  // signed, so that a negative count is refused, not wrapped
  int msaa = 0;
  float anisotropy = kAutomaticAnisotropy;
  std::string coverage = "grid";
  std::string triangle_list = "auto";
  std::string material = "lit";
  DomeOrientationFlags orientation;
  bool ids = false, depth = false, reference = false, json = false, static_view = false;
};

// Per output, which pixels its display.json's blend map hides: α = 0 in every channel, where
// the projector shows black whatever it draws. Empty for an output without a blend map (and for
// built-in displays, which `render` draws unblended).
std::vector<std::vector<bool>> hidden_by_blend(
    const std::optional<projection_io::DisplayConfig>& config) {
  std::vector<std::vector<bool>> hidden;
  if (!config) return hidden;
  for (const auto& projector : config->projectors) {
    std::vector<bool>& mask = hidden.emplace_back();
    if (!projector.blend) continue;
    const projection_io::BlendMap alpha =
        projection_io::read_blend_map(config->resolve(*projector.blend).string(), projector.size);
    mask.assign(std::size_t(alpha.size.x) * alpha.size.y, false);
    for (int y = 0; y < alpha.size.y; ++y) {
      for (int x = 0; x < alpha.size.x; ++x) {
        bool dark = true;
        for (int c = 0; c < alpha.channels && dark; ++c) dark = alpha.at(x, y, c) <= 0.0f;
        mask[std::size_t(y) * alpha.size.x + x] = dark;
      }
    }
  }
  return hidden;
}

// The last frame's IDs against the Embree ray cast of the same view, pooled over the outputs:
// id_mismatch from compare_ids (ratio of pooled pixel counts), edge distances from the exact
// geometry (ReferenceRaycaster::edge_displacement; the worst output's). With --reference-scene the
// ray cast sees that scene and the rendered IDs are mapped to it through `source_ids`
// (load_scene: a depth image's triangles to the triangles they were rendered from).
// What the viewer sees is compared: where an output's blend map hides a pixel (`hidden`, per
// output; see hidden_by_blend) both IDs count as 0, nothing shown. Facets that straddle the edge
// of a warp's coverage are drawn whole, past it, and the blend map is what hides that part (as
// for the pieces of a split tile screen, each drawn over the whole window). The ID files written
// with --ids are the images as rendered and cast.
nlohmann::json compare_with_reference(const Scene& scene, const std::vector<OutputSpec>& outputs,
                                      const std::vector<OutputTarget>& targets,
                                      const std::vector<std::vector<bool>>& hidden,
                                      const glm::dmat4& T_eye_world,
                                      const std::filesystem::path& ids_folder,
                                      const std::string& stopped,
                                      const std::vector<std::uint32_t>* source_ids, double z_near) {
  const ReferenceRaycaster raycaster(scene);
  IdComparison pooled;
  EdgeDisplacement edges;
  std::size_t blend_hidden_pixels = 0;
  nlohmann::json per_output = nlohmann::json::array();
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    throw_if_interrupted(stopped);
    // A GLC camera's pixels cast its own rays: no warp inverse applies.
    const OutputSpec& output = outputs[i];
    std::optional<WarpInverse> inverse;
    if (!output.glc) inverse.emplace(output.warp);
    const bool wrap_x =
        output.glc ? output.glc->wraps_horizontally : output.warp.base.wraps_horizontally();
    const std::vector<std::uint32_t> reference =
        output.glc ? raycaster.ids(*output.glc, T_eye_world, z_near)
                   : raycaster.ids(*inverse, T_eye_world);
    if (!ids_folder.empty()) {
      write_ids_exr(ids_folder / (outputs[i].name + ".reference.ids.exr"), targets[i].size(),
                    reference);
    }
    std::vector<std::uint32_t> tested = targets[i].read_ids();
    if (source_ids) {
      for (std::uint32_t& id : tested) id = id < source_ids->size() ? (*source_ids)[id] : 0;
    }
    std::vector<std::uint32_t> shown = reference;
    std::size_t hidden_pixels = 0;
    if (i < hidden.size() && hidden[i].size() == tested.size()) {
      for (std::size_t k = 0; k < tested.size(); ++k) {
        if (!hidden[i][k]) continue;
        tested[k] = shown[k] = 0;
        ++hidden_pixels;
      }
    }
    const IdComparison c = compare_ids(shown, tested, targets[i].size(), {.wrap_x = wrap_x});
    const EdgeDisplacement e =
        inverse
            ? raycaster.edge_displacement(*inverse, T_eye_world, shown, tested, {.wrap_x = wrap_x})
            : raycaster.edge_displacement(*output.glc, T_eye_world, z_near, shown, tested,
                                          {.wrap_x = wrap_x});
    per_output.push_back({{"name", outputs[i].name},
                          {"id_mismatch", c.id_mismatch},
                          {"compared_pixels", c.compared_pixels},
                          {"mismatched_pixels", c.mismatched_pixels},
                          {"blend_hidden_pixels", hidden_pixels},
                          {"max_edge_px", e.max_px},
                          {"p99_edge_px", e.p99_px},
                          {"edge_beyond_window_pixels", e.beyond_window},
                          {"differing_pixels", e.differing_pixels},
                          {"edge_searched_pixels", e.searched_pixels},
                          {"depth_tie_pixels", e.depth_ties},
                          {"outside_display_pixels", e.outside_display},
                          {"outside_display_max_px", e.outside_display_max_px},
                          {"worst_edge_pixel", {e.worst_pixel.x, e.worst_pixel.y}}});
    pooled.compared_pixels += c.compared_pixels;
    pooled.mismatched_pixels += c.mismatched_pixels;
    blend_hidden_pixels += hidden_pixels;
    edges.differing_pixels += e.differing_pixels;
    edges.searched_pixels += e.searched_pixels;
    edges.measured_pixels += e.measured_pixels;
    edges.beyond_window += e.beyond_window;
    edges.depth_ties += e.depth_ties;
    edges.outside_display += e.outside_display;
    edges.outside_display_max_px = std::max(edges.outside_display_max_px, e.outside_display_max_px);
    edges.max_px = std::max(edges.max_px, e.max_px);
    edges.p99_px = std::max(edges.p99_px, e.p99_px);
  }
  const double mismatch = pooled.compared_pixels
                              ? double(pooled.mismatched_pixels) / double(pooled.compared_pixels)
                              : 0.0;
  return {{"id_mismatch", mismatch},
          {"compared_pixels", pooled.compared_pixels},
          {"mismatched_pixels", pooled.mismatched_pixels},
          {"blend_hidden_pixels", blend_hidden_pixels},
          {"max_edge_px", edges.max_px},
          {"p99_edge_px", edges.p99_px},
          {"differing_pixels", edges.differing_pixels},
          {"edge_searched_pixels", edges.searched_pixels},
          {"edge_beyond_window_pixels", edges.beyond_window},
          {"depth_tie_pixels", edges.depth_ties},
          {"outside_display_pixels", edges.outside_display},
          {"outside_display_max_px", edges.outside_display_max_px},
          {"edge_window_px", EdgeDisplacementOptions{}.window_px},
          {"outputs", per_output}};
}

// The rules of render's --out: a new path, an empty folder, or a folder of an earlier render
// (its <output>.png, .ids.exr, .depth.exr and .reference.ids.exr files and nothing else), which
// is replaced whole; never the current folder, a parent of it or of an input, or anything else.
OutputFolderRules render_out_rules(const RenderOptions& options) {
  namespace fs = std::filesystem;
  OutputFolderRules rules;
  rules.field = "--out";
  rules.expected =
      "a new path, an empty folder, or a folder of an earlier facet render (<output>.png, "
      ".ids.exr and .depth.exr files, nothing else)";
  rules.is_own_output = [](const fs::path& folder) {
    return holds_only_files_named(folder, [](const std::string& name) {
      return name.ends_with(".png") || name.ends_with(".ids.exr") || name.ends_with(".depth.exr");
    });
  };
  for (const std::string& input :
       {options.display, options.scene, options.material, options.reference_scene}) {
    std::error_code error;
    if (!input.empty() && fs::exists(input, error)) rules.inputs.emplace_back(input);
  }
  return rules;
}

void run(const RenderOptions& options) {
  const std::uint64_t frame_count = checked_frames(options.frames);
  // Before any work: an --out that may not be written is refused at once.
  const OutputFolderRules out_rules = render_out_rules(options);
  if (!options.out.empty()) check_output_folder(options.out, out_rules);
  if (options.msaa < 0) throw InputError("command line", "--msaa", "expected 0 or more samples");
  std::optional<glm::ivec2> size;
  if (!options.size.empty()) size = parse_size(options.size, "--size");
  const auto orientation = builtin_dome_orientation(options.orientation, options.display);
  LoadedDisplay loaded = load_display(options.display, size, /*allow_glc=*/true);
  std::vector<OutputSpec> outputs = std::move(loaded.outputs);
  // A GLC camera has no single centre of projection, which every other method's warp needs.
  check_render_method(options.method);
  const bool glc_display = !outputs.empty() && outputs.front().glc;
  if (glc_display && !is_glc_method(options.method)) {
    throw InputError("command line", "--method",
                     "expected glc or glc-2pass for the GLC camera " + options.display +
                         " (its rays share no centre, which method " + options.method + " needs)");
  }
  if (!glc_display && is_glc_method(options.method)) {
    throw InputError("command line", "--display",
                     "expected a GLC camera (FILE.glc.json) for --method " + options.method +
                         "; got " + options.display);
  }
  // Read with the display, before any GL work: a bad blend map is refused at once.
  const std::vector<std::vector<bool>> hidden =
      options.reference ? hidden_by_blend(loaded.config) : std::vector<std::vector<bool>>{};
  for (OutputSpec& output : outputs) {
    if (orientation) orient_warp(output.warp, *orientation);
  }
  // Checked before any GL work; made again once the context exists, which must outlive it.
  check_render_method(options.method);
  RenderSettings settings;
  settings.facets.layout = options.layout.layout();
  // As facet run: facets that miss the tolerance by a near miss render, with a warning.
  settings.facets.near_miss = kRunNearMiss;
  settings.facets.origin = {"command line", "--tolerance", {}};
  settings.facets.warn = [](const std::string& line) {
    std::cerr << "facet render: warning: " << line << "\n";
  };
  if (options.face_size) {
    if (*options.face_size < 1 || *options.face_size > 16384) {
      throw InputError("command line", "--face-size",
                       "expected a cube face size from 1 to 16384 pixels");
    }
    settings.cube_face_size = *options.face_size;
  }
  settings.msaa_samples = options.msaa;
  if (options.coverage == "walk") {
    settings.coverage = FacetCoverage::walk;
  } else if (options.coverage != "grid") {
    throw InputError("command line", "--coverage",
                     "expected grid or walk; got '" + options.coverage + "'");
  }
  if (options.triangle_list == "cpu") {
    settings.triangle_list = TriangleListBuild::cpu;
  } else if (options.triangle_list == "gpu") {
    settings.triangle_list = TriangleListBuild::gpu;
  } else if (options.triangle_list != "auto") {
    throw InputError("command line", "--triangle-list",
                     "expected auto, cpu or gpu; got '" + options.triangle_list + "'");
  }
  // GL caps the level at GL_MAX_TEXTURE_MAX_ANISOTROPY, 16 on every GPU that has it: a larger
  // level (or infinity) would be clamped without a word.
  if (options.anisotropy != kAutomaticAnisotropy &&
      !(options.anisotropy >= 1.0f && options.anisotropy <= 16.0f)) {
    throw InputError("command line", "--anisotropy",
                     "expected 0 (automatic) or a level from 1 to 16, got " +
                         std::to_string(options.anisotropy));
  }
  settings.material = load_material_shader(options.material);
  const ViewRequest view_request = options.view.request();  // malformed flags before the scene
  const SceneName scene_name = parse_scene_name(options.scene);
  // The reference scene's name is checked with the scene's, and refused under its own flag.
  auto as_reference_scene = [&](auto&& step) {
    try {
      return step();
    } catch (const InputError& error) {
      if (error.option() != "scene" && error.option() != "step") throw;
      throw error.with_option_shown_as("--reference-scene");
    }
  };
  std::optional<SceneName> reference_scene_name;
  if (!options.reference_scene.empty()) {
    if (!options.reference)
      throw InputError("command line", "--reference-scene", "expected --reference as well");
    reference_scene_name =
        as_reference_scene([&] { return parse_scene_name(options.reference_scene); });
  }
  std::vector<std::uint32_t> source_ids;
  Scene scene = load_scene(scene_name, &source_ids);
  std::optional<Scene> reference_scene;
  if (reference_scene_name) {
    reference_scene = as_reference_scene([&] { return load_scene(*reference_scene_name); });
  }
  const SceneView view = choose_view(scene, view_request, scene_name.builtin_city(), "render");
  // The view moves every frame (unless --static-view): along the city's camera path, or turning
  // on the spot or about the point looked at (choose_scene_view).
  const FrameViews views(view, kFrameStepS, options.static_view);
  // Depth images with @lod take their levels as seen from each frame's eye (the view comes from
  // the scene, so the first frame's scene is built twice); the scene is rebuilt, its buffers
  // replaced and the method's scene state with them, on the frames where the levels change.
  std::optional<ViewDependentScene> lod_scene;
  if (uses_depth_lod(scene_name)) {
    lod_scene.emplace(scene_name, glm::dvec3(views.T_world_eye(0)[3]));
    scene = Scene{};
  }
  const Scene& drawn = lod_scene ? lod_scene->scene() : scene;
  const std::vector<std::uint32_t>& drawn_source_ids =
      lod_scene ? lod_scene->source_ids() : source_ids;

  auto context = create_headless_context();
  check_material_shader(settings.material);  // its own compile errors name its file (exit 2)
  auto method = make_render_method(options.method);
  GpuScene gpu_scene = upload_scene(drawn, options.anisotropy);
  method->prepare(drawn, gpu_scene, outputs, settings);
  std::vector<OutputTarget> targets;
  for (const OutputSpec& output : outputs) {
    targets.push_back(OutputTarget::create(output.warp.output_size, settings.msaa_samples));
  }

  GpuTimer timer;
  std::vector<double> frame_ms;
  std::vector<RenderStats> stats;
  // With @lod: per frame the level choice, the rebuild and the replacement of the GPU scene and
  // the method's scene state, wall clock (the choice and the rebuild alone: lod_scene->stats()).
  std::vector<double> lod_update_ms;
  glm::dmat4 T_eye_world(1.0);
  // From here on SIGINT and SIGTERM stop the command cleanly (Interrupted, exit 128 + signal).
  watch_interrupts();
  const std::string nothing_written =
      options.out.empty() ? "nothing printed" : "nothing written to " + options.out;
  for (std::uint64_t k = 0; k < frame_count; ++k) {
    throw_if_interrupted("stopped after " + std::to_string(k) + " of " +
                         std::to_string(frame_count) + " frames; " + nothing_written);
    T_eye_world = views.T_eye_world(int(k));
    if (lod_scene) {
      const auto update_start = std::chrono::steady_clock::now();
      if (lod_scene->update(glm::dvec3(views.T_world_eye(int(k))[3]))) {
        replace_geometry(gpu_scene, drawn);
        method->replace_scene(drawn, gpu_scene, outputs, settings);
      }
      glFinish();
      lod_update_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - update_start)
              .count());
    }
    const auto start = std::chrono::steady_clock::now();
    stats.push_back(method->render(T_eye_world, targets, &timer));
    glFinish();
    frame_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }
  std::map<std::string, std::vector<double>> pass_times;
  while (auto frame = timer.poll(true)) {
    std::map<std::string, double> sums;
    for (const PassTime& pass : *frame) sums[pass.pass] += pass.milliseconds;
    for (const auto& [pass, ms] : sums) pass_times[pass].push_back(ms);
  }

  const std::string stopped =
      "stopped after the " + std::to_string(frame_count) + " frames; " + nothing_written;
  // The reference (and with --ids its ID images) before the outputs, so that every file of --out
  // is written as one set.
  std::optional<nlohmann::json> reference;
  auto compare = [&](const std::filesystem::path& ids_folder) {
    if (options.reference)
      reference =
          compare_with_reference(reference_scene ? *reference_scene : drawn, outputs, targets,
                                 hidden, T_eye_world, options.ids ? ids_folder : "", stopped,
                                 reference_scene ? &drawn_source_ids : nullptr, settings.z_near);
  };
  if (options.out.empty()) {
    compare("");
  } else {
    write_folder_atomically(
        options.out,
        [&](const std::filesystem::path& folder) {
          compare(folder);
          for (std::size_t i = 0; i < outputs.size(); ++i) {
            throw_if_interrupted(stopped);
            const glm::ivec2 s = targets[i].size();
            const auto colour = targets[i].read_colour_rgba8();
            write_png_rgba8(folder / (outputs[i].name + ".png"), s, colour);
            if (options.ids) {
              const auto ids = targets[i].read_ids();
              write_ids_exr(folder / (outputs[i].name + ".ids.exr"), s, ids);
            }
            if (options.depth) {
              const auto depth = targets[i].read_depth();
              write_depth_exr(folder / (outputs[i].name + ".depth.exr"), s, depth);
            }
          }
          throw_if_interrupted(stopped);
        },
        out_rules);
  }
  throw_if_interrupted(stopped);

  const RenderStats& last = stats.back();
  double ratio_sum = 0;
  int reused = 0;
  for (const RenderStats& s : stats) {
    ratio_sum += s.replication_ratio();
    reused += s.reused_replication;
  }
  nlohmann::json pass_ms = nlohmann::json::object();
  for (const auto& [pass, times] : pass_times) pass_ms[pass] = median(times);
  nlohmann::json names = nlohmann::json::array();
  for (const OutputSpec& output : outputs) names.push_back(output.name);
  nlohmann::json report = {{"display", options.display},
                           {"scene", options.scene},
                           {"method", method->name()},
                           {"outputs", names},
                           {"renderer", context->info().renderer},
                           {"frames", frame_count},
                           {"facets", last.facets},
                           {"triangles_scene", drawn.triangle_count()},
                           {"triangles_in", last.triangles_in},
                           {"triangles_visible", last.triangles_visible},
                           {"triangles_sole_piece", last.triangles_sole_piece},
                           {"triangle_list_on_gpu", last.triangle_list_on_gpu},
                           {"replicas", last.replicas},
                           {"replication_ratio", last.replication_ratio()},
                           {"replication_ratio_mean", ratio_sum / double(frame_count)},
                           {"reused_frames", reused},
                           {"reused_replication", last.reused_replication},
                           {"static_view", options.static_view},
                           {"gpu_buffer_bytes", last.gpu_buffer_bytes},
                           {"dropped_triangles", last.dropped_triangles},
                           {"seam_copies", last.seam_copies},
                           {"frame_ms", median(frame_ms)},
                           {"pass_ms", pass_ms},
                           {"texture_anisotropy", gpu_scene.max_anisotropy}};
  if (glc_display) {
    std::size_t pieces = 0;
    for (const OutputSpec& output : outputs) pieces += output.glc->pieces.size();
    report["glc_pieces"] = pieces;  // GLCs of the camera (strips, reflector triangles)
  }
  if (lod_scene) {
    const ViewDependentScene::Summary lod = lod_scene->summary();
    report["depth_lod"] = {
        {"rebuilds", lod.rebuilds},           {"update_ms", median(lod_update_ms)},
        {"choose_ms", lod.choose_ms},         {"rebuild_ms", lod.build_ms},
        {"blocks_remade", lod.blocks_remade}, {"triangles_median", lod.triangles_median},
        {"triangles_min", lod.triangles_min}, {"triangles_max", lod.triangles_max}};
  }
  if (reference) report["reference"] = *reference;
  if (options.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    std::printf(
        "%s, %s, %s: %llu facets, %llu triangles in, %llu replicas, ratio %.3f, "
        "%.2f ms/frame (median of %d)\n",
        options.display.c_str(), options.scene.c_str(), options.method.c_str(),
        static_cast<unsigned long long>(last.facets),
        static_cast<unsigned long long>(last.triangles_in),
        static_cast<unsigned long long>(last.replicas), last.replication_ratio(), median(frame_ms),
        static_cast<int>(frame_count));
    for (const auto& [pass, times] : pass_times) {
      std::printf("  %-16s %8.3f ms (GPU, median)\n", pass.c_str(), median(times));
    }
    if (options.reference) {
      const nlohmann::json& r = report["reference"];
      std::printf(
          "  reference: id_mismatch %.6f, max_edge_px %.3f, p99_edge_px %.3f, %zu of %zu "
          "differing pixels beyond %.0f px\n",
          r["id_mismatch"].get<double>(), r["max_edge_px"].get<double>(),
          r["p99_edge_px"].get<double>(), r["edge_beyond_window_pixels"].get<std::size_t>(),
          r["differing_pixels"].get<std::size_t>(), r["edge_window_px"].get<double>());
    }
  }
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"render",
                               {{"display", "--display"},
                                {"size", "--size"},
                                {"method", "--method"},
                                {"frames", "--frames"},
                                {"out", "--out"}},
                               ViewFlags::option_flags()};

const Registration registration{
    30, [](CLI::App& app) {
      auto* command =
          app.add_subcommand("render", "Render a scene into a display's outputs with one method");
      auto options = std::make_shared<RenderOptions>();
      command
          ->add_option("display,--display", options->display,
                       "builtin:cylinder360 | builtin:dome180 | FILE.warp.exr | display.json | "
                       "FILE.glc.json (a GLC camera, --method glc)")
          ->required();
      command->add_option("--scene", options->scene, kSceneNameSyntax)->capture_default_str();
      command->add_flag("--static-view", options->static_view,
                        "Keep frame 1's view on every frame (the facet methods then reuse "
                        "passes 1 and 2); by default the view moves every frame");
      command
          ->add_option("--method", options->method,
                       "facets | facets-gs | tessellated | cubemap | perspective | naive | vertex "
                       "| glc")
          ->capture_default_str();
      command
          ->add_option("--material", options->material,
                       "lit | solid-wireframe | pen-and-ink | procedural | FILE.frag (a GLSL "
                       "shade() against shaders/scene/material_interface.frag)")
          ->capture_default_str();
      options->layout.add_to(*command);
      options->view.add_to(*command);
      command->add_option("--face-size", options->face_size,
                          "Cube-map face size, or the perspective image's longer side, in pixels");
      command->add_option("--size", options->size, "Output size WxH (built-in displays)");
      command
          ->add_option("--frames", options->frames,
                       "Frames to render, 1 to 1000000 (median timings)")
          ->capture_default_str();
      command->add_option("--msaa", options->msaa, "Colour samples per pixel (0: none)");
      options->orientation.add_to(*command);
      command->add_option("--out", options->out, "Folder for <output>.png (and IDs, depth)");
      command->add_flag("--ids", options->ids, "Also write <output>.ids.exr (needs --out)");
      command->add_flag("--depth", options->depth, "Also write <output>.depth.exr (needs --out)");
      command->add_flag(
          "--reference", options->reference,
          "Compare the IDs with the CPU ray-cast reference (with --ids: also write it)");
      command->add_option("--reference-scene", options->reference_scene,
                          "With --reference: cast the rays into this scene (the polygon model a "
                          "depth:FILE.exr was rendered from), IDs mapped through its id channel");
      command->add_option("--anisotropy", options->anisotropy,
                          "Texture anisotropy level (0: automatic, 8 on GPUs, off on llvmpipe)");
      command->add_option("--coverage", options->coverage,
                          "Facet methods' pass 1: grid (default) or walk (the hierarchy "
                          "reference)");
      command->add_option("--triangle-list", options->triangle_list,
                          "Facet pipelines' object culling and triangle list: auto (default: "
                          "the GPU on a hardware renderer, the CPU on a software one), cpu or gpu");
      command->add_flag("--json", options->json, "Print one JSON object");
      command->callback([options] { run(*options); });
    }};

}  // namespace
}  // namespace facet::cli
