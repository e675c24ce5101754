// facet run: an immersive session on a display, in windows on its projectors or headless.
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cluster_flags.hpp"
#include "command.hpp"
#include "console_log.hpp"
#include "display_flags.hpp"
#include "facet/driver/cluster.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/monitors.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/driver/session.hpp"
#include "facet/driver/session_runner.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "facet/projection/progress.hpp"
#include "facet/projection/test_pattern.hpp"
#include "facet/projection/warp.hpp"
#include "frames_flag.hpp"
#include "option_flags.hpp"
#include "view_flags.hpp"

namespace facet::cli {
namespace {

struct RunOptions {
  std::string display = "builtin:dome180";
  std::string scene = "builtin:city";
  std::string size;
  std::string method;
  std::string material = "lit";
  std::optional<double> tolerance;
  std::optional<double> scale;
  DomeOrientationFlags orientation;  // builtin:dome180 only
  bool headless = false, windowed = false;
  std::optional<std::int64_t> frames;  // signed, so that a negative count is refused, not wrapped
  std::string out = "out/session";
  std::int64_t save_every = 1;  // signed, as frames
  std::string pattern;          // a test pattern instead of the scene; empty: the scene
  bool span = false, overlay = false, no_path = false;
  std::string report;
  bool monitors = false;
  ViewFlags view;
  driver::ClusterRequest cluster;  // --node, --join-timeout, --rate
};

// The command-line settings that change a node's pictures, for the cluster's content digest.
std::string picture_settings(const RunOptions& options, const driver::SessionDisplay& display) {
  std::ostringstream text;
  text.precision(17);
  text << "method=" << display.method << ";scale=" << options.scale.value_or(1.0)
       << ";tolerance=" << options.tolerance.value_or(0) << ";size=" << options.size;
  return text.str();
}

bool have_display_server() {
  const char* x_display = std::getenv("DISPLAY");
  const char* wayland_display = std::getenv("WAYLAND_DISPLAY");
  return (x_display && *x_display) || (wayland_display && *wayland_display);
}

// The connected monitors, or an InputError naming `flag` when no display server can be reached:
// windows and monitors need one, and for windows the way out is --headless, not a bug report.
std::vector<driver::MonitorInfo> monitors_of_display_server(const std::string& flag) {
  const std::string hint =
      flag == "--windowed" ? ": use --headless to render frames to files" : std::string();
  if (!have_display_server())
    throw InputError("command line", flag,
                     "a display server (X11) for facet run " + flag +
                         "; none was found (DISPLAY is not set)" + hint);
  try {
    return driver::list_monitors();
  } catch (const driver::GlContextError& e) {
    const char* x_display = std::getenv("DISPLAY");
    throw InputError("command line", flag,
                     "a display server (X11) for facet run " + flag + "; none could be reached" +
                         (x_display && *x_display ? std::string(" at DISPLAY=") + x_display : "") +
                         " (" + e.what() + ")" + hint);
  }
}

void run(const RunOptions& options) {
  if (options.monitors) {
    // Names and geometry to put in display.json outputs.
    for (const driver::MonitorInfo& monitor : monitors_of_display_server("--monitors"))
      std::cout << monitor.name << " " << monitor.size.x << "x" << monitor.size.y << "+"
                << monitor.position.x << "+" << monitor.position.y << " " << monitor.refresh_hz
                << " Hz\n";
    return;
  }
  if (options.headless && options.windowed)
    throw InputError("command line", "--headless", "either --headless or --windowed, not both");
  std::optional<std::uint64_t> frames;
  if (options.frames) frames = checked_frames(*options.frames);
  std::optional<TestPattern> pattern;
  if (!options.pattern.empty())
    pattern = test_pattern_from_string(options.pattern, "command line", "--pattern");
  if (options.save_every < 1 || options.save_every > std::int64_t(driver::kMaxFrames))
    throw InputError("command line", "--save-every",
                     "a frame interval from 1 to " + std::to_string(driver::kMaxFrames));
  std::optional<glm::ivec2> size;
  if (!options.size.empty()) size = parse_size(options.size, "--size");
  const auto orientation = builtin_dome_orientation(options.orientation, options.display);
  // A cluster node renders its own projectors only.
  driver::ClusterRequest cluster_request = options.cluster;
  cluster_request.frames_given = options.frames.has_value();
  auto [display, cluster_share] =
      driver::load_node_display(options.display, size, options.scale, cluster_request);
  for (auto& output : display.outputs) {
    if (orientation) orient_warp(output.spec.warp, *orientation);
  }
  if (!options.method.empty()) display.method = options.method;
  if (options.tolerance) {
    if (!(*options.tolerance > 0 && *options.tolerance <= kMaxImageSide))
      throw InputError("command line", "--tolerance", "a number of output pixels in (0, 16384]");
    display.settings.facets.layout = FacetTolerance{*options.tolerance};
    display.settings.facets.origin.source = "command line";
    display.settings.facets.origin.field = "--tolerance";
  }
  // A default tolerance is named by its library option: shown as its flag in the warnings too.
  if (FacetToleranceOrigin& origin = display.settings.facets.origin; origin.field.is_option())
    origin.field = flag_of_option("run", origin.field.name());
  display.settings.facets.warn = [](const std::string& line) {
    std::cerr << "facet run: warning: " << line << "\n";
  };
  display.settings.material = driver::load_material_shader(options.material);
  // Check the method name before any scene work; one from display.json is reported there.
  try {
    driver::check_render_method(display.method);
  } catch (const InputError& error) {
    if (!options.method.empty()) throw;
    throw InputError(options.display, "render.method", error.expected());
  }
  const bool headless = options.headless || (!options.windowed && !have_display_server());
  // Before the scene, so that a missing display server is reported at once.
  if (headless && !options.report.empty())
    throw InputError("command line", "--report",
                     "a windowed run: the report is of window placement and shown pixels");
  if (!headless) monitors_of_display_server("--windowed");
  const driver::ViewRequest view_request = options.view.request();
  const driver::SceneName scene_name = driver::parse_scene_name(options.scene);
  if (headless) {
    // --out before the scene, the facets and any GL work.
    driver::HeadlessRunOptions out_check;
    out_check.out_dir = options.out;
    if (!options.display.starts_with("builtin:")) out_check.inputs.push_back(options.display);
    if (scene_name.kind == driver::SceneName::Kind::file)
      out_check.inputs.push_back(scene_name.file);
    driver::check_headless_out(out_check, "'facet run'");
  }
  driver::Scene scene = driver::load_scene(scene_name);  // moved into the headless Session
  const driver::CameraPath path =
      driver::camera_path(choose_view(scene, view_request, scene_name.builtin_city(), "run"));

  // A cluster node joins its cluster before it renders: a wrong address or an address in use is
  // found before any GL work.
  std::unique_ptr<driver::FrameSync> sync;
  if (cluster_share) {
    sync = driver::join_cluster(
        *cluster_share, options.display, cluster_request,
        driver::content_digest(cluster_share->config, options.display, scene_name.text,
                               scene_name.kind == driver::SceneName::Kind::file
                                   ? std::optional<std::filesystem::path>(scene_name.file)
                                   : std::nullopt,
                               picture_settings(options, display)),
        console_log("facet run: "));
  }

  // From here on SIGINT and SIGTERM stop the run cleanly (Interrupted, exit 128 + signal).
  watch_interrupts();
  if (!headless) {
    driver::WindowRunOptions window_options;
    window_options.frames = frames;
    window_options.span = options.span;
    window_options.overlay = options.overlay;
    window_options.play_path = !options.no_path;
    window_options.pattern = pattern;
    if (!options.report.empty()) window_options.report = options.report;
    window_options.sync = sync.get();
    window_options.log = console_log("facet run: ");
    if (driver::uses_depth_lod(scene_name)) window_options.view_dependent_scene = scene_name;
    driver::run_windowed_session(display, scene, path, window_options);
    return;
  }
  if (!options.headless)
    std::cerr << "facet run: no display server (DISPLAY is not set): running headless\n";
  auto context = driver::create_headless_context();
  driver::Session session(display, std::move(scene));
  // Depth images with @lod take their levels as seen from every frame's eye.
  if (driver::uses_depth_lod(scene_name))
    session.set_view_dependent_scene(
        std::make_unique<driver::ViewDependentScene>(scene_name, glm::dvec3(path(0.0)[3])));
  session.set_pattern(pattern);
  driver::HeadlessRunOptions headless_options;
  headless_options.frames = frames.value_or(10);
  headless_options.out_dir = options.out;
  headless_options.save_every = std::uint64_t(options.save_every);
  headless_options.sync = sync.get();
  // An earlier run's folder may be replaced, but not with the files this run reads.
  if (!options.display.starts_with("builtin:")) headless_options.inputs.push_back(options.display);
  if (scene_name.kind == driver::SceneName::Kind::file)
    headless_options.inputs.push_back(scene_name.file);
  // A secondary runs until the master ends the run: no count to show progress against.
  if (cluster_share && !cluster_share->master) headless_options.frames = driver::kMaxFrames;
  facet::TerminalProgress progress(stderr, "facet run");
  if (!cluster_share || cluster_share->master) headless_options.progress = progress.sink();
  const driver::HeadlessRunResult result =
      driver::run_headless_session(session, path, headless_options);
  progress.finish();
  std::cout << "facet run: " << result.frames << " frames of " << display.outputs.size()
            << " output(s) (" << context->info().renderer << ", method " << display.method
            << ") rendered; " << result.images_written << " images written to " << options.out
            << "/<output>/<frame>.png; statistics in " << options.out << "/stats.jsonl\n";
  std::cout << "facet run: last frame " << result.last.cpu_ms << " ms, replication ratio "
            << result.last.replication_ratio() << "; resident set " << result.rss_first_kib / 1024
            << " MiB after the first frame, at most " << result.rss_peak_kib / 1024 << " MiB\n";
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"run",
                               {{"display", "--display"},
                                {"size", "--size"},
                                {"factor", "--scale"},
                                {"method", "--method"},
                                {"frames", "--frames"},
                                {"save_every", "--save-every"},
                                {"out", "--out"},
                                {"node", "--node"},
                                {"join_timeout_s", "--join-timeout"},
                                {"rate_hz", "--rate"},
                                {"tolerance_px", "--tolerance"}},
                               ViewFlags::option_flags()};

const Registration registration{
    40, [](CLI::App& app) {
      auto options = std::make_shared<RunOptions>();
      auto* command = app.add_subcommand(
          "run",
          "Run an immersive session: a window per projector (or one spanning window), or "
          "headless frames to files when there is no display server");
      command->add_option("display,--display", options->display,
                          "builtin:dome180 (default), builtin:cylinder360, a .warp.exr or a "
                          "display.json");
      command->add_option("--scene", options->scene, driver::kSceneNameSyntax)
          ->capture_default_str();
      command->add_option("--size", options->size, "Output size WxH of a built-in display");
      options->view.add_to(*command);
      command->add_option(
          "--method", options->method,
          "facets, facets-gs, tessellated, naive, cubemap, perspective or vertex (default: the "
          "display's)");
      command->add_option("--tolerance", options->tolerance, "Facet tolerance in output pixels");
      command
          ->add_option("--material", options->material,
                       "lit | solid-wireframe | pen-and-ink | procedural | FILE.frag (GLSL)")
          ->capture_default_str();
      command->add_option("--scale", options->scale,
                          "Preview at this fraction of every output's resolution (0, 1]");
      options->orientation.add_to(*command);
      command->add_flag("--headless", options->headless, "Render through EGL to --out");
      command->add_flag("--windowed", options->windowed,
                        "Open windows (the default when DISPLAY is set; needs a display server)");
      command->add_option("--frames", options->frames,
                          "Frames to render, 1 to 1000000 (headless default 10; windowed: until "
                          "closed)");
      command->add_option("--out", options->out,
                          "Headless: folder for <output>/<frame>.png and stats.jsonl");
      command->add_option("--pattern", options->pattern,
                          "Show a test pattern instead of the scene: grid, latlong, "
                          "projector-ids, white, black or checker (windowed: T steps through "
                          "them)");
      command->add_option("--save-every", options->save_every,
                          "Headless: write the images of every N-th frame and of the last "
                          "(default 1: every frame); stats.jsonl always has every frame");
      command->add_flag("--span", options->span, "One borderless window spanning every output");
      command->add_flag("--overlay", options->overlay, "Start with the overlay shown (key O)");
      command->add_flag("--no-path", options->no_path, "Start still instead of on the path");
      command->add_option("--report", options->report,
                          "Windowed: write window placement and shown-pixel checks to this JSON");
      add_cluster_flags(*command, options->cluster, "Run");
      command->add_flag("--monitors", options->monitors,
                        "List the connected monitors (name, size+x+y, refresh) and exit");
      command->callback([options] { run(*options); });
    }};

}  // namespace
}  // namespace facet::cli
