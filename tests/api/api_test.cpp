// facet::facet, the application API: a scene built from the application's arrays renders the
// same triangle IDs as the same scene loaded from glTF; objects move through the API; mode 2
// warps an application's perspective image into the outputs the right way up, and its cube map as
// the same panorama would; bad input throws.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "facet/driver/reference.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/facet.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

Context& context() {
  static Context shared = Context::headless();
  return shared;
}

// A unit cube's 24 vertices and 36 indices, faces outwards.
struct Cube {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
};

Cube cube(float side) {
  Cube c;
  const float h = side / 2;
  const glm::vec3 normals[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  for (const glm::vec3& n : normals) {
    const glm::vec3 u = std::abs(n.x) > 0 ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 w = glm::cross(n, u);
    const auto base = std::uint32_t(c.positions.size());
    for (const glm::vec2& k :
         {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
      c.positions.push_back(h * (n + k.x * u + k.y * w));
      c.normals.push_back(n);
      c.uvs.push_back(0.5f * (k + 1.0f));
    }
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) c.indices.push_back(base + i);
  }
  return c;
}

std::string base64(const std::vector<unsigned char>& bytes) {
  static constexpr char alphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = bytes[i], b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0u,
                        b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0u;
    const std::uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += alphabet[(triple >> 18) & 63];
    out += alphabet[(triple >> 12) & 63];
    out += i + 1 < bytes.size() ? alphabet[(triple >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[triple & 63] : '=';
  }
  return out;
}

// The poses of the test's objects: cubes of two sizes around the dome's zenith.
std::vector<glm::dmat4> object_poses() {
  std::vector<glm::dmat4> poses;
  for (int k = 0; k < 5; ++k) {
    const double angle = k * 1.2;
    poses.push_back(glm::rotate(
        glm::translate(glm::dmat4(1.0),
                       glm::dvec3(3 * std::cos(angle), 3 + 0.3 * k, 3 * std::sin(angle))),
        0.4 * k, glm::dvec3(0, 1, 0.3)));
  }
  return poses;
}

// The same scene as a .gltf: two meshes (a big and a small cube) with one material each, nodes
// with the poses as matrices, in the same order.
fs::path write_gltf(const fs::path& folder, const Cube& big, const Cube& small) {
  std::vector<unsigned char> buffer;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();
  auto add = [&](const void* data, std::size_t bytes, int component_type, std::size_t count,
                 const char* type) {
    views.push_back({{"buffer", 0}, {"byteOffset", buffer.size()}, {"byteLength", bytes}});
    const auto* p = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), p, p + bytes);
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", component_type},
                         {"count", count},
                         {"type", type}});
    return int(accessors.size() - 1);
  };
  nlohmann::json meshes = nlohmann::json::array();
  int material = 0;
  for (const Cube* c : {&big, &small}) {
    const int p =
        add(c->positions.data(), c->positions.size() * 12, 5126, c->positions.size(), "VEC3");
    accessors[std::size_t(p)]["min"] = {-1, -1, -1};
    accessors[std::size_t(p)]["max"] = {1, 1, 1};
    const int n = add(c->normals.data(), c->normals.size() * 12, 5126, c->normals.size(), "VEC3");
    const int t = add(c->uvs.data(), c->uvs.size() * 8, 5126, c->uvs.size(), "VEC2");
    const int i = add(c->indices.data(), c->indices.size() * 4, 5125, c->indices.size(), "SCALAR");
    meshes.push_back({{"primitives",
                       {{{"attributes", {{"POSITION", p}, {"NORMAL", n}, {"TEXCOORD_0", t}}},
                         {"indices", i},
                         {"material", material++}}}}});
  }
  nlohmann::json nodes = nlohmann::json::array(), roots = nlohmann::json::array();
  const auto poses = object_poses();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    std::vector<double> matrix(glm::value_ptr(poses[k]), glm::value_ptr(poses[k]) + 16);
    nodes.push_back({{"name", "cube" + std::to_string(k)}, {"mesh", k % 2}, {"matrix", matrix}});
    roots.push_back(k);
  }
  const nlohmann::json gltf = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", roots}}}},
      {"nodes", nodes},
      {"meshes", meshes},
      {"materials",
       {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.2, 0.2, 1}}}}},
        {{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.8, 0.2, 1}}}}}}},
      {"accessors", accessors},
      {"bufferViews", views},
      {"buffers",
       {{{"byteLength", buffer.size()},
         {"uri", "data:application/octet-stream;base64," + base64(buffer)}}}}};
  const fs::path path = folder / "cubes.gltf";
  std::ofstream(path) << gltf.dump();
  return path;
}

