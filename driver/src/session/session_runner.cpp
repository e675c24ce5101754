#include "facet/driver/session_runner.hpp"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <string>
#include <string_view>

#include "../gl/image_rows.hpp"
#include "../output/window_outputs.hpp"
#include "facet/driver/city.hpp"
#include "facet/driver/cluster.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/output_images.hpp"
#include "facet/driver/program.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"

// stb_easy_font turns text into quads; it is a single header with internal linkage.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb/stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace facet::driver {

namespace fs = std::filesystem;

CameraPath camera_path(const SceneView& view) {
  if (view.follows_city_path) {
    auto city_path = std::make_shared<CityCameraPath>();
    return [city_path](double time_s) { return city_path->T_world_eye(time_s); };
  }
  return [view](double time_s) { return view.T_world_eye_turned(time_s / kViewTurnPeriod_s); };
}

CameraPath default_camera_path(const Scene& scene, bool builtin_city) {
  return camera_path(choose_scene_view(scene, {}, builtin_city));
}

namespace {

// A frame image's name: five or more digits, then ".png".
bool is_frame_file_name(const std::string& name) {
  constexpr std::string_view kSuffix = ".png";
  if (name.size() < 5 + kSuffix.size() || !name.ends_with(kSuffix)) return false;
  return std::all_of(name.begin(), name.end() - kSuffix.size(),
                     [](char c) { return c >= '0' && c <= '9'; });
}

// True when the folder `dir` holds exactly what a headless run writes: a stats.jsonl and folders
// of frame images, nothing else (no other file, no symbolic link).
bool holds_earlier_run(const fs::path& dir) {
  bool has_stats = false;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    const fs::file_status entry_status = entry.symlink_status();
    if (entry.path().filename() == "stats.jsonl" && fs::is_regular_file(entry_status)) {
      has_stats = true;
      continue;
    }
    if (!fs::is_directory(entry_status)) return false;
    for (const fs::directory_entry& frame : fs::directory_iterator(entry.path())) {
      if (!fs::is_regular_file(frame.symlink_status()) ||
          !is_frame_file_name(frame.path().filename().string()))
        return false;
    }
  }
  return has_stats;
}

// The process's resident set in KiB, from /proc/self/statm; 0 where that cannot be read.
std::uint64_t resident_set_kib() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t size_pages = 0, resident_pages = 0;
  if (!(statm >> size_pages >> resident_pages)) return 0;
  return resident_pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)) / 1024;
}

std::string frame_file_name(std::uint64_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "%05llu.png", static_cast<unsigned long long>(frame));
  return name;
}

OutputFolderRules headless_out_rules(const HeadlessRunOptions& options,
                                     const std::string& earlier) {
  OutputFolderRules rules;
  rules.field = OptionName{"out"};
  rules.expected = "a new path, an empty folder, or a folder from an earlier " + earlier +
                   " (stats.jsonl and folders of NNNNN.png, nothing else)";
  rules.is_own_output = holds_earlier_run;
  rules.inputs = options.inputs;
  return rules;
}

}  // namespace

void check_headless_out(const HeadlessRunOptions& options, const std::string& earlier) {
  check_output_folder(options.out_dir, headless_out_rules(options, earlier));
}

