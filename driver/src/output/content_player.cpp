#include "facet/driver/content_player.hpp"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "facet/driver/cluster.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/monitors.hpp"
#include "facet/driver/output_images.hpp"
#include "facet/driver/program.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "window_outputs.hpp"

namespace facet::driver {

namespace fs = std::filesystem;

namespace {

// A billionth of a source frame of slack against rounding in time_s · fps.
constexpr double kFrameSlack = 1e-9;

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

std::int64_t PlayClock::unwrapped_frame(double time_s) const {
  const double frames = std::floor(std::max(0.0, time_s) * fps + kFrameSlack);
  return start_frame + std::int64_t(std::min(frames, 1e15));
}

std::int64_t PlayClock::source_frame(double time_s) const {
  const std::int64_t k = unwrapped_frame(time_s);
  const std::int64_t count = std::max<std::int64_t>(1, frame_count);
  return loop ? k % count : std::min(k, count - 1);
}

std::int64_t PlayClock::dropped_between(double previous_s, double now_s) const {
  std::int64_t before = unwrapped_frame(previous_s), now = unwrapped_frame(now_s);
  if (!loop) {
    const std::int64_t last = std::max<std::int64_t>(1, frame_count) - 1;
    before = std::min(before, last);
    now = std::min(now, last);
  }
  return std::max<std::int64_t>(0, now - before - 1);
}

std::uint64_t frames_for_one_pass(const PlayClock& clock) {
  if (clock.frame_count <= 1) return 1;
  const double seconds = double(clock.frame_count - clock.start_frame) / clock.fps;
  const double frames = std::ceil(seconds / kFramePeriod_s - 1e-6);
  return std::uint64_t(std::clamp(frames, 1.0, double(kMaxFrames)));
}

nlohmann::json play_frame_stats_to_json(const PlayFrameStats& stats) {
  return {{"frame", stats.frame},
          {"time_s", stats.time_s},
          {"source_frame", stats.source_frame},
          {"dropped", stats.dropped},
          {"dropped_total", stats.dropped_total},
          {"seeked", stats.seeked},
          {"decode_ms", stats.decode_ms},
          {"upload_ms", stats.upload_ms},
          {"resample_ms", stats.resample_ms},
          {"cpu_ms", stats.cpu_ms},
          {"blend_tiles", stats.blend_tiles}};
}

ContentPlayer::ContentPlayer(SessionDisplay display, std::unique_ptr<ContentMedia> media,
                             PlaybackOptions options, PendingLookups lookups)
    : display_(std::move(display)), media_(std::move(media)), options_(std::move(options)) {
  FACET_ASSERT(media_ != nullptr);
  const std::string source = media_->path().string();
  options_.projection.validate("command line");
  if (options_.projection.format != ContentFormat::perspective)
    check_content_format(media_->size(), options_.projection.format, source);
  clock_.fps = media_->is_video() ? media_->fps() : 1;
  clock_.frame_count = media_->frame_count();
  clock_.loop = options_.loop;
  clock_.start_frame = options_.start_frame;
  if (options_.start_frame < 0 || options_.start_frame >= media_->frame_count())
    throw InputError("command line", OptionName{"start_frame"},
                     "a frame from 0 to " + std::to_string(media_->frame_count() - 1) + " of " +
                         source + "; got " + std::to_string(options_.start_frame));

  // The GL work that needs no lookup first, while they may still be on their way.
  texture_ = ContentTexture(options_.projection.format, media_->size(), media_->pixels(), source);
  for (const SessionOutput& output : display_.outputs) {
    targets_.push_back(OutputTarget::create(output.spec.warp.output_size));
    blends_.emplace_back(output.spec.warp.output_size, output.blend, output.encoding);
  }
  if (lookups.valid()) {
    pass_ = ContentPass(lookups.get(), options_.resample);
  } else {
    std::vector<OutputSpec> specs;
    for (const SessionOutput& output : display_.outputs) specs.push_back(output.spec);
    pass_ = ContentPass(specs, options_.resample);
  }
  FACET_ASSERT(pass_.output_count() == display_.outputs.size());
}

PendingLookups start_content_lookups(const SessionDisplay& display,
                                     const ResampleOptions& options) {
  std::vector<OutputSpec> specs;
  for (const SessionOutput& output : display.outputs) specs.push_back(output.spec);
  std::packaged_task<ContentLookups(std::stop_token)> task(
      [specs = std::move(specs), options](std::stop_token stop) {
        return prepare_content_lookups(specs, options, stop);
      });
  std::future<ContentLookups> result = task.get_future();
  return PendingLookups(std::move(result), std::jthread(std::move(task)));
}

PlayFrameStats ContentPlayer::render(const FrameState& state, bool finish) {
  const auto start = std::chrono::steady_clock::now();
  PlayFrameStats stats;
  stats.frame = state.frame;
  stats.time_s = state.time_s;
  if (previous_time_s_ && state.time_s > *previous_time_s_)
    stats.dropped = clock_.dropped_between(*previous_time_s_, state.time_s);
  previous_time_s_ = state.time_s;
  dropped_total_ += stats.dropped;
  stats.dropped_total = dropped_total_;

  const ContentMedia::Decoded decoded = media_->frame(clock_.source_frame(state.time_s));
  // The real end may have been met: the clock wraps and holds by the frames decoded.
  clock_.frame_count = media_->frame_count();
  stats.source_frame = decoded.index;
  stats.seeked = decoded.seeked;
  stats.decode_ms = decoded.decode_ms;
  if (decoded.index != uploaded_) {
    const auto upload_start = std::chrono::steady_clock::now();
    texture_.upload(*decoded.image);
    uploaded_ = decoded.index;
    if (finish) glFinish();
    stats.upload_ms = ms_since(upload_start);
  }

  const auto resample_start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < targets_.size(); ++i) {
    targets_[i].clear();
    targets_[i].bind();
    pass_.draw(i, texture_, options_.projection);
    blends_[i].apply(targets_[i].colour());
    stats.blend_tiles.push_back(blends_[i].tiles_listed());
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (finish) glFinish();
  stats.resample_ms = ms_since(resample_start);
  stats.cpu_ms = ms_since(start);
  return stats;
}

HeadlessPlayResult run_headless_play(ContentPlayer& player, const HeadlessRunOptions& options) {
  HeadlessRunOptions every_frame = options;
  every_frame.save_every = 1;
  HeadlessPlayResult result;
  write_headless_frames(
      every_frame, "'facet play' or 'facet run'", player.display(), player.targets(), {},
      [&](const FrameState& state) {
        result.frames.push_back(player.render(state, options.finish_each_frame || options.sync));
        return play_frame_stats_to_json(result.frames.back());
      },
      [&](std::uint64_t, nlohmann::json&, std::span<const fs::path> images) {
        result.images.insert(result.images.end(), images.begin(), images.end());
      });
  return result;
}

namespace {

struct PlayKeys {
  bool quit = false;
  bool paused = false;
};

void on_play_key(GLFWwindow* window, int key, int, int action, int) {
  auto& keys = *static_cast<PlayKeys*>(glfwGetWindowUserPointer(window));
  if (action != GLFW_PRESS) return;
  if (key == GLFW_KEY_ESCAPE) keys.quit = true;
  if (key == GLFW_KEY_SPACE) keys.paused = !keys.paused;
}

}  // namespace

void run_windowed_play(const SessionDisplay& display, std::unique_ptr<ContentMedia> media,
                       const PlaybackOptions& options, const WindowPlayOptions& window_options,
                       PendingLookups lookups) {
  const auto entered = std::chrono::steady_clock::now();
  const std::vector<MonitorInfo> monitors = list_monitors();
  const std::vector<OutputPlacement> placements = detail::place_display_outputs(display, monitors);
  PlayKeys keys;
  std::vector<detail::OutputsWindow> windows = detail::open_outputs_windows(
      placements, window_options.span, "facet play", [&keys](GLFWwindow* native) {
        glfwSetWindowUserPointer(native, &keys);
        glfwSetKeyCallback(native, on_play_key);
      });

  windows.front().context->make_current();
  ContentPlayer player(display, std::move(media), options, std::move(lookups));
  const detail::WindowPresenter presenter(player.targets());
  for (detail::OutputsWindow& window : windows) {
    window.context->make_current();
    window.vertex_array = VertexArray::create();
  }
  windows.front().context->make_current();

  std::ofstream stats_file;
  const fs::path stats_temporary =
      window_options.stats
          ? window_options.stats->parent_path() / ("." + window_options.stats->filename().string() +
                                                   ".tmp" + std::to_string(::getpid()))
          : fs::path();
  if (window_options.stats) {
    stats_file.open(stats_temporary);
    if (!stats_file)
      throw InputError(window_options.stats->string(), OptionName{"stats"},
                       "a file that can be written");
  }

  const auto start = std::chrono::steady_clock::now();
  double paused_s = 0, show_s = 0;
  auto last = start;
  int interrupted_by = 0;
  std::uint64_t frames_shown = 0;
  std::int64_t dropped_total = 0;
  for (std::uint64_t frame = 0; !window_options.frames || frame < *window_options.frames; ++frame) {
    if (detail::poll_run_ends(windows, keys.quit, interrupted_by)) break;
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    last = now;
    if (keys.paused) paused_s += dt;
    // The show clock: wall time since the first frame, less the time paused.
    show_s = std::chrono::duration<double>(now - start).count() - paused_s;
    windows.front().context->make_current();
    FrameState state;
    state.frame = frame;
    state.time_s = show_s;
    if (window_options.sync) {
      std::optional<FrameState> next = window_options.sync->next_frame(state);
      if (!next) break;
      state = std::move(*next);
    }
    const PlayFrameStats stats = player.render(state, window_options.sync != nullptr);
    nlohmann::json line = play_frame_stats_to_json(stats);
    const bool show = !window_options.sync || window_options.sync->ready_to_swap(state, line);
    if (frame == 0 && window_options.log) {
      char said[64];
      std::snprintf(
          said, sizeof said, "first frame after %.0f ms",
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - entered)
              .count());
      window_options.log(LogLevel::info, said);
    }
    dropped_total = stats.dropped_total;
    if (stats_file.is_open()) stats_file << line.dump() << '\n';
    GLsync rendered = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    for (detail::OutputsWindow& window : windows) {
      if (!show) break;  // a frame the cluster's barrier did not let swap
      window.context->make_current();
      glWaitSync(rendered, 0, GL_TIMEOUT_IGNORED);
      presenter.present(window.context->framebuffer_size(), window.vertex_array, window.outputs,
                        window.viewports);
      window.context->swap_buffers();
    }
    windows.front().context->make_current();
    glDeleteSync(rendered);
    frames_shown = frame + 1;
  }
  for (detail::OutputsWindow& window : windows) {
    window.context->make_current();
    window.vertex_array.reset();
  }
  windows.front().context->make_current();
  if (window_options.log)
    window_options.log(LogLevel::info, std::to_string(frames_shown) + " frames shown, " +
                                           std::to_string(dropped_total) +
                                           " source frames dropped");
  if (stats_file.is_open()) {
    stats_file.close();
    // Interrupted: no statistics file, as nothing is written then.
    if (interrupted_by || !stats_file) {
      std::error_code ignored;
      fs::remove(stats_temporary, ignored);
      if (!interrupted_by)
        throw std::runtime_error(window_options.stats->string() + ": write failed");
    } else {
      fs::rename(stats_temporary, *window_options.stats);
    }
  }
  if (interrupted_by)
    throw Interrupted(interrupted_by, "stopped after " + std::to_string(frames_shown) + " frames");
}

}  // namespace facet::driver