fs::path fresh_folder(const std::string& name) {
  const fs::path folder = facet::test_paths::scratch_path("facet_api_test_" + name);
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

TEST(Api, SceneFromArraysRendersTheSameIdsAsFromGltf) {
  context();
  const fs::path folder = fresh_folder("round_trip");
  const Cube big = cube(1.5f), small = cube(0.8f);
  SceneBuilder builder;
  const int red = builder.add_material({.base_colour = {0.8f, 0.2f, 0.2f, 1}});
  const int green = builder.add_material({.base_colour = {0.2f, 0.8f, 0.2f, 1}});
  const int meshes[2] = {
      builder.add_mesh({big.positions, big.normals, big.uvs, big.indices}, red),
      builder.add_mesh({small.positions, small.normals, small.uvs, small.indices}, green)};
  const auto poses = object_poses();
  for (std::size_t k = 0; k < poses.size(); ++k)
    EXPECT_EQ(builder.add_object(meshes[k % 2], poses[k], "cube" + std::to_string(k)), ObjectId(k));
  const Scene built = std::move(builder).build();
  const Scene loaded = Scene::load(write_gltf(folder, big, small).string());
  ASSERT_EQ(built.object_count(), loaded.object_count());
  ASSERT_EQ(built.triangle_count(), loaded.triangle_count());
  EXPECT_EQ(loaded.find_object("cube3"), ObjectId(3));

  Display display = Display::open("builtin:dome180", glm::ivec2(128, 128));
  Renderer from_arrays(display, built), from_gltf(display, loaded);
  for (Renderer* r : {&from_arrays, &from_gltf}) r->render(true);
  const auto a = from_arrays.read_output_ids(0), b = from_gltf.read_output_ids(0);
  std::size_t drawn = 0, differing = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    drawn += a[i] != 0;
    differing += a[i] != b[i];
  }
  std::printf("API vs glTF, dome180 128x128: %zu drawn pixels, %zu differ\n", drawn, differing);
  EXPECT_GT(drawn, 500u);  // every cube in view
  EXPECT_EQ(differing, 0u);
  // And the colours: the same materials.
  EXPECT_EQ(from_arrays.read_output_rgba8(0), from_gltf.read_output_rgba8(0));
  // Another material shader changes the colours, never the IDs.
  Display wireframe = display;
  wireframe.set_material_shader("solid-wireframe");
  Renderer shaded(wireframe, built);
  shaded.render(true);
  EXPECT_EQ(shaded.read_output_ids(0), a);
  EXPECT_NE(shaded.read_output_rgba8(0), from_arrays.read_output_rgba8(0));
  EXPECT_THROW(wireframe.set_material_shader("chrome"), InputError);
  // A material's own shader: the green cubes in pen and ink, the red ones as before.
  SceneBuilder inked;
  const int inked_red = inked.add_material({.base_colour = {0.8f, 0.2f, 0.2f, 1}});
  const int inked_green =
      inked.add_material({.base_colour = {0.2f, 0.8f, 0.2f, 1}, .shader = "pen-and-ink"});
  const int inked_meshes[2] = {
      inked.add_mesh({big.positions, big.normals, big.uvs, big.indices}, inked_red),
      inked.add_mesh({small.positions, small.normals, small.uvs, small.indices}, inked_green)};
  for (std::size_t k = 0; k < poses.size(); ++k) inked.add_object(inked_meshes[k % 2], poses[k]);
  Renderer own(display, std::move(inked).build());
  own.render(true);
  EXPECT_EQ(own.read_output_ids(0), a);
  const auto own_rgba = own.read_output_rgba8(0), plain_rgba = from_arrays.read_output_rgba8(0);
  std::size_t red_same = 0, red_pixels = 0, green_changed = 0, green_pixels = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] == 0) continue;
    const bool same = std::equal(&own_rgba[4 * i], &own_rgba[4 * i] + 4, &plain_rgba[4 * i]);
    // Which material a pixel shows: its colour in the plain render.
    const bool greenish = plain_rgba[4 * i + 1] > plain_rgba[4 * i];
    (greenish ? green_pixels : red_pixels)++;
    (greenish ? green_changed : red_same) += greenish ? !same : same;
  }
  std::printf("own shaders: red %zu of %zu unchanged, green %zu of %zu changed\n", red_same,
              red_pixels, green_changed, green_pixels);
  EXPECT_GT(red_pixels, 100u);
  EXPECT_EQ(red_same, red_pixels);
  EXPECT_GT(green_changed, green_pixels / 2);
  SceneBuilder unknown;
  try {
    unknown.add_material({.shader = "chrome"});
    ADD_FAILURE() << "an unknown shader was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "materials[0].shader") << e.what();
  }
  fs::remove_all(folder);
}

