// facet play: a dome master, panorama or cube map (still or video) on a display, through its
// exact warp and blend; windows per projector, or headless frames to files.
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "cluster_flags.hpp"
#include "command.hpp"
#include "console_log.hpp"
#include "display_flags.hpp"
#include "facet/driver/cluster.hpp"
#include "facet/driver/content_media.hpp"
#include "facet/driver/content_player.hpp"
#include "facet/driver/direction_cache.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/session.hpp"
#include "facet/driver/session_runner.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/content_projection.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "facet/projection/progress.hpp"
#include "frames_flag.hpp"
#include "option_flags.hpp"

namespace facet::cli {
namespace {

// A cache folder given with --direction-cache must be one facet can use: made now when missing,
// then probed with a file. The default cache, which the user did not name, is skipped quietly
// when it cannot be used.
std::filesystem::path usable_cache_folder(const std::string& folder) {
  namespace fs = std::filesystem;
  const auto refuse = [&](const std::string& why) {
    throw InputError("command line", "--direction-cache",
                     "a folder facet may create and write files in; '" + folder + "' " + why);
  };
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) refuse("cannot be made (" + error.message() + ")");
  if (!fs::is_directory(folder, error)) refuse("is not a folder");
  const fs::path probe = fs::path(folder) / (".facet-probe-" + std::to_string(::getpid()));
  if (!std::ofstream(probe)) refuse("takes no new file");
  fs::remove(probe, error);
  return folder;
}

struct PlayOptions {
  std::string file;
  std::string display = "builtin:dome180";
  std::string size;
  std::optional<double> scale;
  std::string format;  // empty: from the aspect ratio
  std::optional<double> fov;
  DomeOrientationFlags orientation;
  bool headless = false, windowed = false, span = false, loop = false;
  std::optional<std::int64_t> frames;
  std::int64_t start_frame = 0;
  std::string out = "out/play";
  std::string stats;               // windowed: the statistics file
  driver::ClusterRequest cluster;  // --node, --join-timeout, --rate
  std::string direction_cache;     // empty: driver::default_direction_cache()
  bool no_direction_cache = false;
  std::optional<std::int64_t> direction_cache_budget_mib;  // empty: the library's default
};

// The most the direction cache may keep: 1 TiB, far beyond any display's lookups (dome4's four
// outputs take 37.7 MB), so that a typo's 10^12 MiB is refused rather than meaning "never trim".
constexpr std::int64_t kMaxDirectionCacheBudgetMib = std::int64_t(1) << 20;

// What changes a node's pictures besides the display, for the cluster's content digest: the
// content file by name and size (not its bytes: a show's video may be gigabytes) and the flags.
std::string picture_settings(const PlayOptions& options) {
  std::ostringstream text;
  text.precision(17);
  std::error_code error;
  const auto bytes = std::filesystem::file_size(options.file, error);
  text << "play=" << std::filesystem::path(options.file).filename().string()
       << ";bytes=" << (error ? 0 : bytes) << ";format=" << options.format
       << ";fov=" << options.fov.value_or(180) << ";tilt=" << options.orientation.tilt
       << ";orientation=" << options.orientation.orientation << ";loop=" << options.loop
       << ";start=" << options.start_frame << ";scale=" << options.scale.value_or(1.0)
       << ";size=" << options.size;
  return text.str();
}

bool have_display_server() {
  const char* x_display = std::getenv("DISPLAY");
  const char* wayland_display = std::getenv("WAYLAND_DISPLAY");
  return (x_display && *x_display) || (wayland_display && *wayland_display);
}

void play(const PlayOptions& options) {
  if (options.headless && options.windowed)
    throw InputError("command line", "--headless", "either --headless or --windowed, not both");
  std::optional<std::uint64_t> frames;
  if (options.frames) frames = checked_frames(*options.frames);
  std::optional<glm::ivec2> size;
  if (!options.size.empty()) size = parse_size(options.size, "--size");
  std::optional<ContentFormat> format;
  if (!options.format.empty())
    format = content_format_from_string(options.format, "command line", "--format");
  const DomeOrientation orientation = options.orientation.value();
  if (options.fov && format && *format != ContentFormat::fisheye)
    throw InputError("command line", "--fov", "a field of view for --format fisheye only");
  if (const auto& mib = options.direction_cache_budget_mib) {
    if (options.no_direction_cache)
      throw InputError("command line", "--direction-cache-budget",
                       "a budget for a direction cache, not with --no-direction-cache");
    if (*mib < 1 || *mib > kMaxDirectionCacheBudgetMib)
      throw InputError("command line", "--direction-cache-budget",
                       "a number of MiB from 1 to " + std::to_string(kMaxDirectionCacheBudgetMib) +
                           " (1 TiB), got " + std::to_string(*mib));
  }

  // A cluster node shows its own projectors only.
  driver::ClusterRequest cluster_request = options.cluster;
  cluster_request.frames_given = options.frames.has_value();
  auto [display, cluster_share] =
      driver::load_node_display(options.display, size, options.scale, cluster_request);

  driver::PlaybackOptions playback;
  if (options.no_direction_cache && !options.direction_cache.empty())
    throw InputError("command line", "--no-direction-cache",
                     "either --direction-cache DIR or --no-direction-cache, not both");
  if (!options.no_direction_cache) {
    playback.resample.direction_cache = options.direction_cache.empty()
                                            ? driver::default_direction_cache()
                                            : usable_cache_folder(options.direction_cache);
  }
  if (options.direction_cache_budget_mib)
    playback.resample.direction_cache_budget = std::uint64_t(*options.direction_cache_budget_mib)
                                               << 20;
  // The direction lookups (the warp inverse at every output pixel, or the cache read) on a
  // thread of their own while FFmpeg opens the file and the GL starts. An error before the
  // player takes them (a content file that cannot be played) stops them on its way out.
  driver::PendingLookups lookups = driver::start_content_lookups(display, playback.resample);

  auto media = driver::ContentMedia::open(options.file);
  const ContentFormat chosen = driver::check_content_format(media->size(), format, options.file);
  switch (chosen) {
    case ContentFormat::fisheye:
      playback.projection = fisheye_content(options.fov.value_or(180), orientation);
      break;
    case ContentFormat::equirect:
      playback.projection = equirect_content(orientation);
      break;
    default:
      playback.projection = cubemap_content(orientation);
      break;
  }
  playback.projection.validate("command line");
  playback.loop = options.loop;
  playback.start_frame = options.start_frame;
  if (options.start_frame < 0 || options.start_frame >= media->frame_count())
    throw InputError("command line", "--start-frame",
                     "a frame from 0 to " + std::to_string(media->frame_count() - 1) + " of " +
                         options.file + "; got " + std::to_string(options.start_frame));
  std::cout << "facet play: " << options.file << ": " << media->size().x << "x" << media->size().y
            << " " << to_string(chosen)
            << (media->is_video() ? ", video at " + std::to_string(media->fps()) + " fps, " +
                                        std::to_string(media->frame_count()) + " frames"
                                  : std::string(", still image"))
            << "\n";

  const bool headless = options.headless || (!options.windowed && !have_display_server());
  if (headless && !options.stats.empty())
    throw InputError("command line", "--stats",
                     "windows: headless runs write stats.jsonl into --out");
  if (!options.stats.empty()) refuse_output_over_inputs(options.stats, "--stats", {options.file});
  if (headless) {
    // --out before any GL work or a cluster's join.
    driver::HeadlessRunOptions out_check;
    out_check.out_dir = options.out;
    out_check.inputs = {options.file};
    if (!options.display.starts_with("builtin:")) out_check.inputs.push_back(options.display);
    driver::check_headless_out(out_check, "'facet play' or 'facet run'");
  }
  // A cluster node joins its cluster before any GL work.
  std::unique_ptr<driver::FrameSync> sync;
  if (cluster_share) {
    sync =
        driver::join_cluster(*cluster_share, options.display, cluster_request,
                             driver::content_digest(cluster_share->config, options.display, "play",
                                                    std::nullopt, picture_settings(options)),
                             console_log("facet play: "));
  }

  watch_interrupts();
  if (!headless) {
    if (!have_display_server())
      throw InputError("command line", "--windowed",
                       "a display server (X11) for windows; none was found (DISPLAY is not set): "
                       "use --headless to render frames to files");
    driver::WindowPlayOptions window_options;
    window_options.frames = frames;
    window_options.span = options.span;
    if (!options.stats.empty()) window_options.stats = options.stats;
    window_options.sync = sync.get();
    window_options.log = console_log("facet play: ");
    driver::run_windowed_play(display, std::move(media), playback, window_options,
                              std::move(lookups));
    return;
  }
  if (!options.headless)
    std::cerr << "facet play: no display server (DISPLAY is not set): playing headless\n";
  auto context = driver::create_headless_context();
  driver::ContentPlayer player(std::move(display), std::move(media), playback, std::move(lookups));
  driver::HeadlessRunOptions headless_options;
  headless_options.frames = frames.value_or(driver::frames_for_one_pass(player.clock()));
  headless_options.out_dir = options.out;
  headless_options.sync = sync.get();
  // An earlier run's folder may be replaced, but not with the files this playback reads.
  headless_options.inputs = {options.file};
  if (!options.display.starts_with("builtin:")) headless_options.inputs.push_back(options.display);
  // A secondary plays until the master ends the run.
  if (cluster_share && !cluster_share->master) headless_options.frames = driver::kMaxFrames;
  facet::TerminalProgress progress(stderr, "facet play");
  if (!cluster_share || cluster_share->master) headless_options.progress = progress.sink();
  const driver::HeadlessPlayResult result = driver::run_headless_play(player, headless_options);
  progress.finish();
  std::int64_t dropped = result.frames.empty() ? 0 : result.frames.back().dropped_total;
  std::cout << "facet play: " << result.frames.size() << " frames of "
            << player.display().outputs.size() << " output(s) (" << context->info().renderer
            << ") written to " << options.out << "/<output>/<frame>.png; statistics in "
            << options.out << "/stats.jsonl; " << dropped << " source frames dropped\n";
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"play",
                               {{"display", "--display"},
                                {"size", "--size"},
                                {"factor", "--scale"},
                                {"format", "--format"},
                                {"fov_deg", "--fov"},
                                {"frames", "--frames"},
                                {"start_frame", "--start-frame"},
                                {"out", "--out"},
                                {"stats", "--stats"},
                                {"node", "--node"},
                                {"join_timeout_s", "--join-timeout"},
                                {"rate_hz", "--rate"}}};

const Registration registration{
    42, [](CLI::App& app) {
      auto options = std::make_shared<PlayOptions>();
      auto* command = app.add_subcommand(
          "play",
          "Play a dome master, equirectangular panorama or cube map (PNG, JPEG, EXR or a video) "
          "on a display through its exact warp and blend");
      command->add_option("file", options->file, "Still image (.png .jpg .exr ...) or video")
          ->required();
      command->add_option("display,--display", options->display,
                          "builtin:dome180 (default), builtin:cylinder360, builtin:wall2x2, a "
                          ".warp.exr or a display.json");
      command->add_option("--size", options->size, "Output size WxH of a built-in display");
      command->add_option("--scale", options->scale,
                          "Preview at this fraction of every output's resolution (0, 1]");
      command->add_option("--format", options->format,
                          "fisheye (square dome master), equirect (2:1) or cubemap (6:1 strip: "
                          "+x -x +y -y +z -z in OpenGL's orientation); default from the aspect");
      command->add_option("--fov", options->fov,
                          "Fisheye: the dome master's full field of view in degrees (default 180)");
      command->add_option("--tilt", options->orientation.tilt,
                          "The content's zenith tilted forward by DEG, in [-90, 90] (default 0)");
      command->add_option("--orientation", options->orientation.orientation,
                          "The content turned by DEG about the vertical, its front toward the "
                          "right, in [-360, 360] (default 0)");
      command->add_flag("--headless", options->headless, "Render through EGL to --out");
      command->add_flag("--windowed", options->windowed,
                        "Open windows (the default when DISPLAY is set)");
      command->add_flag("--span", options->span, "One borderless window spanning every output");
      command->add_option("--frames", options->frames,
                          "Output frames at 60 Hz, 1 to 1000000 (headless default: one pass of "
                          "the video, 1 for a still; windowed: until closed)");
      command->add_flag("--loop", options->loop, "Loop the video");
      command->add_option("--direction-cache", options->direction_cache,
                          "Folder keeping each output's direction lookup (the warp inverse at "
                          "every pixel) between starts, keyed by the warp's content, the least "
                          "recently used beyond --direction-cache-budget removed (default "
                          "$XDG_CACHE_HOME/facet/directions or ~/.cache/facet/directions)");
      command->add_option("--direction-cache-budget", options->direction_cache_budget_mib,
                          "MiB of direction lookups the cache folder keeps, 1 to 1048576 "
                          "(default 1024)");
      command->add_flag("--no-direction-cache", options->no_direction_cache,
                        "Compute the direction lookups at every start and write none");
      command->add_option("--start-frame", options->start_frame,
                          "Video frame shown at time 0 (default 0)");
      command
          ->add_option("--out", options->out,
                       "Headless: folder for <output>/<frame>.png and stats.jsonl")
          ->capture_default_str();
      command->add_option("--stats", options->stats,
                          "Windowed: write per-frame statistics (stats.jsonl lines) to this file");
      add_cluster_flags(*command, options->cluster, "Play");
      command->callback([options] { play(*options); });
    }};

}  // namespace
}  // namespace facet::cli
