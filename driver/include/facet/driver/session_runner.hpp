#pragma once
// Running a Session: headless through EGL (frames to files) or in GLFW windows on the projector
// monitors, with navigation and an overlay.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "facet/driver/log.hpp"
#include "facet/driver/monitors.hpp"
#include "facet/driver/scene.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/driver/scene_view.hpp"
#include "facet/driver/session.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/progress.hpp"

namespace facet::driver {

class FrameSync;

// Frames advance scene time by this much: a 60 Hz projector.
inline constexpr double kFramePeriod_s = 1.0 / 60.0;

// The eye pose over time when nobody steers: the city's camera path for the built-in city, and
// for any other scene one turn a minute of the view (SceneView::T_world_eye_turned: on the spot,
// or about the point looked at), so a whole dome sees every side of the model.
using CameraPath = std::function<glm::dmat4(double time_s)>;
inline constexpr double kViewTurnPeriod_s = 60.0;
CameraPath camera_path(const SceneView& view);
// camera_path of the default view (choose_scene_view with no request).
CameraPath default_camera_path(const Scene& scene, bool builtin_city);

// The most frames one command renders: facet run (headless or windowed), render and bench refuse
// a --frames beyond it (a headless run writes a PNG per output and frame).
inline constexpr std::uint64_t kMaxFrames = 1'000'000;

struct HeadlessRunOptions {
  std::uint64_t frames = 1;
  std::filesystem::path out_dir;  // receives <output>/<frame>.png and stats.jsonl
  std::uint64_t save_every = 1;   // PNGs of frames 0, n, 2n, ... and of the last frame; >= 1
  bool finish_each_frame = true;  // glFinish per frame, so cpu_ms is the frame's whole time
  // Where the frame states come from and when a frame is shown (cluster.hpp); null: frames
  // 0..frames-1 along the path, each shown. With a sync, `frames` only bounds the run and names
  // the last frame for save_every, and a frame the sync does not let swap is not written.
  FrameSync* sync = nullptr;
  ProgressSink progress;  // ("frames", done, frames) before the first and after each frame
  // What the run reads (display, scene, content files): out_dir may neither be one nor hold one.
  std::vector<std::filesystem::path> inputs;
};

// What a run leaves in memory stays the same size whatever the frame count: the per-frame
// statistics go to stats.jsonl only.
struct HeadlessRunResult {
  std::uint64_t frames = 0;          // frames rendered
  std::uint64_t images_written = 0;  // PNGs written
  FrameStats last;                   // the last frame's statistics
  std::uint64_t rss_first_kib = 0;   // resident set after the first frame
  std::uint64_t rss_peak_kib = 0;    // largest resident set after any frame
};

// What a headless run does per frame: render the frame `state` into the targets and return its
// statistics line.
using RenderHeadlessFrame = std::function<nlohmann::json(const FrameState& state)>;
// Called per frame `done` (0, 1, ...) after its images were written (final paths, none when the
// frame was not saved), before its line goes to stats.jsonl: may add to the line.
using HeadlessFrameDone = std::function<void(std::uint64_t done, nlohmann::json& line,
                                             std::span<const std::filesystem::path> images)>;

// The check write_headless_frames makes of options.out_dir (with options.inputs; `earlier` as
// there), for a command to make before its work: InputError naming the folder and --out.
void check_headless_out(const HeadlessRunOptions& options, const std::string& earlier);

// The frame loop of every headless run (run_headless_session, run_headless_play). Checks
// options.frames (1 to kMaxFrames), options.save_every (>= 1) and options.out_dir, which may be
// new, an empty folder or an earlier headless run's folder (stats.jsonl and folders of
// NNNNN.png, nothing else; `earlier` names the commands that write one, for the error: "'facet
// run'"); then through write_folder_atomically: for done = 0..frames-1 the state of time
// done·kFramePeriod_s and eye path(time) (`path` may be empty), or what options.sync makes of it,
// goes to render; the images of `targets` (one per display output) of every shown frame that
// save_every selects (and of the last) go to out_dir/<output>/<frame, 5 digits>.png, and the
// line to out_dir/stats.jsonl. SIGINT or SIGTERM (after watch_interrupts) stops it before the
// next frame or before the rename with Interrupted, leaving out_dir as it was.
void write_headless_frames(const HeadlessRunOptions& options, const std::string& earlier,
                           const SessionDisplay& display, std::span<const OutputTarget> targets,
                           const CameraPath& path, const RenderHeadlessFrame& render,
                           const HeadlessFrameDone& done_frame);

// Renders frames 0..frames-1 at times k·kFramePeriod_s along `path` and writes
// out_dir/<output>/<frame, 5 digits>.png (every save_every-th frame and the last) and
// out_dir/stats.jsonl (one frame_stats_to_json line per frame, plus "rss_kib": the process's
// resident set after the frame). The folder is written under a temporary name and renamed when
// complete. An existing out_dir is replaced only when it is empty or holds exactly an earlier run
// (stats.jsonl and folders of NNNNN.png, nothing else); a folder with anything else in it, the
// current folder or one of its parents, a frame count outside [1, kMaxFrames] and save_every 0 are
// InputErrors, raised before anything is written. After watch_interrupts(), SIGINT or SIGTERM stops
// the run before the next frame (or before the rename): the temporary folder is removed, out_dir is
// left as it was, and Interrupted says how many frames were rendered.
HeadlessRunResult run_headless_session(Session& session, const CameraPath& path,
                                       const HeadlessRunOptions& options);

struct WindowRunOptions {
  std::optional<std::uint64_t> frames;  // stop after this many frames (tests); else until closed
  bool span = false;                    // one borderless window spanning every output's rectangle
  bool overlay = false;                 // start with the overlay shown (toggle with O)
  bool play_path = true;                // start playing the camera path (toggle with P)
  // Written when the run ends: per window its placement, its actual position and size, and
  // whether its framebuffer held exactly its output's pixels on the last frame.
  std::optional<std::filesystem::path> report;
  // A cluster node's frame states and swap barrier (cluster.hpp); null: the session's own.
  FrameSync* sync = nullptr;
  // Start on this test pattern instead of the scene (T cycles: the scene, then every pattern).
  std::optional<TestPattern> pattern;
  // The windows opened (info), the pattern shown (info), monitors that come or go (warning).
  LogSink log;
  // A scene name with @lod depth images (uses_depth_lod): the session draws it instead of
  // `scene`, built for the camera path's first eye and rebuilt where the eye's levels change
  // (Session::set_view_dependent_scene). The report counts the frames that rebuilt it.
  std::optional<SceneName> view_dependent_scene;
};

// Opens the windows (one per output on its monitor, or one spanning window), renders until the
// windows close or `frames` have been shown. Keys: W/S forward and back, A/D sideways, Q/E down
// and up, arrows or dragging with the left mouse button turn, P toggles the camera path,
// O toggles the overlay (fps, replication, ms per pass), T steps from the scene through the test
// patterns (all_test_patterns) and back, Escape quits. Monitors that disappear
// during the session are reported to options.log and their windows kept. After watch_interrupts(),
// SIGINT or SIGTERM closes the windows and throws Interrupted, writing no report. Needs a display
// server: GlContextError without one. InputError when a monitor the display needs is missing and
// the display says "missing_monitor": "error".
void run_windowed_session(const SessionDisplay& display, const Scene& scene, const CameraPath& path,
                          const WindowRunOptions& options);

}  // namespace facet::driver