TEST(Api, MovedObjectsAndTheirErrors) {
  context();
  const Cube c = cube(1.0f);
  SceneBuilder builder;
  const int white = builder.add_material({});
  const int mesh = builder.add_mesh({c.positions, {}, {}, c.indices}, white);  // normals computed
  const ObjectId ball =
      builder.add_object(mesh, glm::translate(glm::dmat4(1.0), glm::dvec3(0, 4, -2)));
  const Scene scene = std::move(builder).build();
  Renderer renderer(Display::open("builtin:dome180", glm::ivec2(96, 96)), scene);
  const auto lit_pixels = [&] {
    const auto ids = renderer.read_output_ids(0);
    double x_sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (ids[i] != 0) {
        x_sum += double(i % 96);
        ++n;
      }
    return std::pair(n, n ? x_sum / double(n) : 0.0);
  };
  renderer.render(true);
  const auto [n0, x0] = lit_pixels();
  EXPECT_GT(n0, 20u);
  // Moved to the other side: drawn there, coverage recomputed, then reused while still.
  renderer.set_object_transform(ball, glm::translate(glm::dmat4(1.0), glm::dvec3(0, 4, 2)));
  EXPECT_FALSE(renderer.render(true).outputs[0].reused_coverage);
  EXPECT_TRUE(renderer.render(true).outputs[0].reused_coverage);
  const auto [n1, x1] = lit_pixels();
  EXPECT_GT(n1, 20u);
  const std::vector<std::uint32_t> ids = renderer.read_output_ids(0);
  renderer.reset_object_transform(ball);
  renderer.render(true);
  EXPECT_NE(renderer.read_output_ids(0), ids);
  EXPECT_THROW(renderer.set_object_transform(1, glm::dmat4(1.0)), InputError);
  glm::dmat4 projective(1.0);
  projective[0][3] = 0.5;
  EXPECT_THROW(renderer.set_object_transform(ball, projective), InputError);
  // Builder errors name the field.
  SceneBuilder bad;
  try {
    bad.add_mesh({c.positions, {}, {}, c.indices}, 0);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("meshes[0].material"), std::string::npos) << e.what();
  }
  const int m = bad.add_material({});
  std::vector<std::uint32_t> wrong = {0, 1, 99};
  EXPECT_THROW(bad.add_mesh({c.positions, {}, {}, wrong}, m), InputError);
  EXPECT_THROW(bad.add_object(5, glm::dmat4(1.0)), InputError);
  const std::vector<std::uint8_t> short_rgba(10);
  EXPECT_THROW(bad.add_texture({2, 2, short_rgba}), InputError);
  EXPECT_THROW(Display::open("builtin:nothing"), InputError);
  Display display = Display::open("builtin:wall2x2", glm::ivec2(64, 48));
  EXPECT_THROW(display.set_method("warp-it"), InputError);
}

// Mode 2: on builtin:wall2x2, each projector's frustum rendered by the "application" as a
// texture whose top half is red and bottom half blue comes out with red above blue in every
// output, where the frustum's middle row maps.
// A smooth colour of an eye direction: each channel 0.5 + 0.5 of one component, as bytes.
std::array<std::uint8_t, 4> direction_colour(glm::dvec3 v) {
  v = glm::normalize(v);
  const auto byte = [](double x) { return std::uint8_t(std::lround(255 * (0.5 + 0.5 * x))); };
  return {byte(v.x), byte(v.y), byte(v.z), 255};
}