void write_headless_frames(const HeadlessRunOptions& options, const std::string& earlier,
                           const SessionDisplay& display, std::span<const OutputTarget> targets,
                           const CameraPath& path, const RenderHeadlessFrame& render,
                           const HeadlessFrameDone& done_frame) {
  FACET_ASSERT(targets.size() == display.outputs.size());
  if (options.frames < 1 || options.frames > kMaxFrames)
    throw InputError("command line", OptionName{"frames"},
                     "from 1 to " + std::to_string(kMaxFrames) + " frames");
  if (options.save_every < 1)
    throw InputError("command line", OptionName{"save_every"}, "a frame interval of at least 1");
  const OutputFolderRules rules = headless_out_rules(options, earlier);
  const fs::path out_dir = check_output_folder(options.out_dir, rules);
  const bool replacing = fs::exists(fs::symlink_status(out_dir));
  write_folder_atomically(
      out_dir,
      [&](const fs::path& temporary) {
        for (const SessionOutput& output : display.outputs)
          fs::create_directories(temporary / output.spec.name);
        std::ofstream stats_file(temporary / "stats.jsonl");
        // Stops before a frame, and before the rename, once SIGINT or SIGTERM has arrived (after
        // watch_interrupts); write_folder_atomically then removes the temporary folder.
        auto stop_if_interrupted = [&](std::uint64_t done) {
          if (const int signal = interrupt_signal())
            throw Interrupted(signal, "stopped after " + std::to_string(done) + " of " +
                                          std::to_string(options.frames) +
                                          " frames; nothing written to " + out_dir.string() +
                                          (replacing ? " (what was there is kept)" : ""));
        };
        if (options.progress) options.progress({"frames", 0, options.frames});
        std::vector<fs::path> images;
        for (std::uint64_t done = 0; done < options.frames; ++done) {
          stop_if_interrupted(done);
          FrameState state;
          state.frame = done;
          state.time_s = double(done) * kFramePeriod_s;
          if (path) state.T_world_eye = path(state.time_s);
          if (options.sync) {
            std::optional<FrameState> next = options.sync->next_frame(state);
            if (!next) break;
            state = std::move(*next);
          }
          const std::uint64_t frame = state.frame;
          nlohmann::json line = render(state);
          const bool shown = !options.sync || options.sync->ready_to_swap(state, line);
          const bool save =
              shown && (frame % options.save_every == 0 || frame + 1 == options.frames);
          images.clear();
          for (std::size_t i = 0; save && i < targets.size(); ++i) {
            const fs::path image = fs::path(display.outputs[i].spec.name) / frame_file_name(frame);
            write_png_rgba8(temporary / image, targets[i].size(), targets[i].read_colour_rgba8());
            images.push_back(out_dir / image);
          }
          if (done_frame) done_frame(done, line, images);
          // Flushed per frame: whoever watches a long run (a cluster's tests) sees it progress.
          stats_file << line.dump() << '\n' << std::flush;
          if (options.progress) options.progress({"frames", done + 1, options.frames});
        }
        stats_file.close();
        if (!stats_file)
          throw std::runtime_error((out_dir / "stats.jsonl").string() + ": write failed");
        stop_if_interrupted(options.frames);
      },
      rules);
}

HeadlessRunResult run_headless_session(Session& session, const CameraPath& path,
                                       const HeadlessRunOptions& options) {
  HeadlessRunResult result;
  write_headless_frames(
      options, "'facet run'", session.display(), session.targets(), path,
      [&](const FrameState& state) {
        result.last = session.render(state, options.finish_each_frame);
        return frame_stats_to_json(result.last);
      },
      [&](std::uint64_t done, nlohmann::json& line, std::span<const fs::path> images) {
        result.images_written += images.size();
        const std::uint64_t rss_kib = resident_set_kib();
        if (done == 0) result.rss_first_kib = rss_kib;
        result.rss_peak_kib = std::max(result.rss_peak_kib, rss_kib);
        line["rss_kib"] = rss_kib;
        result.frames = done + 1;
      });
  return result;
}

namespace {

// Keyboard and mouse state shared by every window of a session.
struct Navigation {
  bool play_path = true;
  bool overlay = false;
  int pattern_steps = 0;  // presses of T not yet acted on
  bool quit = false;
  glm::dvec3 position{0.0};
  double yaw = 0, pitch = 0;  // radians; yaw about world up, pitch about the eye's x
  bool dragging = false;
  glm::dvec2 last_cursor{0.0};
  std::vector<std::string> messages;

