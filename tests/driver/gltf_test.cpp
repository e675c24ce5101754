// glTF loading: a tiny file written here (a .gltf with its buffer embedded as base64) loads with
// the right counts, transforms, materials and bounds; malformed files give InputError naming the
// file.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "facet/driver/gltf_loader.hpp"
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
    path_ =
        fs::temp_directory_path() /
        ("facet_gltf_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
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
std::string square_gltf(std::array<std::uint16_t, 6> indices = {0, 1, 2, 0, 2, 3}) {
  std::vector<unsigned char> buffer;
  const float positions[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const float uvs[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  for (const auto& p : positions)
    for (const float v : p) append(buffer, v);
  for (const auto& t : uvs)
    for (const float v : t) append(buffer, v);
  for (const auto i : indices) append(buffer, i);
  buffer.resize(buffer.size() + 2, 0);  // pad to a multiple of 4
  const std::string uri = "data:application/octet-stream;base64," + base64(buffer);
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

}  // namespace
}  // namespace facet::driver
