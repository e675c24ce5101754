// Sessions: the frame state as a sendable value, display loading, rendering every output with
// its blend, skipping outputs that see nothing, and the headless runner's files.
#include "facet/driver/session.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>
#include <numbers>

#include "facet/driver/reference.hpp"
#include "facet/driver/session_runner.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "gl_test_context.hpp"
#include "support/files.hpp"

namespace facet::driver {
namespace {

namespace fs = std::filesystem;

// A 20 m square wall facing +z at z = -5 (in front of an eye at the origin looking down -z).
Scene wall_scene() {
  Scene scene;
  scene.name = "wall";
  scene.positions = {{-10, -10, -5}, {10, -10, -5}, {10, 10, -5}, {-10, 10, -5}};
  scene.normals.assign(4, glm::vec3(0, 0, 1));
  scene.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  scene.indices = {0, 1, 2, 0, 2, 3};
  scene.primitives = {{0, 6, 0}};
  Material grey;
  grey.base_colour = {0.5f, 0.5f, 0.5f, 1.0f};
  scene.materials = {grey};
  Object wall;
  wall.name = "wall";
  wall.first_primitive = 0;
  wall.primitive_count = 1;
  scene.objects = {wall};
  scene.update_bounds();
  return scene;
}

Warp looking(double yaw_deg, glm::ivec2 size) {
  const double yaw = glm::radians(yaw_deg);
  const glm::dmat3 R_eye_base(glm::dvec3(std::cos(yaw), 0, -std::sin(yaw)), glm::dvec3(0, 1, 0),
                              glm::dvec3(std::sin(yaw), 0, std::cos(yaw)));
  return Warp::analytic(BaseProjection::perspective(-0.5, 0.5, 0.4, -0.4), size, {2, 2},
                        R_eye_base);
}

TEST(FrameState, RoundTripsThroughJson) {
  FrameState state;
  state.frame = 42;
  state.time_s = 0.7;
  state.T_world_eye = glm::dmat4(1.0);
  state.T_world_eye[3] = glm::dvec4(1.5, 1.7, -3.25, 1.0);
  state.T_world_eye[0][1] = 0.125;
  EXPECT_EQ(
      frame_state_from_json(nlohmann::json::parse(frame_state_to_json(state).dump()), "state"),
      state);
  ObjectPose moved;
  moved.object = 3;
  moved.T_world_object[3] = glm::dvec4(-2.0, 0.5, 7.0, 1.0);
  moved.T_world_object[1][0] = 0.25;
  state.object_poses = {moved, ObjectPose{}};
  const nlohmann::json json = frame_state_to_json(state);
  ASSERT_EQ(json["object_poses"].size(), 2u);
  EXPECT_EQ(frame_state_from_json(nlohmann::json::parse(json.dump()), "state"), state);
}

TEST(FrameState, RejectsBadObjectPoses) {
  FrameState state;
  state.object_poses = {ObjectPose{}, ObjectPose{}};
  const auto message = [](const nlohmann::json& json) {
    try {
      frame_state_from_json(json, "broadcast");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(frame_state_to_json(state)).find("listed twice"), std::string::npos);
  state.object_poses[1].object = 1;
  nlohmann::json json = frame_state_to_json(state);
  EXPECT_EQ(message(json), "no error");
  json["object_poses"][1]["object"] = -1;
  EXPECT_NE(message(json).find("object_poses[1].object"), std::string::npos) << message(json);
  json = frame_state_to_json(state);
  json["object_poses"][0]["T_world_object"][3][0] = 0.5;  // projective, not affine
  EXPECT_NE(message(json).find("object_poses[0].T_world_object[3]"), std::string::npos);
  json = frame_state_to_json(state);
  json["object_poses"][0].erase("T_world_object");
  EXPECT_NE(message(json).find("object_poses[0].T_world_object"), std::string::npos);
  json = frame_state_to_json(state);
  json["object_poses"] = 7;
  EXPECT_NE(message(json).find("object_poses"), std::string::npos);
}

TEST(FrameState, RejectsMalformedValues) {
  nlohmann::json json = frame_state_to_json(FrameState{});
  json["T_world_eye"][2][1] = "x";
  try {
    frame_state_from_json(json, "broadcast");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("T_world_eye[2][1]"), std::string::npos) << e.what();
  }
  json = frame_state_to_json(FrameState{});
  json.erase("time_s");
  EXPECT_THROW(frame_state_from_json(json, "broadcast"), InputError);
}

// A cube of side `side` metres centred on its object frame's origin, faces outwards, appended to
// `scene` as one object with its own material.
void add_cube(Scene& scene, const std::string& name, float side, const glm::mat4& T_world_object) {
  const float h = side / 2;
  const std::uint32_t first_index = std::uint32_t(scene.indices.size());
  const glm::vec3 normals[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  for (const glm::vec3& n : normals) {
    // Two axes u, w across the face with u × w = n, so corners run counter-clockwise from outside.
    const glm::vec3 u = std::abs(n.x) > 0 ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 w = glm::cross(n, u);
    const auto base = std::uint32_t(scene.positions.size());
    for (const glm::vec2& c :
         {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
      scene.positions.push_back(h * (n + c.x * u + c.y * w));
      scene.normals.push_back(n);
      scene.uvs.push_back(0.5f * (c + 1.0f));
    }
    for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) scene.indices.push_back(base + k);
  }
  scene.materials.push_back({});
  scene.primitives.push_back({first_index, 36, std::uint32_t(scene.materials.size() - 1)});
  Object object;
  object.name = name;
  object.T_world_object = T_world_object;
  object.first_primitive = std::uint32_t(scene.primitives.size() - 1);
  object.primitive_count = 1;
  scene.objects.push_back(object);
  scene.update_bounds();
}

// A cube circling the zenith of the 180° dome (45° up, turning about itself as it goes), one the
// scene's animation slides overhead, and a still one: every frame the session draws both where the
// exact ray cast sees them, coverage runs again whenever the cube moves, and is reused while
// nothing moves.
TEST(Session, MovingObjectIsDrawnWhereTheReferenceSeesIt) {
  test::shared_context();
  Scene scene;
  scene.name = "orbit";
  add_cube(scene, "still", 1.5f, glm::translate(glm::mat4(1.0f), glm::vec3(0, 4, -2)));
  add_cube(scene, "moving", 1.0f, glm::mat4(1.0f));  // at the eye until posed: never drawn there
  // A third cube the scene's own animation slides from x = -3 to 3 m over 2 s, 4 m up.
  add_cube(scene, "animated", 1.0f, glm::mat4(1.0f));
  AnimationChannel slide;
  slide.node = 0;
  slide.times_s = {0, 2};
  slide.values = {-3, 4, 1, 3, 4, 1};
  scene.animation.nodes = {AnimationNode{}};
  scene.animation.object_node = {-1, -1, 0};
  scene.animation.clips = {AnimationClip{"slide", 2.0, {slide}}};
  Session session(load_session_display("builtin:dome180", glm::ivec2(128, 128)), scene);
  const Warp& warp = session.display().outputs[0].spec.warp;
  const WarpInverse inverse(warp);
  double worst_mismatch = 0;
  for (int frame = 0; frame < 6; ++frame) {
    const double angle = frame * 0.7;
    FrameState state;
    state.frame = std::uint64_t(frame);
    state.time_s = frame * 0.3;
    ObjectPose pose;
    pose.object = 1;
    pose.T_world_object = glm::rotate(
        glm::translate(glm::dmat4(1.0), glm::dvec3(3 * std::cos(angle), 3, 3 * std::sin(angle))),
        2 * angle, glm::dvec3(0.3, 1, 0.2));
    state.object_poses = {pose};
    const FrameStats stats = session.render(state, true);
    ASSERT_TRUE(stats.outputs[0].rendered);
    EXPECT_FALSE(stats.outputs[0].render.reused_replication) << "frame " << frame;
    // The moved object's world box holds its moved vertices.
    for (std::uint32_t i = scene.primitives[1].first_index;
         i < scene.primitives[1].first_index + 36; ++i) {
      const glm::vec3 p_world(session.scene().objects[1].T_world_object *
                              glm::vec4(scene.positions[scene.indices[i]], 1.0f));
      ASSERT_TRUE(session.scene().objects[1].bounds_world.contains(p_world, 1e-4f));
    }
    EXPECT_NEAR(session.scene().objects[2].T_world_object[3].x, -3 + 3 * state.time_s, 1e-5);
    const std::vector<std::uint32_t> tested = session.targets()[0].read_ids();
    const std::vector<std::uint32_t> reference =
        ReferenceRaycaster(session.scene()).ids(inverse, glm::dmat4(1.0));
    const IdComparison comparison = compare_ids(reference, tested, warp.output_size);
    // Both cubes in view, the moving one (IDs 13..24) where the reference puts it.
    const auto shows = [](const std::vector<std::uint32_t>& ids, std::uint32_t low,
                          std::uint32_t high) {
      return std::count_if(ids.begin(), ids.end(),
                           [&](std::uint32_t id) { return id >= low && id <= high; });
    };
    EXPECT_GT(shows(reference, 13, 24), 20) << "frame " << frame;
    EXPECT_GT(shows(reference, 1, 12), 20) << "frame " << frame;
    EXPECT_GT(shows(reference, 25, 36), 20) << "frame " << frame;
    EXPECT_LE(comparison.id_mismatch, 0.002)
        << "frame " << frame << ": " << comparison.mismatched_pixels << " of "
        << comparison.compared_pixels << " pixels";
    worst_mismatch = std::max(worst_mismatch, comparison.id_mismatch);
  }
  std::printf("moving cube, 6 frames on dome180 128x128: worst id_mismatch %.5f\n", worst_mismatch);
  // The same state again: nothing moved, coverage is reused. Back to the scene's own pose: moved.
  FrameState still;
  still.object_poses = {{1, glm::translate(glm::dmat4(1.0), glm::dvec3(0, 3, 3))}};
  EXPECT_FALSE(session.render(still, true).outputs[0].render.reused_replication);
  EXPECT_TRUE(session.render(still, true).outputs[0].render.reused_replication);
  EXPECT_FALSE(session.render(FrameState{}, true).outputs[0].render.reused_replication);
  EXPECT_EQ(session.scene().objects[1].T_world_object, glm::mat4(1.0f));
  // The animation moves the third cube over time: a new time alone reruns coverage.
  FrameState later;
  later.time_s = 0.5;
  EXPECT_FALSE(session.render(later, true).outputs[0].render.reused_replication);
  EXPECT_TRUE(session.render(later, true).outputs[0].render.reused_replication);
  // Poses of objects the scene lacks, or twice, render nothing and say which.
  FrameState bad;
  bad.object_poses = {{3, glm::dmat4(1.0)}};
  EXPECT_THROW(session.render(bad), InputError);
  bad.object_poses = {{0, glm::dmat4(1.0)}, {0, glm::dmat4(1.0)}};
  EXPECT_THROW(session.render(bad), InputError);
}

TEST(SessionDisplay, BuiltinsGetOneWindowAndNoBlend) {
  const SessionDisplay display = load_session_display("builtin:cylinder360", glm::ivec2(320, 240));
  ASSERT_EQ(display.outputs.size(), 1u);
  EXPECT_EQ(display.outputs[0].spec.warp.output_size, glm::ivec2(320, 240));
  EXPECT_TRUE(display.outputs[0].blend.alpha.empty());
  EXPECT_FALSE(display.outputs[0].encoding.gamma.has_value());
  EXPECT_THROW(load_session_display("builtin:nothing"), InputError);
}

// A display.json with two projectors: "front" looks at the wall, "back" the other way.
fs::path write_two_projector_display(const fs::path& folder, bool with_blend) {
  const glm::ivec2 size(64, 48);
  projection_io::DisplayConfig config;
  config.name = "two";
  for (const auto& [name, yaw] : {std::pair<std::string, double>{"front", 0.0}, {"back", 180.0}}) {
    write_warp((folder / (name + ".warp.exr")).string(), looking(yaw, size));
    projection_io::DisplayProjector projector;
    projector.name = name;
    projector.size = size;
    projector.warp = name + ".warp.exr";
    projector.output.kind = projection_io::DisplayOutput::Kind::window;
    projector.output.window = {0, 0, size.x, size.y};
    projector.gamma = 2.2;
    if (with_blend) {
      // Left half weight 1, right half 0.5.
      projection_io::BlendMap alpha = projection_io::BlendMap::constant(size, 1.0f);
      for (int y = 0; y < size.y; ++y)
        for (int x = size.x / 2; x < size.x; ++x) alpha.at(x, y) = 0.5f;
      projection_io::write_blend_map((folder / (name + ".blend.exr")).string(), alpha);
      projector.blend = name + ".blend.exr";
    }
    config.projectors.push_back(projector);
  }
  config.render.tolerance_px = 0.25;
  const fs::path path = folder / "display.json";
  projection_io::write_display_config(config, path);
  return path;
}

TEST(Session, RendersOutputsThatSeeTheSceneAndSkipsTheOthers) {
  test::shared_context();
  const fs::path folder = facet::test::fresh_folder("facet_session_test_skip");
  SessionDisplay display =
      load_session_display(write_two_projector_display(folder, false).string());
  const Scene scene = wall_scene();
  Session session(display, scene);
  EXPECT_TRUE(session.output_sees_scene(0, glm::dmat4(1.0)));
  EXPECT_FALSE(session.output_sees_scene(1, glm::dmat4(1.0)));
  const FrameStats stats = session.render(FrameState{}, true);
  ASSERT_EQ(stats.outputs.size(), 2u);
  EXPECT_TRUE(stats.outputs[0].rendered);
  EXPECT_GT(stats.outputs[0].render.replicas, 0u);
  EXPECT_FALSE(stats.outputs[1].rendered);
  // The front output is all wall; the back one stays black.
  const auto front = session.targets()[0].read_colour_rgba8();
  const auto back = session.targets()[1].read_colour_rgba8();
  const auto front_ids = session.targets()[0].read_ids();
  for (std::uint32_t id : front_ids) ASSERT_NE(id, 0u);
  for (std::size_t i = 0; i < back.size(); i += 4) ASSERT_EQ(back[i], 0);
  // Turned around, the roles swap.
  FrameState turned;
  turned.T_world_eye = glm::dmat4(glm::dmat3(-1, 0, 0, 0, 1, 0, 0, 0, -1));
  const FrameStats turned_stats = session.render(turned, true);
  EXPECT_FALSE(turned_stats.outputs[0].rendered);
  EXPECT_TRUE(turned_stats.outputs[1].rendered);
}

TEST(Session, BlendsInLinearLightAfterRendering) {
  test::shared_context();
  const fs::path plain_folder = facet::test::fresh_folder("facet_session_test_plain"),
                 blend_folder = facet::test::fresh_folder("facet_session_test_blend");
  const Scene scene = wall_scene();
  Session plain(load_session_display(write_two_projector_display(plain_folder, false).string()),
                scene);
  Session blended(load_session_display(write_two_projector_display(blend_folder, true).string()),
                  scene);
  // Both displays encode with gamma 2.2; the plain one has weight 1.
  plain.render(FrameState{}, true);
  const FrameStats stats = blended.render(FrameState{}, true);
  EXPECT_GT(stats.outputs[0].blend_tiles, 0u);
  const auto a = plain.targets()[0].read_colour_rgba8();
  const auto b = blended.targets()[0].read_colour_rgba8();
  const glm::ivec2 size = plain.targets()[0].size();
  double worst_left = 0, worst_right = 0;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const std::size_t p = (std::size_t(y) * size.x + x) * 4;
      // Decode with gamma 2.2 (the projector's encoding) and compare the light.
      const double light_a = std::pow(a[p] / 255.0, 2.2), light_b = std::pow(b[p] / 255.0, 2.2);
      if (x < size.x / 2)
        worst_left = std::max(worst_left, std::abs(light_b - light_a));
      else
        worst_right = std::max(worst_right, std::abs(light_b - 0.5 * light_a));
    }
  }
  // One 8-bit level of a mid-grey under gamma 2.2 is about 0.005 in linear light.
  EXPECT_LE(worst_left, 0.006);
  EXPECT_LE(worst_right, 0.006);
}

TEST(HeadlessRun, WritesFramesPerOutputAndStatistics) {
  test::shared_context();
  const fs::path folder = facet::test::fresh_folder("facet_session_test_headless");
  const Scene scene = wall_scene();
  Session session(load_session_display(write_two_projector_display(folder, false).string()), scene);
  const fs::path out = folder / "run";
  HeadlessRunOptions options;
  options.frames = 3;
  options.out_dir = out;
  const CameraPath still = [](double) { return glm::dmat4(1.0); };
  const HeadlessRunResult result = run_headless_session(session, still, options);
  EXPECT_EQ(result.frames, 3u);
  EXPECT_EQ(result.images_written, 6u);
  for (const char* file : {"front/00000.png", "front/00002.png", "back/00001.png", "stats.jsonl"})
    EXPECT_TRUE(fs::exists(out / file)) << file;
  std::ifstream stats(out / "stats.jsonl");
  int lines = 0;
  for (std::string line; std::getline(stats, line); ++lines) {
    const nlohmann::json frame = nlohmann::json::parse(line);
    EXPECT_EQ(frame["frame"], lines);
    EXPECT_EQ(frame["outputs"].size(), 2u);
    EXPECT_TRUE(frame.contains("replication_ratio"));
  }
  EXPECT_EQ(lines, 3);
  // A second run replaces the first; a folder that is not a run is refused and left alone.
  EXPECT_NO_THROW(run_headless_session(session, still, options));
  const fs::path foreign = folder / "foreign";
  fs::create_directories(foreign);
  std::ofstream(foreign / "keep.txt") << "mine";
  options.out_dir = foreign;
  EXPECT_THROW(run_headless_session(session, still, options), InputError);
  EXPECT_TRUE(fs::exists(foreign / "keep.txt"));
  EXPECT_FALSE(fs::exists(foreign / "stats.jsonl"));
  // A stats.jsonl does not make a folder a run: anything else in it keeps it from being replaced,
  // beside the frames or among them.
  std::ofstream(foreign / "stats.jsonl") << "{}\n";
  EXPECT_THROW(run_headless_session(session, still, options), InputError);
  EXPECT_TRUE(fs::exists(foreign / "keep.txt"));
  std::ofstream(out / "front" / "notes.txt") << "mine";
  options.out_dir = out;
  EXPECT_THROW(run_headless_session(session, still, options), InputError);
  EXPECT_TRUE(fs::exists(out / "front" / "notes.txt"));
  fs::remove(out / "front" / "notes.txt");
  // "run/" is "run"; the current folder and its parents are refused, as are 0 frames and more
  // than kMaxFrames, before anything is written.
  options.out_dir = out.string() + "/";
  EXPECT_NO_THROW(run_headless_session(session, still, options));
  EXPECT_TRUE(fs::exists(out / "stats.jsonl"));
  const fs::path before = fs::current_path();
  fs::current_path(out / "front");
  for (const char* here : {".", "..", "../"}) {
    options.out_dir = here;
    EXPECT_THROW(run_headless_session(session, still, options), InputError) << here;
  }
  fs::current_path(before);
  EXPECT_TRUE(fs::exists(out / "front" / "00000.png"));
  // Nor may it replace a folder holding a file the run reads, such as a frame shown as content.
  options.out_dir = out;
  options.inputs = {out / "front" / "00000.png"};
  EXPECT_THROW(run_headless_session(session, still, options), InputError);
  EXPECT_TRUE(fs::exists(out / "front" / "00000.png"));
  options.inputs.clear();
  options.out_dir = folder / "counted";
  for (const std::uint64_t frames : {std::uint64_t(0), kMaxFrames + 1}) {
    options.frames = frames;
    EXPECT_THROW(run_headless_session(session, still, options), InputError) << frames;
    EXPECT_FALSE(fs::exists(options.out_dir)) << frames;
  }
  // Nothing of the runs is left beside them.
  for (const fs::directory_entry& entry : fs::directory_iterator(folder))
    EXPECT_NE(entry.path().filename().string().front(), '.') << entry.path();
}

// The byte of sRGB-encoded linear value c in [0, 1].
int srgb_byte(double c) {
  const double e = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
  return int(std::lround(e * 255));
}

// Test patterns replace the scene: latlong's lines land where the exact warp puts their
// directions (a 30° crossing white, the front meridian red, the middle of a 10° cell black);
// white goes through the blend, so each pixel shows its blend weight; T steps back to the scene.
TEST(SessionPatterns, LatlongFollowsTheWarpAndWhiteShowsTheBlend) {
  test::shared_context();
  SessionDisplay dome = load_session_display("builtin:dome180", glm::ivec2(256, 256));
  const Warp warp = dome.outputs[0].spec.warp;
  Session session(std::move(dome), wall_scene());
  session.set_pattern(TestPattern::latlong);
  session.render(FrameState{});
  const std::vector<std::uint8_t> rgba = session.targets()[0].read_colour_rgba8();
  auto pixel_at = [&](double elevation_deg, double azimuth_deg) {
    const double e = elevation_deg * std::numbers::pi / 180,
                 a = azimuth_deg * std::numbers::pi / 180;
    const glm::dvec3 v{std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
    const auto projected = warp.project(v);
    EXPECT_TRUE(projected && projected->covered) << elevation_deg << ", " << azimuth_deg;
    const glm::ivec2 q = glm::ivec2(glm::floor(projected->q));
    const std::uint8_t* p = &rgba[(std::size_t(q.y) * 256 + std::size_t(q.x)) * 4];
    return glm::ivec3(p[0], p[1], p[2]);
  };
  EXPECT_EQ(pixel_at(30, 60), glm::ivec3(255, 255, 255));
  EXPECT_EQ(pixel_at(45, 0), glm::ivec3(255, 0, 0));
  EXPECT_EQ(pixel_at(35, 25), glm::ivec3(0, 0, 0));
  EXPECT_EQ(pixel_at(55, -115), glm::ivec3(0, 0, 0));

  SessionDisplay wall = load_session_display("builtin:wall2x2", glm::ivec2(96, 64));
  const BlendMaps blend = wall.outputs[0].blend;
  ASSERT_FALSE(blend.alpha.empty());
  Session walls(std::move(wall), wall_scene());
  walls.set_pattern(TestPattern::white);
  walls.render(FrameState{});
  const std::vector<std::uint8_t> white = walls.targets()[0].read_colour_rgba8();
  int below_one = 0;
  for (int y = 0; y < 64; y += 3)
    for (int x = 0; x < 96; x += 3) {
      const double alpha = blend.alpha[std::size_t(y) * 96 + std::size_t(x)];
      below_one += alpha < 0.99;
      EXPECT_NEAR(white[(std::size_t(y) * 96 + std::size_t(x)) * 4], srgb_byte(alpha), 1)
          << x << ", " << y << ": alpha " << alpha;
    }
  EXPECT_GT(below_one, 10);
  walls.set_pattern(std::nullopt);
  EXPECT_FALSE(walls.pattern());
}

}  // namespace
}  // namespace facet::driver