  glm::dmat4 T_world_eye() const {
    glm::dmat4 T = glm::translate(glm::dmat4(1.0), position);
    T = glm::rotate(T, yaw, glm::dvec3(0, 1, 0));
    return glm::rotate(T, pitch, glm::dvec3(1, 0, 0));
  }
  // Takes over from the camera path at its current pose.
  void take_over(const glm::dmat4& T_world_eye_now) {
    if (!play_path) return;
    play_path = false;
    position = glm::dvec3(T_world_eye_now[3]);
    const glm::dvec3 forward = -glm::dvec3(T_world_eye_now[2]);
    yaw = std::atan2(-forward.x, -forward.z);
    pitch = std::asin(std::clamp(forward.y, -1.0, 1.0));
  }
};

Navigation* navigation_of(GLFWwindow* window) {
  return static_cast<Navigation*>(glfwGetWindowUserPointer(window));
}

void on_key(GLFWwindow* window, int key, int, int action, int) {
  Navigation& nav = *navigation_of(window);
  if (action != GLFW_PRESS) return;
  if (key == GLFW_KEY_ESCAPE) nav.quit = true;
  if (key == GLFW_KEY_P) nav.play_path = !nav.play_path;
  if (key == GLFW_KEY_O) nav.overlay = !nav.overlay;
  if (key == GLFW_KEY_T) ++nav.pattern_steps;
}

void on_mouse_button(GLFWwindow* window, int button, int action, int) {
  Navigation& nav = *navigation_of(window);
  if (button != GLFW_MOUSE_BUTTON_LEFT) return;
  nav.dragging = action == GLFW_PRESS;
  glfwGetCursorPos(window, &nav.last_cursor.x, &nav.last_cursor.y);
}

Navigation* monitor_messages = nullptr;
const LogSink* monitor_log = nullptr;

void on_monitor(GLFWmonitor* monitor, int event) {
  const char* name = glfwGetMonitorName(monitor);
  const std::string message = std::string("monitor ") + (name ? name : "?") +
                              (event == GLFW_CONNECTED ? " connected" : " disconnected") +
                              "; windows stay where they are";
  if (monitor_log && *monitor_log) (*monitor_log)(LogLevel::warning, message);
  if (monitor_messages) monitor_messages->messages.push_back(message);
}

// Moves the eye with the held keys and the dragged mouse, scaled by the frame time.
void steer(Navigation& nav, GLFWwindow* window, double dt, const glm::dmat4& T_world_eye_now) {
  const double speed = 6.0, turn = 1.2;  // m/s, rad/s
  glm::dvec3 move{0.0};
  if (glfwGetKey(window, GLFW_KEY_W) == GLFW_PRESS) move.z -= 1;
  if (glfwGetKey(window, GLFW_KEY_S) == GLFW_PRESS) move.z += 1;
  if (glfwGetKey(window, GLFW_KEY_A) == GLFW_PRESS) move.x -= 1;
  if (glfwGetKey(window, GLFW_KEY_D) == GLFW_PRESS) move.x += 1;
  if (glfwGetKey(window, GLFW_KEY_Q) == GLFW_PRESS) move.y -= 1;
  if (glfwGetKey(window, GLFW_KEY_E) == GLFW_PRESS) move.y += 1;
  double yaw_rate = 0, pitch_rate = 0;
  if (glfwGetKey(window, GLFW_KEY_LEFT) == GLFW_PRESS) yaw_rate += turn;
  if (glfwGetKey(window, GLFW_KEY_RIGHT) == GLFW_PRESS) yaw_rate -= turn;
  if (glfwGetKey(window, GLFW_KEY_UP) == GLFW_PRESS) pitch_rate += turn;
  if (glfwGetKey(window, GLFW_KEY_DOWN) == GLFW_PRESS) pitch_rate -= turn;
  glm::dvec2 drag{0.0};
  if (nav.dragging) {
    glm::dvec2 cursor;
    glfwGetCursorPos(window, &cursor.x, &cursor.y);
    drag = cursor - nav.last_cursor;
    nav.last_cursor = cursor;
  }
  if (move == glm::dvec3(0.0) && yaw_rate == 0 && pitch_rate == 0 && drag == glm::dvec2(0.0))
    return;
  nav.take_over(T_world_eye_now);
  nav.yaw += yaw_rate * dt - drag.x * 0.004;
  nav.pitch = std::clamp(nav.pitch + pitch_rate * dt - drag.y * 0.004, -1.5, 1.5);
  const glm::dmat3 R_world_eye(nav.T_world_eye());
  nav.position += R_world_eye * move * speed * dt;
}

// Triangles (x, y in window pixels from the top left) for `text` at (x, y).
std::vector<float> overlay_triangles(const std::string& text, float x, float y) {
  std::vector<char> quads(text.size() * 270 + 64);
  std::string mutable_text = text;
  const int quad_count =
      stb_easy_font_print(x, y, mutable_text.data(), nullptr, quads.data(), int(quads.size()));
  std::vector<float> triangles;
  triangles.reserve(std::size_t(quad_count) * 12);
  auto vertex = [&](int quad, int corner) {
    float xyz[3];
    std::memcpy(xyz, quads.data() + (std::size_t(quad) * 4 + corner) * 16, sizeof xyz);
    triangles.push_back(xyz[0]);
    triangles.push_back(xyz[1]);
  };
  for (int q = 0; q < quad_count; ++q)
    for (int corner : {0, 1, 2, 0, 2, 3}) vertex(q, corner);
  return triangles;
}

// The log line that says where the outputs' windows opened.
std::string windows_open_line(const SessionDisplay& display,
                              std::span<const OutputPlacement> placements, std::size_t windows) {
  std::string line = std::to_string(windows) + " windows open:";
  for (std::size_t i = 0; i < placements.size(); ++i) {
    const glm::ivec4& r = placements[i].rect;
    line += " " + display.outputs[i].spec.name + " at " + std::to_string(r.x) + "," +
            std::to_string(r.y) + " " + std::to_string(r.z) + "x" + std::to_string(r.w) + " (" +
            placements[i].how + ")";
  }
  return line;
}

// Acts on the presses of T since the last frame: the scene, then every pattern in order, then
// the scene again.
void step_patterns(Session& session, Navigation& nav, const LogSink& log) {
  for (; nav.pattern_steps > 0; --nav.pattern_steps) {
    const auto& patterns = all_test_patterns();
    const auto at = session.pattern()
                        ? std::find(patterns.begin(), patterns.end(), *session.pattern())
                        : patterns.end();
    const auto next = at == patterns.end() ? patterns.begin() : at + 1;
    session.set_pattern(next == patterns.end() ? std::nullopt : std::optional<TestPattern>(*next));
    if (log)
      log(LogLevel::info,
          "showing " + (session.pattern() ? to_string(*session.pattern()) : "the scene"));
  }
}

// The overlay's text: frame rate, replication ratio and frame, then a line per timed pass.
std::string overlay_text(double fps, const FrameStats& stats, std::uint64_t frame) {
  char line[160];
  std::snprintf(line, sizeof line, "%.1f fps   replication %.2f   frame %llu\n", fps,
                stats.replication_ratio(), static_cast<unsigned long long>(frame));
  std::string text = line;
  for (const PassTime& pass : stats.pass_ms) {
    std::snprintf(line, sizeof line, "%-14s %7.3f ms\n", pass.pass.c_str(), pass.milliseconds);
    text += line;
  }
  return text;
}

// Draws `text` over the current window's framebuffer of `size` pixels, its triangles in
// `vertices`.
void draw_overlay(const Program& overlay, const VertexArray& vertex_array, Buffer& vertices,
                  const std::string& text, glm::ivec2 size) {
  const std::vector<float> triangles = overlay_triangles(text, 12, 12);
  vertices = Buffer::create_from(triangles);
  glViewport(0, 0, size.x, size.y);
  overlay.use();
  glUniform2f(0, float(size.x), float(size.y));
  glBindVertexArray(vertex_array.id());
  vertices.bind_base(GL_SHADER_STORAGE_BUFFER, 0);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(triangles.size() / 2));
}

