#pragma once
// Content playback (`facet play`): a still image or a video shown on every projector output of a
// display through the exact warp (ContentPass), then blended as sessions blend.
//
// Timing comes from the show clock, FrameState::time_s: video frame k is on screen from k/fps
// to (k+1)/fps after the start, so every node of a cluster given the same FrameState shows the
// same video frame. Source frames whose whole time passes between two output frames are dropped
// and counted.
#include <cstdint>
#include <filesystem>
#include <future>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "facet/driver/blend_pass.hpp"
#include "facet/driver/content_media.hpp"
#include "facet/driver/content_pass.hpp"
#include "facet/driver/log.hpp"
#include "facet/driver/session.hpp"
#include "facet/driver/session_runner.hpp"

namespace facet::driver {

// Which source frame is on screen at show time `time_s` (seconds from the start, >= 0): the
// unwrapped index start_frame + floor(time_s · fps), then wrapped modulo frame_count when
// looping, else held at the last frame. A billionth of a frame of slack takes times such as
// 2/60 s at 30 fps to their frame despite rounding.
struct PlayClock {
  double fps = 30;
  std::int64_t frame_count = 1;
  std::int64_t start_frame = 0;
  bool loop = false;

  std::int64_t unwrapped_frame(double time_s) const;
  std::int64_t source_frame(double time_s) const;
  // Source frames that were never on screen between the output frames at `previous_s` and
  // `now_s` (now_s > previous_s); past the end of a non-looping video nothing more is dropped.
  std::int64_t dropped_between(double previous_s, double now_s) const;
};

struct PlaybackOptions {
  ContentProjection projection;  // fisheye_content() by default
  bool loop = false;
  std::int64_t start_frame = 0;  // InputError(OptionName "start_frame") beyond the video
  ResampleOptions resample;
};

struct PlayFrameStats {
  std::uint64_t frame = 0;
  double time_s = 0;
  std::int64_t source_frame = 0;   // the content frame shown
  std::int64_t dropped = 0;        // source frames skipped since the previous output frame
  std::int64_t dropped_total = 0;  // since the start
  bool seeked = false;             // the decoder had to seek (a loop, a start frame)
  double decode_ms = 0;            // decoding (0 when the frame was already decoded)
  double upload_ms = 0;            // texture upload and mip levels (0 when unchanged)
  double resample_ms = 0;          // every output's resample and blend, to glFinish when asked
  double cpu_ms = 0;               // the whole ContentPlayer::render
  std::vector<std::size_t> blend_tiles;  // per output
};
nlohmann::json play_frame_stats_to_json(const PlayFrameStats& stats);

// The direction lookups start_content_lookups prepares on a thread of its own. Letting it go
// without get() (a bad content file, any error before the player takes it) stops the work within
// a row of the warp inverse and waits only for that, so that an early exit does not wait for
// lookups nobody will use; a stopped output writes no cache file.
class PendingLookups {
 public:
  PendingLookups() = default;
  PendingLookups(std::future<ContentLookups> result, std::jthread worker)
      : result_(std::move(result)), worker_(std::move(worker)) {}

  bool valid() const { return result_.valid(); }
  // Waits for the lookups; rethrows what preparing them threw.
  ContentLookups get() { return result_.get(); }

 private:
  std::future<ContentLookups> result_;
  std::jthread worker_;  // destroyed first: asks the work to stop, then joins it
};

class ContentPlayer {
 public:
  // Opens nothing: `media` is the opened file. Builds the direction lookups and blend passes of
  // every output. Needs a current GL context for the player's life. InputError for a content
  // format that does not fit the media (check_content_format) or a start frame beyond its end.
  // `lookups`, when valid, brings the direction lookups start_content_lookups began (with this
  // display and options.resample); else they are prepared here.
  ContentPlayer(SessionDisplay display, std::unique_ptr<ContentMedia> media,
                PlaybackOptions options, PendingLookups lookups = {});

  // Shows the source frame for `state.time_s` on every output: decode if it changed, upload,
  // resample through the warp, blend. With `finish`, waits for the GPU (for timings).
  PlayFrameStats render(const FrameState& state, bool finish = false);

  const SessionDisplay& display() const { return display_; }
  std::span<const OutputTarget> targets() const { return targets_; }
  const ContentMedia& media() const { return *media_; }
  const PlayClock& clock() const { return clock_; }
  const ContentPass& pass() const { return pass_; }

 private:
  SessionDisplay display_;
  std::unique_ptr<ContentMedia> media_;
  PlaybackOptions options_;
  PlayClock clock_;
  ContentPass pass_;
  ContentTexture texture_;
  std::vector<OutputTarget> targets_;
  std::vector<BlendPass> blends_;
  std::int64_t uploaded_ = -1;  // the source frame in texture_
  std::optional<double> previous_time_s_;
  std::int64_t dropped_total_ = 0;
};

// Starts preparing the direction lookups of every output of `display` (prepare_content_lookups)
// on a thread of its own, so that opening the content and the GL overlap them; the result goes
// to ContentPlayer or run_windowed_play. They need the CPU, not the GL.
PendingLookups start_content_lookups(const SessionDisplay& display, const ResampleOptions& options);

struct HeadlessPlayResult {
  std::vector<PlayFrameStats> frames;
  std::vector<std::filesystem::path> images;
};

// Shows frames 0..frames−1 at show times k·kFramePeriod_s and writes
// out_dir/<output>/<frame, 5 digits>.png and out_dir/stats.jsonl (play_frame_stats_to_json per
// frame), with run_headless_session's rules for out_dir (an earlier run there is replaced, any
// other folder refused; written under a temporary name; SIGINT and SIGTERM stop it cleanly).
// With options.sync the frame states are the cluster master's (so every node shows the same
// video frame), `frames` only bounds the run, and a frame the barrier does not let swap is
// listed in stats.jsonl but not written. save_every is not used: every frame is written.
HeadlessPlayResult run_headless_play(ContentPlayer& player, const HeadlessRunOptions& options);

// The frames one pass of the media takes at kFramePeriod_s: 1 for a still image, else enough
// output frames for every source frame from the start frame to the end, capped at kMaxFrames.
std::uint64_t frames_for_one_pass(const PlayClock& clock);

struct WindowPlayOptions {
  std::optional<std::uint64_t> frames;  // stop after this many frames; else until closed
  bool span = false;                    // one borderless window over every output
  // play_frame_stats_to_json per frame shown, written under a temporary name and renamed when
  // the windows close (not when interrupted).
  std::optional<std::filesystem::path> stats;
  // Frame-locked with a cluster: the master's frame states, its swap barrier.
  FrameSync* sync = nullptr;
  // How long the first frame took, and at the end the frames shown and dropped (info).
  LogSink log;
};

// A window per output on its monitor (or one spanning window), showing the content on the
// wall clock from the first frame; Space pauses, Escape quits. GlContextError without a display
// server; Interrupted after watch_interrupts().
void run_windowed_play(const SessionDisplay& display, std::unique_ptr<ContentMedia> media,
                       const PlaybackOptions& options, const WindowPlayOptions& window_options,
                       PendingLookups lookups = {});

}  // namespace facet::driver
