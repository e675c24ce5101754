// glTF loading: a tiny file written here (a .gltf with its buffer embedded as base64) loads with
// the right counts, transforms, materials, cameras and bounds; malformed files give InputError
// naming the file. The view of a scene (scene_view.hpp): the default eye leaves closed geometry,
// --eye inside it warns, --look-at and --camera set the pose.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "facet/driver/gltf_loader.hpp"
#include "facet/driver/reference.hpp"
#include "facet/driver/scene_view.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

namespace fs = std::filesystem;

std::string base64(const std::vector<unsigned char>& bytes) {
  static constexpr char alphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = bytes[i];
    const std::uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0u;
    const std::uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0u;
    const std::uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += alphabet[(triple >> 18) & 63];
    out += alphabet[(triple >> 12) & 63];
    out += i + 1 < bytes.size() ? alphabet[(triple >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[triple & 63] : '=';
  }
  return out;
}

template <class T>
void append(std::vector<unsigned char>& out, const T& value) {
  const auto* p = reinterpret_cast<const unsigned char*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

class TempDir {
 public:
  TempDir() {
    path_ = facet::test_paths::scratch_path(
        std::string("facet_gltf_test_") +
        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }

 private:
  fs::path path_;
};

// A unit square in the x-y plane (two triangles, 16-bit indices, positions and texture
// coordinates, no normals) instanced by two nodes: one at the origin, and one translated by
// (10, 0, 0) under a parent scaled by 2. `index_override` replaces the index data when set.
std::vector<unsigned char> square_buffer(const std::array<std::uint16_t, 6>& indices) {
  std::vector<unsigned char> buffer;
  const float positions[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const float uvs[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  for (const auto& p : positions)
    for (const float v : p) append(buffer, v);
  for (const auto& t : uvs)
    for (const float v : t) append(buffer, v);
  for (const auto i : indices) append(buffer, i);
  buffer.resize(buffer.size() + 2, 0);  // pad to a multiple of 4
  return buffer;
}

// With `buffer_uri` empty, the buffer is embedded as a data URI.
std::string square_gltf(std::array<std::uint16_t, 6> indices = {0, 1, 2, 0, 2, 3},
                        const std::string& buffer_uri = {}) {
  const std::vector<unsigned char> buffer = square_buffer(indices);
  const std::string uri =
      buffer_uri.empty() ? "data:application/octet-stream;base64," + base64(buffer) : buffer_uri;
  return R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 1]}],
  "nodes": [
    {"name": "first", "mesh": 0},
    {"name": "parent", "scale": [2, 2, 2], "children": [2]},
    {"name": "second", "mesh": 0, "translation": [10, 0, 0]}
  ],
  "meshes": [{"primitives": [{
    "attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
  "materials": [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
     "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 32},
    {"buffer": 0, "byteOffset": 80, "byteLength": 12}
  ],
  "buffers": [{"byteLength": )" +
         std::to_string(buffer.size()) + R"(, "uri": ")" + uri + R"("}]
})";
}

// External buffers are read from the glTF file's folder or below it, as regular files, and URIs
// are taken as written: a path leading out of the folder (by "..", an absolute path or a link),
// a FIFO (which would block the reader) and "~" are refused, naming the URI.
TEST(Gltf, ExternalFilesStayInTheGltfFilesFolder) {
  TempDir dir;
  const auto bytes = square_buffer({0, 1, 2, 0, 2, 3});
  const fs::path folder = dir.write("outside.bin", "").parent_path() / "model";
  fs::create_directories(folder);
  std::ofstream(folder / "square.bin", std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  std::ofstream(folder.parent_path() / "outside.bin", std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  fs::create_directories(folder / "sub");
  fs::copy_file(folder / "square.bin", folder / "sub" / "square.bin");
  fs::create_symlink(folder.parent_path() / "outside.bin", folder / "link.bin");
  ASSERT_EQ(::mkfifo((folder / "fifo.bin").c_str(), 0600), 0);
  for (const std::string& uri :
       std::vector<std::string>{"square.bin", "sub/square.bin", "./sub/../square.bin"}) {
    const Scene scene = load_gltf(dir.write("model/" + std::to_string(uri.size()) + ".gltf",
                                            square_gltf({0, 1, 2, 0, 2, 3}, uri)));
    EXPECT_EQ(scene.indices.size(), 6u) << uri;
  }
  const std::string outside = (folder.parent_path() / "outside.bin").string();
  for (const std::string& uri : {std::string("../outside.bin"), outside, std::string("link.bin"),
                                 std::string("fifo.bin"), std::string("~/square.bin")}) {
    const fs::path file = dir.write("model/bad.gltf", square_gltf({0, 1, 2, 0, 2, 3}, uri));
    try {
      load_gltf(file);
      ADD_FAILURE() << uri << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(uri), std::string::npos) << e.what();
    }
  }
}

TEST(Gltf, LoadsCountsTransformsAndBounds) {
  TempDir dir;
  const Scene scene = load_gltf(dir.write("square.gltf", square_gltf()));
  EXPECT_EQ(scene.name, "square");
  EXPECT_EQ(scene.positions.size(), 4u);  // shared by both instances
  EXPECT_EQ(scene.indices.size(), 6u);
  ASSERT_EQ(scene.primitives.size(), 1u);
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.triangle_count(), 4u);  // two instances of two triangles
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].name, "red");
  EXPECT_EQ(scene.materials[0].base_colour, glm::vec4(1, 0, 0, 1));
  EXPECT_EQ(scene.materials[0].texture, -1);
  EXPECT_EQ(scene.primitives[0].material, 0u);

  // Missing normals are computed: the square faces +z (counter-clockwise from +z).
  for (const auto& n : scene.normals)
    EXPECT_NEAR(glm::distance(n, glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
  EXPECT_EQ(scene.uvs[0], glm::vec2(0, 1));

  const Object& first = scene.objects[0];
  const Object& second = scene.objects[1];
  EXPECT_EQ(first.name, "first");
  EXPECT_EQ(second.name, "second");
  EXPECT_EQ(second.first_primitive, first.first_primitive);
  // Bounds in metres, exact for these transforms: [0,1]^2 and 2 * ([10,11] x [0,1]).
  EXPECT_EQ(first.bounds_world.p_min, glm::vec3(0, 0, 0));
  EXPECT_EQ(first.bounds_world.p_max, glm::vec3(1, 1, 0));
  EXPECT_EQ(second.bounds_world.p_min, glm::vec3(20, 0, 0));
  EXPECT_EQ(second.bounds_world.p_max, glm::vec3(22, 2, 0));
  EXPECT_EQ(second.T_world_object * glm::vec4(1, 1, 0, 1), glm::vec4(22, 2, 0, 1));
}

void expect_input_error(const fs::path& file, const std::string& field_part) {
  try {
    load_gltf(file);
    ADD_FAILURE() << "expected InputError for " << file;
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), file.string());
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(e.field().find(field_part), std::string::npos) << e.what();
  }
}

// square_gltf with one animation over keys at 0, 1 and 2 s: node "first" jumps (STEP) to
// x = 5 m for the second second, and node "parent" turns (LINEAR) about +y by 90° a second,
// carrying "second" with it. `interpolation` replaces the rotation sampler's.
std::string animated_square_gltf(const std::string& interpolation = "LINEAR") {
  std::string text = square_gltf();
  std::vector<unsigned char> buffer;
  for (const float t : {0.0f, 1.0f, 2.0f}) append(buffer, t);
  for (const float x : {0.0f, 5.0f, 0.0f})
    for (const float v : {x, 0.0f, 0.0f}) append(buffer, v);
  const float s = std::sqrt(0.5f);
  const float rotations[3][4] = {{0, 0, 0, 1}, {0, s, 0, s}, {0, 1, 0, 0}};
  for (const auto& q : rotations)
    for (const float v : q) append(buffer, v);
  nlohmann::json gltf = nlohmann::json::parse(text);
  gltf["buffers"].push_back({{"byteLength", buffer.size()},
                             {"uri", "data:application/octet-stream;base64," + base64(buffer)}});
  gltf["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 0}, {"byteLength", 12}});
  gltf["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 12}, {"byteLength", 36}});
  gltf["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 48}, {"byteLength", 48}});
  gltf["accessors"].push_back({{"bufferView", 3},
                               {"componentType", 5126},
                               {"count", 3},
                               {"type", "SCALAR"},
                               {"min", {0}},
                               {"max", {2}}});
  gltf["accessors"].push_back(
      {{"bufferView", 4}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  gltf["accessors"].push_back(
      {{"bufferView", 5}, {"componentType", 5126}, {"count", 3}, {"type", "VEC4"}});
  const auto channel = [](int sampler, int node, const char* path) {
    return nlohmann::json{{"sampler", sampler}, {"target", {{"node", node}, {"path", path}}}};
  };
  gltf["animations"] = {
      {{"name", "turn"},
       {"channels",
        {channel(0, 0, "translation"), channel(1, 1, "rotation"), channel(1, 1, "weights")}},
       {"samplers",
        {{{"input", 3}, {"output", 4}, {"interpolation", "STEP"}},
         {{"input", 3}, {"output", 5}, {"interpolation", interpolation}}}}}};
  return gltf.dump(1);
}

// The pose of object `o` at `time_s`, or nothing when the animation does not move it.
std::optional<glm::dmat4> pose_at(const Scene& scene, std::uint32_t o, double time_s) {
  for (const ObjectPose& pose : animated_object_poses(scene.animation, time_s))
    if (pose.object == o) return pose.T_world_object;
  return std::nullopt;
}

TEST(Gltf, NodeAnimationsMoveTheirObjectsAndLoop) {
  TempDir dir;
  const Scene scene = load_gltf(dir.write("animated.gltf", animated_square_gltf()));
  ASSERT_EQ(scene.animation.clips.size(), 1u);
  EXPECT_EQ(scene.animation.clips[0].name, "turn");
  EXPECT_EQ(scene.animation.clips[0].channels.size(), 2u);  // weights skipped
  EXPECT_DOUBLE_EQ(scene.animation.duration_s(), 2.0);
  ASSERT_EQ(scene.animation.object_node.size(), 2u);
  // The rest pose stays in the objects.
  EXPECT_EQ(scene.objects[1].T_world_object * glm::vec4(1, 1, 0, 1), glm::vec4(22, 2, 0, 1));
  // STEP: the first key's value until 1 s, then the second's.
  const auto moved = [&](std::uint32_t o, double t, glm::dvec3 p) {
    const auto pose = pose_at(scene, o, t);
    return pose ? glm::dvec3(*pose * glm::dvec4(p, 1.0)) : glm::dvec3(NAN);
  };
  EXPECT_NEAR(glm::distance(moved(0, 0.5, {1, 1, 0}), glm::dvec3(1, 1, 0)), 0, 1e-12);
  EXPECT_NEAR(glm::distance(moved(0, 1.5, {1, 1, 0}), glm::dvec3(6, 1, 0)), 0, 1e-12);
  // LINEAR rotation is a slerp: 45° at 0.5 s, 135° at 1.5 s, about +y, through the parent's
  // scale of 2: (1, 1, 0) of "second" sits at 2 · (11, 1, 0) before turning. The keys are
  // float quaternions: good to about 1e-7 of the 22 m radius.
  for (const double t : {0.5, 1.5}) {
    const double angle = std::numbers::pi / 2 * t;
    const glm::dvec3 expected(22 * std::cos(angle), 2, -22 * std::sin(angle));
    EXPECT_NEAR(glm::distance(moved(1, t, {1, 1, 0}), expected), 0, 1e-6) << t;
    // Looping: a whole period later, and a period before, the same pose.
    EXPECT_NEAR(glm::distance(moved(1, t + 2, {1, 1, 0}), expected), 0, 1e-6) << t;
    EXPECT_NEAR(glm::distance(moved(1, t - 2, {1, 1, 0}), expected), 0, 1e-6) << t;
  }
  // A still scene has no animation and no poses.
  const Scene still = load_gltf(dir.write("still.gltf", square_gltf()));
  EXPECT_TRUE(still.animation.empty());
  EXPECT_TRUE(animated_object_poses(still.animation, 1.0).empty());
}

TEST(Gltf, BadAnimationsNameTheField) {
  TempDir dir;
  std::string text = animated_square_gltf("SMOOTH");
  expect_input_error(dir.write("interpolation.gltf", text), "samplers[1].interpolation");
  // CUBICSPLINE needs three elements a key: 3 rotations are too few for 3 keys.
  text = animated_square_gltf("CUBICSPLINE");
  expect_input_error(dir.write("cubic.gltf", text), "samplers[1].output");
  text = animated_square_gltf();
  text.replace(text.find("\"rotation\""), 10, "\"shear\"");
  expect_input_error(dir.write("path.gltf", text), "channels[1].target.path");
}

// Cubic Hermite keys: with zero tangents the value halfway is the mean of the keys; with equal
// tangents m and values 0, 0 it is m · dt / 8 · ... (u = 1/2: (u³ - 2u² + u - u³ + u²) dt m).
TEST(Animation, CubicSplineAndStepSampling) {
  SceneAnimation animation;
  animation.nodes.push_back({});
  animation.object_node = {0};
  AnimationChannel channel;
  channel.path = AnimationPath::translation;
  channel.interpolation = AnimationInterpolation::cubic_spline;
  channel.times_s = {0, 2};
  // Key 0: in (0,0,0), value (0,0,0), out (1,0,0); key 1: in (1,0,0), value (0,0,0), out 0.
  channel.values = {0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0};
  AnimationClip clip;
  clip.duration_s = 2;
  clip.channels = {channel};
  animation.clips = {clip};
  auto x_at = [&](double t) {
    return animated_object_poses(animation, t).at(0).T_world_object[3].x;
  };
  // (u - 2u² + u³) dt + (u³ - u²) dt at u = 1/2, dt = 2: (1/8) · 2 + (-1/8) · 2 = 0.
  EXPECT_NEAR(x_at(1.0), 0.0, 1e-12);
  // At u = 1/4: (1/4 - 1/8 + 1/64) · 2 + (1/64 - 1/16) · 2 = 0.28125 - 0.09375 = 0.1875.
  EXPECT_NEAR(x_at(0.5), 0.1875, 1e-7);
  animation.clips[0].channels[0].interpolation = AnimationInterpolation::step;
  animation.clips[0].channels[0].values = {1, 0, 0, 3, 0, 0};
  EXPECT_EQ(x_at(1.99), 1.0);
  EXPECT_EQ(x_at(2.0), 1.0);  // the loop's end is its start
}

TEST(Gltf, MalformedJsonNamesTheFile) {
  TempDir dir;
  std::string text = square_gltf();
  text.resize(text.size() / 2);  // cut off mid-way
  expect_input_error(dir.write("truncated.gltf", text), "");
  expect_input_error(dir.write("not_json.gltf", "this is not glTF"), "");
}

TEST(Gltf, OutOfRangeIndicesNameTheField) {
  TempDir dir;
  expect_input_error(dir.write("bad_index.gltf", square_gltf({0, 1, 2, 0, 2, 9})),
                     "meshes[0].primitives[0].indices");
}

TEST(Gltf, MissingFileOrWrongExtension) {
  TempDir dir;
  expect_input_error(dir.write("x.obj", "o square\n"), "");
  try {
    load_gltf("/nonexistent/facet/scene.gltf");
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "/nonexistent/facet/scene.gltf");
  }
}

// A closed 2 m box around the origin, its faces counter-clockwise seen from outside (or from
// inside when `inward`: a room), with an unlit material and two cameras: "Front" 5 m along +z,
// and "Side" (camera name "side view", orthographic) under a parent at (1, 0, 0), itself at
// (3, 1, 0) turned 90° about y and scaled by 2.
std::string box_gltf(bool inward = false, bool cameras = true) {
  std::vector<unsigned char> buffer;
  const float corners[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                               {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const int faces[6][4] = {{4, 5, 6, 7}, {1, 0, 3, 2}, {5, 1, 2, 6},
                           {0, 4, 7, 3}, {3, 7, 6, 2}, {0, 1, 5, 4}};
  for (const auto& corner : corners)
    for (const float v : corner) append(buffer, v);
  for (const auto& f : faces) {
    const int quad[6] = {f[0], f[1], f[2], f[0], f[2], f[3]};
    for (int k = 0; k < 6; ++k) append(buffer, std::uint16_t(quad[inward ? 5 - k : k]));
  }
  const std::string uri = "data:application/octet-stream;base64," + base64(buffer);
  const std::string camera_nodes =
      cameras ? R"(, {"name": "Front", "camera": 0, "translation": [0, 0, 5]},
    {"translation": [1, 0, 0], "children": [3]},
    {"name": "Side", "camera": 1, "translation": [3, 1, 0], "scale": [2, 2, 2],
     "rotation": [0, 0.70710678118654752, 0, 0.70710678118654752]})"
              : "";
  const std::string camera_list = cameras ? R"("cameras": [
    {"name": "front view", "type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}},
    {"name": "side view", "type": "orthographic",
     "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 100}}],)"
                                          : "";
  return R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_materials_unlit"],
  "scene": 0,
  "scenes": [{"nodes": )" +
         std::string(cameras ? "[0, 1, 2]" : "[0]") + R"(}],
  "nodes": [{"name": "box", "mesh": 0})" +
         camera_nodes + R"(],
  )" + camera_list +
         R"(
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
  "materials": [{"name": "flat", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.5, 0.8, 1]},
                 "extensions": {"KHR_materials_unlit": {}}},
                {"name": "lit"}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
     "min": [-1, -1, -1], "max": [1, 1, 1]},
    {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 96},
    {"buffer": 0, "byteOffset": 96, "byteLength": 72}
  ],
  "buffers": [{"byteLength": )" +
         std::to_string(buffer.size()) + R"(, "uri": ")" + uri + R"("}]
})";
}

void expect_near(const glm::dmat4& a, const glm::dmat4& b, double tolerance = 1e-9) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(a[c][r], b[c][r], tolerance) << c << "," << r;
}

TEST(Gltf, LoadsUnlitMaterialsAndCameras) {
  TempDir dir;
  const Scene scene = load_gltf(dir.write("box.gltf", box_gltf()));
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_TRUE(scene.materials[0].unlit);
  EXPECT_FALSE(scene.materials[1].unlit);
  ASSERT_EQ(scene.cameras.size(), 2u);
  EXPECT_EQ(scene.cameras[0].name, "Front");
  EXPECT_EQ(scene.cameras[0].camera_name, "front view");
  EXPECT_FALSE(scene.cameras[0].orthographic);
  expect_near(scene.cameras[0].T_world_camera,
              glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 5)));
  // Parent translation, then the node's own; its scale is dropped, its turn kept (the camera
  // looks down world -x).
  EXPECT_EQ(scene.cameras[1].name, "Side");
  EXPECT_TRUE(scene.cameras[1].orthographic);
  const glm::dmat4 expected = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(4, 1, 0)),
                                          std::numbers::pi / 2, glm::dvec3(0, 1, 0));
  expect_near(scene.cameras[1].T_world_camera, expected);
}

// A material's extras.facet_shader: a built-in's name, or a .frag file beside the glTF file;
// anything else is an InputError naming the glTF file and the field.
TEST(Gltf, MaterialsTakeTheirOwnShaderFromExtras) {
  TempDir dir;
  const std::string box = box_gltf();
  const std::string lit = R"({"name": "lit"})";
  ASSERT_NE(box.find(lit), std::string::npos);
  const auto with_shader = [&](const std::string& value) {
    std::string text = box;
    text.replace(text.find(lit), lit.size(),
                 R"({"name": "lit", "extras": {"facet_shader": )" + value + "}}");
    return dir.write("shaded.gltf", text);
  };
  const Scene ink = load_gltf(with_shader(R"("pen-and-ink")"));
  ASSERT_EQ(ink.materials.size(), 2u);
  EXPECT_FALSE(ink.materials[0].shader.has_value());
  ASSERT_TRUE(ink.materials[1].shader.has_value());
  EXPECT_EQ(ink.materials[1].shader->name, "pen-and-ink");

  const fs::path paint =
      dir.write("paint.frag", "vec4 shade(MaterialInput m) { return vec4(1, 0, 1, 1); }\n");
  const Scene painted = load_gltf(with_shader(R"("paint.frag")"));
  ASSERT_TRUE(painted.materials[1].shader.has_value());
  EXPECT_NE(painted.materials[1].shader->text.find("vec4(1, 0, 1, 1)"), std::string::npos);
  EXPECT_EQ(fs::path(painted.materials[1].shader->file), paint);

  for (const std::string value : {R"("missing.frag")", R"("chalk")", "42", R"("")"}) {
    try {
      load_gltf(with_shader(value));
      ADD_FAILURE() << value << " was taken";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("shaded.gltf"), std::string::npos) << message;
      EXPECT_EQ(e.field(), "materials[1].extras.facet_shader") << message;
    }
  }
}

