#pragma once
// An immersive session: one shared scene rendered every frame into every projector output of a
// display, followed by each output's blend and black-level pass. The same Session drives the
// headless runner (EGL, frames to files) and the windowed one (a GLFW window per projector).
//
// Cluster-ready: everything a frame depends on is the small value FrameState, so one node can
// broadcast it and every node render its own outputs from it.
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "facet/driver/blend_pass.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/driver/scene.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/projection/test_pattern.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::driver {

struct SessionOutput {
  OutputSpec spec;  // name and exact warp
  BlendMaps blend;  // empty maps: weight 1 and black level 0 everywhere
  OutputEncoding encoding;
  projection_io::DisplayOutput placement;  // where a windowed session shows it
};

// What a session shows: the outputs with their blends, and how to render them.
struct SessionDisplay {
  std::string source;  // the display argument, for messages
  std::vector<SessionOutput> outputs;
  std::string method = "facets";
  RenderSettings settings;
  projection_io::MissingMonitor missing_monitor = projection_io::MissingMonitor::window;
  // The display.json as read, when the display is one: what else needs it (a cluster node's
  // section) takes it from here rather than reading the file again.
  std::optional<projection_io::DisplayConfig> config;
};

// Loads a display the way `facet render` names it (see load_display_outputs): a built-in, a
// .warp.exr, or a display.json, whose blend and black maps, gammas, outputs, render method and
// tolerance are used too. Built-ins and warp files get one window each, side by side, and sRGB
// encoding; builtin:wall2x2 blends its overlaps, the others have no blend. `size` overrides a
// built-in's output size. A display.json is read once, and kept in SessionDisplay::config.
// Throws InputError for bad input.
SessionDisplay load_session_display(std::string_view display,
                                    std::optional<glm::ivec2> size = std::nullopt);

// A preview at a fraction of the resolution: every output's size and warp offsets scaled by
// `factor` (0 < factor <= 1; sizes rounded, at least 1 pixel), blend and black maps sampled at the
// nearest pixel. The geometry stays exact up to the rounding of the output size.
void scale_session_display(SessionDisplay& display, double factor);

// Writes `display` as a display.json folder (warps, blends, black levels, display.json) through
// write_folder_atomically: `folder` must not exist yet or be empty (InputError naming --out).
void write_session_display(const SessionDisplay& display, const std::string& name,
                           const std::filesystem::path& folder);

// The most object poses one FrameState may carry (the JSON reader refuses more).
inline constexpr std::size_t kMaxObjectPoses = std::size_t(1) << 20;

// The whole state one frame depends on.
struct FrameState {
  std::uint64_t frame = 0;
  double time_s = 0;            // scene time, seconds
  glm::dmat4 T_world_eye{1.0};  // eye pose: eye-frame points into the world frame (metres)
  // The objects that stand elsewhere than the scene places them (ObjectPose, animation.hpp),
  // each at most once, in any order. An object not listed stands where the scene itself puts it
  // at time_s: its node animation (Scene::animation, looping) where it has one, else
  // Object::T_world_object as loaded or built. So every FrameState is complete on its own: a node
  // that missed earlier frames renders this one right.
  std::vector<ObjectPose> object_poses;

  bool operator==(const FrameState&) const = default;
};
nlohmann::json frame_state_to_json(const FrameState& state);
// Throws InputError(source, field, ...) for a malformed value.
FrameState frame_state_from_json(const nlohmann::json& value, const std::string& source);

struct OutputFrameStats {
  std::string name;
  bool rendered = false;  // false: no object can be seen by this output, so it was only cleared
  RenderStats render;
  std::size_t blend_tiles = 0;  // tiles the blend pass touched
};

struct FrameStats {
  std::uint64_t frame = 0;
  double time_s = 0;
  double cpu_ms = 0;  // wall time of Session::render on the CPU, including glFinish when asked
  // With a view-dependent scene: whether this frame's eye rebuilt it (set_view_dependent_scene).
  bool scene_rebuilt = false;
  std::vector<OutputFrameStats> outputs;
  std::vector<PassTime> pass_ms;  // GPU time per pass summed over outputs, from an earlier frame

  std::uint64_t triangles_in() const;
  std::uint64_t replicas() const;
  double replication_ratio() const;
};
nlohmann::json frame_stats_to_json(const FrameStats& stats);

class Session {
 public:
  // Uploads the scene and prepares one renderer per output. Needs a current GL context, which
  // must stay current (on this thread) for the session's life. The session keeps its own copy of
  // the scene (move one in to avoid the copy), whose object poses each frame state sets.
  Session(SessionDisplay display, Scene scene);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Places every object (state.object_poses, else the scene's animation at state.time_s, else
  // the scene's own pose), renders every output
  // that can see part of the scene, then blends every output. With `finish`, waits for the GPU
  // so that cpu_ms is the frame's full time. InputError("frame state", ...) for a pose of an
  // object the scene does not have, or of one object twice; nothing is rendered then.
  FrameStats render(const FrameState& state, bool finish = false);

  // From the next render on, the scene is `scene`'s (which replaces the one given): each frame
  // first updates it for the frame's eye (ViewDependentScene::update), and where it is rebuilt
  // replaces the GPU buffers and every output's method state (RenderMethod::replace_scene).
  void set_view_dependent_scene(std::unique_ptr<ViewDependentScene> scene);

  // Shows `pattern` on every output instead of the scene from the next render on (nullopt: the
  // scene again). The images are drawn once here (latlong inverts every output's warp); blended
  // patterns then go through each output's blend and black-level pass as the scene does.
  void set_pattern(std::optional<TestPattern> pattern);
  std::optional<TestPattern> pattern() const { return pattern_; }

  const SessionDisplay& display() const { return display_; }
  // The scene with the objects where the last render placed them.
  const Scene& scene() const { return scene_; }
  std::span<const OutputTarget> targets() const { return targets_; }

  // Whether any object's bounds meet the directions output `index` covers, seen from the eye
  // pose T_world_eye. Conservative: false only when the output cannot see anything.
  bool output_sees_scene(std::size_t index, const glm::dmat4& T_world_eye) const;

 private:
  struct CoverageCone {
    glm::dvec3 axis{0, 0, -1};  // eye frame, unit
    double half_angle = 0;      // radians; >= pi covers every direction
  };

  // Sets every object's T_world_object and bounds_world for `poses`, then `animated` for the
  // objects `poses` leaves out (see render).
  void place_objects(const std::vector<ObjectPose>& poses, const std::vector<ObjectPose>& animated);

  // An object's pose as the scene was given, and its object-frame box (computed the first time
  // the object is moved).
  struct RestPose {
    glm::mat4 T_world_object{1.0f};
    Aabb bounds_world;
    std::optional<Aabb> bounds_object;
  };

  // Replaces the scene (the same objects, materials and images: a view-dependent one rebuilt).
  void replace_scene(const Scene& scene);

  SessionDisplay display_;
  Scene scene_;
  std::unique_ptr<ViewDependentScene> view_dependent_;
  std::vector<RestPose> rest_poses_;
  GpuScene gpu_scene_;
  std::vector<std::unique_ptr<RenderMethod>> methods_;
  std::vector<OutputTarget> targets_;
  std::vector<BlendPass> blends_;
  std::vector<CoverageCone> cones_;
  GpuTimer timer_;
  std::vector<PassTime> last_pass_ms_;
  std::optional<TestPattern> pattern_;
  std::vector<std::vector<std::uint8_t>> pattern_rows_up_;  // per output, sRGB RGBA8, GL row order
};

}  // namespace facet::driver