TEST(Api, WarpCubemapShowsWhatTheSamePanoramaShows) {
  context();
  // The cube map's faces as GL samples them (OpenGL 4.5 table 8.19), written out here on their
  // own: face f's texel (i, j) at sc = 2s - 1, tc = 2t - 1 looks along these eye directions.
  const auto face_direction = [](int f, double sc, double tc) -> glm::dvec3 {
    switch (f) {
      case 0:
        return {1, -tc, -sc};  // +x
      case 1:
        return {-1, -tc, sc};  // -x
      case 2:
        return {sc, 1, tc};  // +y
      case 3:
        return {sc, -1, -tc};  // -y
      case 4:
        return {sc, -tc, 1};  // +z
      default:
        return {-sc, -tc, -1};  // -z
    }
  };
  constexpr int kFace = 256;
  GLuint cube = 0;
  glCreateTextures(GL_TEXTURE_CUBE_MAP, 1, &cube);
  glTextureStorage2D(cube, 1, GL_SRGB8_ALPHA8, kFace, kFace);
  std::vector<std::uint8_t> face(std::size_t(kFace) * kFace * 4);
  for (int f = 0; f < 6; ++f) {
    for (int j = 0; j < kFace; ++j)
      for (int i = 0; i < kFace; ++i) {
        const auto c = direction_colour(
            face_direction(f, 2 * (i + 0.5) / kFace - 1, 2 * (j + 0.5) / kFace - 1));
        std::copy(c.begin(), c.end(), &face[(std::size_t(j) * kFace + i) * 4]);
      }
    glTextureSubImage3D(cube, 0, 0, 0, f, kFace, kFace, 1, GL_RGBA, GL_UNSIGNED_BYTE, face.data());
  }
  // The same colours as an equirectangular panorama (the middle column ahead, -z; azimuth to the
  // right; GL row 0 at the bottom, the nadir).
  constexpr int kWidth = 2048, kHeight = 1024;
  std::vector<std::uint8_t> rgba(std::size_t(kWidth) * kHeight * 4);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double azimuth = ((x + 0.5) / kWidth - 0.5) * 2 * M_PI;
      const double elevation = ((y + 0.5) / kHeight - 0.5) * M_PI;
      const auto c = direction_colour({std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                                       -std::cos(elevation) * std::cos(azimuth)});
      std::copy(c.begin(), c.end(), &rgba[(std::size_t(y) * kWidth + x) * 4]);
    }
  GLuint panorama = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &panorama);
  glTextureStorage2D(panorama, 1, GL_SRGB8_ALPHA8, kWidth, kHeight);
  glTextureSubImage2D(panorama, 0, 0, 0, kWidth, kHeight, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());

  for (const char* name : {"builtin:dome180", "builtin:wall2x2"}) {
    Renderer renderer(Display::open(name, glm::ivec2(128, 96)));
    std::vector<std::vector<std::uint8_t>> from_cube, from_panorama;
    renderer.warp_cubemap(cube);
    for (std::size_t o = 0; o < renderer.output_count(); ++o)
      from_cube.push_back(renderer.read_output_rgba8(o));
    renderer.warp_image(panorama, Renderer::ImageKind::equirect);
    for (std::size_t o = 0; o < renderer.output_count(); ++o)
      from_panorama.push_back(renderer.read_output_rgba8(o));
    // Both resample the same smooth colours through the same warp: they differ by the filtering
    // of two samplings of them only, a few levels; a face turned or flipped differs by up to 255.
    // Compared within 70° of the horizon: toward its poles the panorama's rows bunch up and a
    // pixel's footprint spans every azimuth, so there the panorama, not the cube map, blurs.
    // (Where the colour says the direction: green is 0.5 + 0.5 of its y.)
    int worst = 0;
    std::size_t compared = 0;
    for (std::size_t o = 0; o < from_cube.size(); ++o)
      for (std::size_t k = 0; k < from_cube[o].size(); k += 4) {
        const std::uint8_t* cube_pixel = &from_cube[o][k];
        const std::uint8_t* panorama_pixel = &from_panorama[o][k];
        const bool lit = (cube_pixel[0] | cube_pixel[1] | cube_pixel[2]) != 0;
        const double y = cube_pixel[1] / 127.5 - 1;
        if (!lit || std::abs(y) > std::sin(70 * M_PI / 180)) continue;
        ++compared;
        for (std::size_t c = 0; c < 3; ++c)
          worst = std::max(worst, std::abs(int(cube_pixel[c]) - int(panorama_pixel[c])));
      }
    std::printf("%s: cube map against panorama, worst %d levels over %zu pixels\n", name, worst,
                compared);
    EXPECT_GT(compared, std::size_t(128 * 96 / 3)) << name;
    EXPECT_LE(worst, 4) << name << ": worst difference in levels of 255, any channel";
  }
  // A 2D texture is not a cube map, and a cube map no 2D image.
  Renderer renderer(Display::open("builtin:dome180", glm::ivec2(32, 32)));
  EXPECT_THROW(renderer.warp_cubemap(panorama), InputError);
  EXPECT_THROW(renderer.warp_image(cube, Renderer::ImageKind::fisheye), InputError);
  EXPECT_THROW(renderer.warp_cubemap(0), InputError);
  glDeleteTextures(1, &cube);
  glDeleteTextures(1, &panorama);
}