TEST(SceneView, DefaultEyeLeavesClosedGeometry) {
  TempDir dir;
  const Scene scene = load_gltf(dir.write("box.gltf", box_gltf()));
  EXPECT_EQ(back_face_hits(scene, glm::dvec3(0.0)), kInsideTestRays);
  EXPECT_TRUE(eye_inside_geometry(scene, glm::dvec3(0.0)));
  EXPECT_FALSE(eye_inside_geometry(scene, glm::dvec3(0, 0, 5)));
  const SceneView view = choose_scene_view(scene, {}, false);
  EXPECT_FALSE(view.follows_city_path);
  EXPECT_FALSE(view.eye_inside);
  EXPECT_NE(view.message.find("inside geometry"), std::string::npos) << view.message;
  const double r = std::sqrt(3.0);  // half the box's diagonal
  const glm::dvec3 p_eye(view.T_world_eye[3]);
  EXPECT_NEAR(glm::distance(p_eye, glm::dvec3(0, 0.6 * r, 1.6 * r)), 0.0, 1e-9);
  EXPECT_EQ(view.pivot_world, glm::dvec3(0.0));
  // It looks at the centre (down its -z), and from there the box's front faces are seen.
  const glm::dvec3 forward = -glm::dvec3(view.T_world_eye[2]);
  EXPECT_NEAR(glm::distance(forward, glm::normalize(-p_eye)), 0.0, 1e-9);
  const ReferenceRaycaster culling(scene);  // culls back faces
  EXPECT_NE(culling.id_along(p_eye, -p_eye), 0u);
  // A quarter turn circles the centre, still looking at it.
  const glm::dmat4 turned = view.T_world_eye_turned(0.25);
  const glm::dvec3 p_turned(turned[3]);
  EXPECT_NEAR(glm::length(p_turned), glm::length(p_eye), 1e-9);
  EXPECT_NEAR(p_turned.y, p_eye.y, 1e-9);
  EXPECT_NEAR(glm::distance(-glm::dvec3(turned[2]), glm::normalize(-p_turned)), 0.0, 1e-9);
}