// Where a window was and whether it showed exactly the outputs' bytes, as the projector would
// receive them: per output the colour bytes that differ, -1 where the output is scaled.
struct WindowReport {
  glm::ivec2 position{0}, framebuffer{0};
  std::vector<long long> mismatched_bytes;
};

// The report of `window` (current, `size` framebuffer pixels) just after presenting: reads its
// back buffer, and each output's colour with `first`'s context current.
WindowReport report_window(const detail::OutputsWindow& window, const detail::OutputsWindow& first,
                           std::span<const OutputTarget> targets, glm::ivec2 size) {
  WindowReport report;
  glfwGetWindowPos(static_cast<GLFWwindow*>(window.context->native_window()), &report.position.x,
                   &report.position.y);
  report.framebuffer = size;
  for (std::size_t k = 0; k < window.outputs.size(); ++k) {
    const glm::ivec4& v = window.viewports[k];
    const OutputTarget& target = targets[window.outputs[k]];
    if (glm::ivec2(v.z, v.w) != target.size()) {
      report.mismatched_bytes.push_back(-1);  // scaled: not comparable byte for byte
      continue;
    }
    std::vector<std::uint8_t> shown(std::size_t(v.z) * v.w * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(v.x, v.y, v.z, v.w, GL_RGBA, GL_UNSIGNED_BYTE, shown.data());
    first.context->make_current();
    const std::vector<std::uint8_t> expected = target.read_colour_rgba8();
    window.context->make_current();
    long long mismatched = 0;
    for (int y = 0; y < v.w; ++y)
      for (int x = 0; x < v.z; ++x)
        for (int c = 0; c < 3; ++c)
          mismatched += shown[(flipped_row_start(y, v.w, v.z) + x) * 4 + c] !=
                        expected[(std::size_t(y) * v.z + x) * 4 + c];
    report.mismatched_bytes.push_back(mismatched);
  }
  return report;
}

// The --report file's JSON: each window's position, framebuffer and outputs (placement and
// mismatched bytes), the monitor events and the last frame's figures.
nlohmann::json windowed_report(const SessionDisplay& display, std::span<const MonitorInfo> monitors,
                               std::span<const OutputPlacement> placements,
                               std::span<const detail::OutputsWindow> windows,
                               std::span<const WindowReport> reports,
                               const std::vector<std::string>& monitor_events,
                               const FrameStats& last_frame, std::uint64_t scene_rebuilds) {
  nlohmann::json windows_json = nlohmann::json::array();
  for (std::size_t w = 0; w < windows.size(); ++w) {
    nlohmann::json outputs_json = nlohmann::json::array();
    for (std::size_t k = 0; k < windows[w].outputs.size(); ++k) {
      const std::size_t index = windows[w].outputs[k];
      const OutputPlacement& p = placements[index];
      outputs_json.push_back(
          {{"name", display.outputs[index].spec.name},
           {"placement", p.kind == OutputPlacement::Kind::fullscreen ? "fullscreen" : "window"},
           {"how", p.how},
           {"monitor", p.monitor >= 0 ? monitors[std::size_t(p.monitor)].name : ""},
           {"rect", {p.rect.x, p.rect.y, p.rect.z, p.rect.w}},
           {"mismatched_bytes",
            k < reports[w].mismatched_bytes.size() ? reports[w].mismatched_bytes[k] : -1}});
    }
    windows_json.push_back({{"position", {reports[w].position.x, reports[w].position.y}},
                            {"framebuffer", {reports[w].framebuffer.x, reports[w].framebuffer.y}},
                            {"outputs", outputs_json}});
  }
  return {{"windows", windows_json},
          {"monitor_events", monitor_events},
          {"scene_rebuilds", scene_rebuilds},
          {"last_frame", frame_stats_to_json(last_frame)}};
}

}  // namespace