TEST(Api, WarpPerspectiveKeepsTheApplicationsImageUpright) {
  context();
  const Display display = Display::open("builtin:wall2x2", glm::ivec2(96, 72));
  Renderer renderer(display);
  ASSERT_EQ(renderer.output_count(), 4u);
  const glm::ivec2 size(64, 64);
  std::vector<std::uint8_t> rgba(std::size_t(size.x) * size.y * 4);
  // GL row 0 is the bottom: rows below the middle blue, above it red.
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      std::uint8_t* p = &rgba[(std::size_t(y) * size.x + x) * 4];
      const bool top = y >= size.y / 2;
      p[0] = top ? 255 : 0;
      p[1] = 0;
      p[2] = top ? 0 : 255;
      p[3] = 255;
    }
  GLuint texture = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  glTextureStorage2D(texture, 1, GL_SRGB8_ALPHA8, size.x, size.y);
  glTextureSubImage2D(texture, 0, 0, 0, size.x, size.y, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  for (std::size_t o = 0; o < 4; ++o) {
    const Display::Frustum frustum = display.frustum(o);
    EXPECT_LT(frustum.tan_extent[0], frustum.tan_extent[1]);
    EXPECT_GT(frustum.tan_extent[2], frustum.tan_extent[3]);
    renderer.warp_perspective(o, texture);
    const auto image = renderer.read_output_rgba8(o);
    const glm::ivec2 out = renderer.output_size(o);
    // The column through the middle: red pixels all above blue ones.
    int last_red = -1, first_blue = out.y;
    for (int y = 0; y < out.y; ++y) {
      const std::uint8_t* p = &image[(std::size_t(y) * out.x + out.x / 2) * 4];
      if (p[0] > 200 && p[2] < 50) last_red = y;
      if (p[2] > 200 && p[0] < 50) first_blue = std::min(first_blue, y);
    }
    EXPECT_GE(last_red, 0) << o;
    EXPECT_LT(first_blue, out.y) << o;
    EXPECT_LT(last_red, first_blue) << "output " << o;
  }
  // The same halves as an equirectangular panorama (twice as wide): the sky red, the ground
  // blue.
  GLuint panorama = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &panorama);
  glTextureStorage2D(panorama, 1, GL_SRGB8_ALPHA8, size.x, size.y / 2);
  glTextureSubImage2D(panorama, 0, 0, 0, size.x, size.y / 2, GL_RGBA, GL_UNSIGNED_BYTE,
                      rgba.data() + std::size_t(size.x) * std::size_t(size.y / 4) * 4);
  renderer.warp_image(panorama, Renderer::ImageKind::equirect);
  for (std::size_t o = 0; o < 4; ++o) {
    const auto image = renderer.read_output_rgba8(o);
    const glm::ivec2 out = renderer.output_size(o);
    int last_red = -1, first_blue = out.y;
    for (int y = 0; y < out.y; ++y) {
      const std::uint8_t* p = &image[(std::size_t(y) * out.x + out.x / 2) * 4];
      if (p[0] > 200 && p[2] < 50) last_red = y;
      if (p[2] > 200 && p[0] < 50) first_blue = std::min(first_blue, y);
    }
    // The horizon runs where the upper and lower projectors meet: the upper ones show sky, the
    // lower ones ground, and no output shows ground above sky.
    EXPECT_TRUE(o >= 2 || last_red >= 0) << "no sky in upper output " << o;
    EXPECT_TRUE(o < 2 || first_blue < out.y) << "no ground in lower output " << o;
    EXPECT_LT(last_red, first_blue) << "equirect, output " << o;
  }
  // A dome master on the 180° dome: its red zenith disc (a quarter of the radius) lands at the
  // dome output's centre, its blue rest near the rim.
  std::vector<std::uint8_t> master(64 * 64 * 4);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool zenith = std::hypot(x + 0.5 - 32, y + 0.5 - 32) < 8;
      std::uint8_t* p = &master[(std::size_t(y) * 64 + std::size_t(x)) * 4];
      p[0] = zenith ? 255 : 0;
      p[1] = 0;
      p[2] = zenith ? 0 : 255;
      p[3] = 255;
    }
  GLuint fisheye = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &fisheye);
  glTextureStorage2D(fisheye, 1, GL_RGBA8, 64, 64);
  glTextureSubImage2D(fisheye, 0, 0, 0, 64, 64, GL_RGBA, GL_UNSIGNED_BYTE, master.data());
  Renderer dome(Display::open("builtin:dome180", glm::ivec2(64, 64)));
  dome.warp_image(fisheye, Renderer::ImageKind::fisheye, 180);
  const auto shown = dome.read_output_rgba8(0);
  const auto at = [&](int x, int y) { return &shown[(std::size_t(y) * 64 + std::size_t(x)) * 4]; };
  EXPECT_GT(at(32, 32)[0], 200);
  EXPECT_LT(at(32, 32)[2], 50);
  EXPECT_GT(at(32, 4)[2], 200);
  EXPECT_LT(at(32, 4)[0], 50);
  EXPECT_THROW(dome.warp_image(fisheye, Renderer::ImageKind::fisheye, 400), InputError);
  for (GLuint t : {texture, panorama, fisheye}) glDeleteTextures(1, &t);
  Renderer with_scene(display, Scene::load("builtin:city"));
  EXPECT_THROW(with_scene.warp_perspective(0, 1), InputError);
  EXPECT_THROW(with_scene.warp_image(1, Renderer::ImageKind::equirect), InputError);
}