TEST(SceneView, OpenOrOutsideCentreKeepsTheEyeThere) {
  TempDir dir;
  // A room: from its centre every ray meets a face from the front.
  const Scene room = load_gltf(dir.write("room.gltf", box_gltf(true)));
  EXPECT_EQ(back_face_hits(room, glm::dvec3(0.0)), 0);
  const SceneView view = choose_scene_view(room, {}, false);
  EXPECT_TRUE(view.message.empty()) << view.message;
  expect_near(view.T_world_eye, glm::dmat4(1.0));
  // Turning on the spot.
  EXPECT_NEAR(glm::length(glm::dvec3(view.T_world_eye_turned(0.3)[3])), 0.0, 1e-12);
  // The built-in city keeps its camera path.
  EXPECT_TRUE(choose_scene_view(room, {}, true).follows_city_path);
}

TEST(SceneView, EyeAndLookAt) {
  TempDir dir;
  const Scene scene = load_gltf(dir.write("box.gltf", box_gltf()));
  ViewRequest request;
  request.eye_world = glm::dvec3(0.2, 0.1, 0);
  const SceneView inside = choose_scene_view(scene, request, false);
  EXPECT_TRUE(inside.eye_inside);
  EXPECT_EQ(inside.message.rfind("warning: the eye point", 0), 0u) << inside.message;
  request.eye_world = glm::dvec3(4, 3, 0);
  request.look_at_world = glm::dvec3(0, 3, 0);
  const SceneView outside = choose_scene_view(scene, request, false);
  EXPECT_FALSE(outside.eye_inside);
  EXPECT_TRUE(outside.message.empty()) << outside.message;
  expect_near(outside.T_world_eye, glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(4, 3, 0)),
                                               std::numbers::pi / 2, glm::dvec3(0, 1, 0)));
  EXPECT_EQ(outside.pivot_world, glm::dvec3(0, 3, 0));

  request.look_at_world = glm::dvec3(4, 3, 0);
  EXPECT_THROW(choose_scene_view(scene, request, false), InputError);
  request.eye_world.reset();
  EXPECT_THROW(choose_scene_view(scene, request, false), InputError);

  EXPECT_EQ(parse_point(" 1, -2.5,+3e1 ", "--eye"), glm::dvec3(1, -2.5, 30));
  for (const char* bad : {"1,2", "1,2,3,4", "a,b,c", "1,,3", "nan,0,0", "", "1 2 3"}) {
    try {
      parse_point(bad, "--look-at");
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "--look-at");
      EXPECT_NE(e.expected().find("X,Y,Z"), std::string::npos) << e.what();
    }
  }
}