void run_windowed_session(const SessionDisplay& display, const Scene& scene, const CameraPath& path,
                          const WindowRunOptions& options) {
  const std::vector<MonitorInfo> monitors = list_monitors();
  const std::vector<OutputPlacement> placements = detail::place_display_outputs(display, monitors);

  Navigation nav;
  nav.play_path = options.play_path;
  nav.overlay = options.overlay;

  std::vector<detail::OutputsWindow> windows;
  // Until the windows close, also when the run ends by an exception (a lost cluster master).
  monitor_messages = &nav;
  monitor_log = &options.log;
  struct StopMonitorMessages {
    ~StopMonitorMessages() {
      glfwSetMonitorCallback(nullptr);
      monitor_messages = nullptr;
      monitor_log = nullptr;
    }
  } stop_monitor_messages;
  windows =
      detail::open_outputs_windows(placements, options.span, "facet", [&nav](GLFWwindow* native) {
        glfwSetWindowUserPointer(native, &nav);
        glfwSetKeyCallback(native, on_key);
        glfwSetMouseButtonCallback(native, on_mouse_button);
      });
  glfwSetMonitorCallback(on_monitor);
  if (options.log)
    options.log(LogLevel::info, windows_open_line(display, placements, windows.size()));

  windows.front().context->make_current();
  Session session(display, scene);
  if (options.view_dependent_scene)
    session.set_view_dependent_scene(std::make_unique<ViewDependentScene>(
        *options.view_dependent_scene, glm::dvec3(path(0.0)[3])));
  session.set_pattern(options.pattern);
  const detail::WindowPresenter presenter(session.targets());
  const Program overlay_program =
      ProgramBuilder().shader("output/overlay.vert").shader("output/overlay.frag").link();
  for (detail::OutputsWindow& window : windows) {
    window.context->make_current();
    window.vertex_array = VertexArray::create();
  }
  std::vector<Buffer> overlay_vertices(windows.size());  // per window: the overlay's triangles

  std::vector<WindowReport> reports(windows.size());
  double time_s = 0;
  auto last = std::chrono::steady_clock::now();
  double fps = 0;
  FrameStats stats;
  // SIGINT or SIGTERM (after watch_interrupts) closes the windows like Escape, but writes no
  // report: the run ends with Interrupted below.
  std::uint64_t frames_shown = 0, scene_rebuilds = 0;
  int interrupted_by = 0;
  for (std::uint64_t frame = 0; !options.frames || frame < *options.frames; ++frame) {
    if (detail::poll_run_ends(windows, nav.quit, interrupted_by)) break;
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    last = now;
    if (frame > 0) fps = fps == 0 ? 1 / dt : 0.9 * fps + 0.1 / dt;
    const glm::dmat4 T_path = path(time_s);
    steer(nav, static_cast<GLFWwindow*>(windows.front().context->native_window()), dt,
          nav.play_path ? T_path : nav.T_world_eye());
    if (nav.play_path) time_s += options.frames ? kFramePeriod_s : dt;

    windows.front().context->make_current();
    step_patterns(session, nav, options.log);
    FrameState state{frame, time_s, nav.play_path ? T_path : nav.T_world_eye(), {}};
    bool show = true;
    if (options.sync) {
      std::optional<FrameState> next = options.sync->next_frame(state);
      if (!next) break;
      state = std::move(*next);
    }
    // In a cluster the barrier is for rendered outputs: wait for the GPU first.
    stats = session.render(state, options.sync != nullptr);
    scene_rebuilds += stats.scene_rebuilt;
    if (options.sync) {
      nlohmann::json line;
      show = options.sync->ready_to_swap(state, line);
    }
    // The other contexts read the outputs: make the rendering visible to them first.
    GLsync rendered = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();

    const std::string overlay = nav.overlay ? overlay_text(fps, stats, frame) : std::string();
    const bool last_frame = options.frames && frame + 1 == *options.frames;
    // A frame the cluster went on without is not shown.
    for (std::size_t w = 0; show && w < windows.size(); ++w) {
      detail::OutputsWindow& window = windows[w];
      window.context->make_current();
      glWaitSync(rendered, 0, GL_TIMEOUT_IGNORED);
      const glm::ivec2 size = window.context->framebuffer_size();
      presenter.present(size, window.vertex_array, window.outputs, window.viewports);
      if (last_frame && options.report) {
        reports[w] = report_window(window, windows.front(), session.targets(), size);
      }
      if (!overlay.empty()) {
        draw_overlay(overlay_program, window.vertex_array, overlay_vertices[w], overlay, size);
      }
      window.context->swap_buffers();
    }
    windows.front().context->make_current();
    glDeleteSync(rendered);
    frames_shown = frame + 1;
  }

  if (options.report && !interrupted_by) {
    const nlohmann::json report = windowed_report(display, monitors, placements, windows, reports,
                                                  nav.messages, stats, scene_rebuilds);
    write_atomically(*options.report, [&](const fs::path& temporary) {
      std::ofstream(temporary) << report.dump(2) << '\n';
    });
  }
  // Vertex arrays belong to their own context: delete each with its context current.
  for (std::size_t w = 0; w < windows.size(); ++w) {
    windows[w].context->make_current();
    windows[w].vertex_array.reset();
    overlay_vertices[w].reset();
  }
  windows.front().context->make_current();
  if (interrupted_by)
    throw Interrupted(interrupted_by,
                      "stopped after " + std::to_string(frames_shown) + " frames" +
                          (options.report ? "; no report written to " + options.report->string()
                                          : std::string()));
}

}  // namespace facet::driver