// The application's framebuffer stays bound through render(); present() then draws the
// output's bytes into it exactly (rows bottom-up, as GL stores them), and output_texture names
// the texture holding them.
TEST(Api, PresentsIntoTheApplicationsFramebuffer) {
  context();
  const Cube c = cube(1.0f);
  SceneBuilder builder;
  const int mesh = builder.add_mesh({c.positions, c.normals, c.uvs, c.indices},
                                    builder.add_material({.base_colour = {0.9f, 0.5f, 0.1f, 1}}));
  builder.add_object(mesh, glm::translate(glm::dmat4(1.0), glm::dvec3(0.5, 3, -1)));
  Renderer renderer(Display::open("builtin:dome180", glm::ivec2(64, 64)),
                    std::move(builder).build());
  GLuint app_texture = 0, app_framebuffer = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &app_texture);
  glTextureStorage2D(app_texture, 1, GL_RGBA8, 80, 70);
  glCreateFramebuffers(1, &app_framebuffer);
  glNamedFramebufferTexture(app_framebuffer, GL_COLOR_ATTACHMENT0, app_texture, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, app_framebuffer);
  glViewport(1, 2, 3, 4);
  renderer.render(true);
  GLint bound = 0, viewport[4] = {0, 0, 0, 0};
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
  glGetIntegerv(GL_VIEWPORT, viewport);
  EXPECT_EQ(GLuint(bound), app_framebuffer);
  EXPECT_EQ(viewport[2], 3);
  renderer.present(0, {10, 5, 64, 64});
  std::vector<std::uint8_t> shown(64 * 64 * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(10, 5, 64, 64, GL_RGBA, GL_UNSIGNED_BYTE, shown.data());
  const std::vector<std::uint8_t> expected = renderer.read_output_rgba8(0);
  std::size_t mismatched = 0, lit = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int k = 0; k < 3; ++k) {
        const std::uint8_t e =
            expected[(std::size_t(63 - y) * 64 + std::size_t(x)) * 4 + std::size_t(k)];
        mismatched += shown[(std::size_t(y) * 64 + std::size_t(x)) * 4 + std::size_t(k)] != e;
        lit += e > 0;
      }
  EXPECT_GT(lit, 100u);
  EXPECT_EQ(mismatched, 0u);
  GLint width = 0;
  glGetTextureLevelParameteriv(renderer.output_texture(0), 0, GL_TEXTURE_WIDTH, &width);
  EXPECT_EQ(width, 64);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &app_framebuffer);
  glDeleteTextures(1, &app_texture);
}

TEST(Api, BorrowsTheCurrentContext) {
  context();
  const Context borrowed = Context::borrow_current();
  EXPECT_TRUE(borrowed.is_borrowed());
  EXPECT_FALSE(borrowed.renderer().empty());
}

}  // namespace
}  // namespace facet