TEST(SceneView, CameraByName) {
  TempDir dir;
  const Scene scene = load_gltf(dir.write("box.gltf", box_gltf()));
  ViewRequest request;
  request.camera = "Side";
  const SceneView side = choose_scene_view(scene, request, false);
  expect_near(side.T_world_eye, scene.cameras[1].T_world_camera);
  EXPECT_EQ(side.pivot_world, glm::dvec3(4, 1, 0));
  EXPECT_TRUE(side.message.empty()) << side.message;
  request.camera = "front view";  // the camera's own name
  expect_near(choose_scene_view(scene, request, false).T_world_eye,
              scene.cameras[0].T_world_camera);

  request.camera = "Top";
  try {
    choose_scene_view(scene, request, false);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "camera");
    EXPECT_NE(e.expected().find("'Front', 'Side'"), std::string::npos) << e.what();
  }
  request.camera = "Side";
  request.eye_world = glm::dvec3(0, 0, 5);
  EXPECT_THROW(choose_scene_view(scene, request, false), InputError);

  const Scene bare = load_gltf(dir.write("bare.gltf", box_gltf(false, false)));
  EXPECT_TRUE(bare.cameras.empty());
  request.eye_world.reset();
  try {
    choose_scene_view(bare, request, false);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(e.expected().find("bare has none"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace facet::driver
