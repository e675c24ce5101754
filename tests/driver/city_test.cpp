// The built-in city: deterministic, in the triangle and material budget of the paper's test
// model, well-formed, with tight bounds, buildings all around the origin, and a camera path that
// loops along the streets. The scale scenes: tiles, subdivision, their names and the moving view.
#include "facet/driver/city.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <numbers>
#include <set>

#include "facet/driver/scene_names.hpp"
#include "facet/driver/scene_view.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

const Scene& city() {
  static const Scene scene = build_city({});
  return scene;
}

TEST(City, IsDeterministic) {
  const Scene again = build_city({});
  EXPECT_EQ(again.triangle_count(), city().triangle_count());
  EXPECT_EQ(geometry_hash(again), geometry_hash(city()));
  EXPECT_EQ(again.positions.size(), city().positions.size());
  // The hash does see the data: another seed gives another city.
  CityOptions other;
  other.seed = 7;
  EXPECT_NE(geometry_hash(build_city(other)), geometry_hash(city()));
}

TEST(City, MatchesThePapersBudget) {
  const Scene& scene = city();
  const std::size_t triangles = scene.triangle_count();
  std::printf("city: %zu triangles, %zu vertices, %zu objects, %zu materials, hash %016llx\n",
              triangles, scene.positions.size(), scene.objects.size(), scene.materials.size(),
              static_cast<unsigned long long>(geometry_hash(scene)));
  EXPECT_GE(triangles, 30000u);
  EXPECT_LE(triangles, 40000u);
  EXPECT_GE(scene.materials.size(), 12u);
  EXPECT_LE(scene.materials.size(), 16u);
  EXPECT_EQ(scene.materials.size(), static_cast<std::size_t>(CityMaterial::count));
  // Every material group is used.
  std::set<std::uint32_t> used;
  for (const auto& p : scene.primitives) used.insert(p.material);
  EXPECT_EQ(used.size(), scene.materials.size());
}

TEST(City, IsWellFormed) {
  const Scene& scene = city();
  ASSERT_EQ(scene.normals.size(), scene.positions.size());
  ASSERT_EQ(scene.uvs.size(), scene.positions.size());
  for (const auto& p : scene.primitives) {
    EXPECT_EQ(p.index_count % 3, 0u);
    EXPECT_LE(p.first_index + p.index_count, scene.indices.size());
    EXPECT_LT(p.material, scene.materials.size());
  }
  for (const auto index : scene.indices) ASSERT_LT(index, scene.positions.size());
  // Unit normals to float rounding (1e-5 relative), finite everything.
  for (std::size_t i = 0; i < scene.positions.size(); ++i) {
    ASSERT_NEAR(glm::length(scene.normals[i]), 1.0f, 1e-5f) << "vertex " << i;
    ASSERT_TRUE(std::isfinite(scene.positions[i].x + scene.positions[i].y + scene.positions[i].z));
    ASSERT_TRUE(std::isfinite(scene.uvs[i].x + scene.uvs[i].y));
  }
  // No degenerate triangles: every one has an area above 1 cm^2.
  for (std::size_t t = 0; t + 2 < scene.indices.size(); t += 3) {
    const glm::vec3 a = scene.positions[scene.indices[t]],
                    b = scene.positions[scene.indices[t + 1]],
                    c = scene.positions[scene.indices[t + 2]];
    ASSERT_GT(0.5f * glm::length(glm::cross(b - a, c - a)), 1e-4f) << "triangle " << t / 3;
  }
  for (const auto& m : scene.materials)
    if (m.texture >= 0) {
      ASSERT_LT(static_cast<std::size_t>(m.texture), scene.images.size());
    }
  for (const auto& image : scene.images) {
    EXPECT_EQ(image.width, 128);
    EXPECT_EQ(image.rgba.size(), static_cast<std::size_t>(image.width * image.height * 4));
    // Generated, not flat: the texels are not all the same.
    bool varies = false;
    for (std::size_t i = 4; i < image.rgba.size() && !varies; ++i)
      varies = image.rgba[i] != image.rgba[i % 4];
    EXPECT_TRUE(varies) << image.name;
  }
}

TEST(City, BoundsContainTheirTriangles) {
  const Scene& scene = city();
  for (const auto& object : scene.objects) {
    ASSERT_FALSE(object.bounds_world.empty()) << object.name;
    ASSERT_GT(object.primitive_count, 0u);
    for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
      const Primitive& p = scene.primitives[object.first_primitive + k];
      for (std::uint32_t i = 0; i < p.index_count; ++i) {
        const glm::vec3 p_world =
            glm::vec3(object.T_world_object *
                      glm::vec4(scene.positions[scene.indices[p.first_index + i]], 1));
        ASSERT_TRUE(object.bounds_world.contains(p_world, 0.0f)) << object.name;
      }
    }
  }
  // Bounds are tight: recomputing them changes nothing.
  Scene copy = scene;
  copy.update_bounds();
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    EXPECT_EQ(copy.objects[i].bounds_world.p_min, scene.objects[i].bounds_world.p_min);
    EXPECT_EQ(copy.objects[i].bounds_world.p_max, scene.objects[i].bounds_world.p_max);
  }
}

TEST(City, SurroundsTheOrigin) {
  // Every 45 degree sector of azimuth around the origin holds a building within 150 m.
  std::set<int> sectors;
  for (const auto& object : city().objects) {
    if (object.name.rfind("building", 0) != 0) continue;
    const glm::vec3 c = object.bounds_world.centre();
    if (std::hypot(c.x, c.z) > 150.0f) continue;
    const double azimuth = std::atan2(static_cast<double>(c.z), static_cast<double>(c.x));
    sectors.insert(
        static_cast<int>(std::floor((azimuth + std::numbers::pi) / (std::numbers::pi / 4))) % 8);
  }
  EXPECT_EQ(sectors.size(), 8u);
}

TEST(City, RejectsBadOptions) {
  CityOptions bad;
  bad.blocks_per_side = 0;
  EXPECT_THROW(build_city(bad), std::invalid_argument);
  bad = {};
  bad.texture_size = 100;
  EXPECT_THROW(build_city(bad), std::invalid_argument);
}

TEST(CityCameraPath, LoopsSmoothlyAlongTheStreets) {
  const CityCameraPath path;
  const double period = path.period_s();
  ASSERT_GT(period, 10.0);
  constexpr double speed = 8.0;   // m/s, as documented
  constexpr double street = 4.0;  // asphalt half-width, metres
  for (double t = 0; t < period; t += 0.05) {
    const glm::dmat4 T = path.T_world_eye(t);
    const glm::dmat4 T_later = path.T_world_eye(t + period);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) ASSERT_NEAR(T[c][r], T_later[c][r], 1e-6) << "t=" << t;
    // A rigid pose: orthonormal, right-handed rotation with world up as the eye's y.
    const glm::dvec3 x(T[0]), y(T[1]), z(T[2]);
    ASSERT_NEAR(glm::length(x), 1.0, 1e-9);
    ASSERT_NEAR(glm::length(z), 1.0, 1e-9);
    ASSERT_NEAR(glm::dot(x, z), 0.0, 1e-9);
    ASSERT_NEAR(glm::length(glm::cross(x, y) - z), 0.0, 1e-9);
    ASSERT_EQ(y, glm::dvec3(0, 1, 0));
    ASSERT_DOUBLE_EQ(T[3].y, 1.7);
    // On the asphalt of some street: near a grid line in x or in z.
    auto off_line = [](double v) { return std::abs(v - 62.0 * std::round(v / 62.0)); };
    ASSERT_TRUE(off_line(T[3].x) <= street || off_line(T[3].z) <= street)
        << "t=" << t << " at " << T[3].x << ", " << T[3].z;
    // Continuous at the documented speed (1% slack for the arc-length table).
    const glm::dmat4 T_next = path.T_world_eye(t + 0.01);
    ASSERT_LE(glm::length(glm::dvec3(T_next[3] - T[3])), speed * 0.01 * 1.01) << "t=" << t;
  }
}

}  // namespace
}  // namespace facet::driver

namespace facet::driver {
namespace {

std::uint64_t countryside_triangles(const Scene& scene) {
  std::uint64_t count = 0;
  for (const Object& object : scene.objects) {
    if (object.name.find("countryside") == std::string::npos) continue;
    for (std::uint32_t k = 0; k < object.primitive_count; ++k)
      count += scene.primitives[object.first_primitive + k].index_count / 3;
  }
  return count;
}

TEST(CityTiles, CountTheTileTrianglesKSquaredTimes) {
  const std::uint64_t tile = city().triangle_count() - countryside_triangles(city());
  for (const int k : {1, 2, 3}) {
    const Scene tiles = build_city_tiles(k);
    const std::uint64_t countryside = countryside_triangles(tiles);
    EXPECT_EQ(tiles.triangle_count() - countryside, tile * std::uint64_t(k * k)) << k;
    EXPECT_EQ(tiles.triangle_count(), city_tiles_triangle_count(k)) << k;
    // Instances: the vertex data is the city's and the countryside's (quads: 4 vertices per 2
    // triangles); only the objects repeat.
    EXPECT_LE(tiles.positions.size(), city().positions.size() + 2 * countryside) << k;
  }
  EXPECT_EQ(geometry_hash(build_city_tiles(1)), geometry_hash(city()));
  EXPECT_THROW(build_city_tiles(0), std::invalid_argument);
  EXPECT_THROW(build_city_tiles(65), std::invalid_argument);
}

TEST(CityTiles, TilesSitSideBySideWithTightBounds) {
  const int k = 3;
  const Scene tiles = build_city_tiles(k);
  const float period = static_cast<float>(city_tile_period_m());
  EXPECT_EQ(period, 510.0f);  // 2 (4 blocks x 62 m + 7 m of street and sidewalk)
  // Bounds are tight: recomputing them from the vertices and T_world_object changes nothing.
  Scene copy = tiles;
  copy.update_bounds();
  for (std::size_t i = 0; i < tiles.objects.size(); ++i) {
    ASSERT_EQ(copy.objects[i].bounds_world.p_min, tiles.objects[i].bounds_world.p_min) << i;
    ASSERT_EQ(copy.objects[i].bounds_world.p_max, tiles.objects[i].bounds_world.p_max) << i;
  }
  // Every tile is the city's core moved by whole periods; tile (1, 1) of 3 is the city itself.
  Aabb core;
  for (const Object& object : city().objects)
    if (object.name.find("countryside") == std::string::npos) core.extend(object.bounds_world);
  EXPECT_NEAR(core.p_max.x - core.p_min.x, period, 1e-3f);
  std::set<std::pair<int, int>> seen;
  for (const Object& object : tiles.objects) {
    if (object.name.find("countryside") != std::string::npos) continue;
    const glm::vec3 offset(object.T_world_object[3]);
    const int i = static_cast<int>(std::lround(offset.x / period));
    const int j = static_cast<int>(std::lround(offset.z / period));
    ASSERT_EQ(offset,
              glm::vec3(static_cast<float>(i) * period, 0.0f, static_cast<float>(j) * period));
    ASSERT_TRUE(i >= -1 && i <= 1 && j >= -1 && j <= 1) << object.name;
    seen.insert({i, j});
    Aabb moved = core;
    moved.p_min += offset;
    moved.p_max += offset;
    ASSERT_TRUE(moved.contains(object.bounds_world.p_min, 1e-3f) &&
                moved.contains(object.bounds_world.p_max, 1e-3f))
        << object.name;
  }
  EXPECT_EQ(seen.size(), 9u);
  // The tiled streets and the countryside cover the ground out past every tile.
  const Aabb all = tiles.bounds_world();
  EXPECT_LE(all.p_min.x, -1.5f * period);
  EXPECT_GE(all.p_max.z, 1.5f * period);
  EXPECT_EQ(city_tile_offset(0, 8), -3);
  EXPECT_EQ(city_tile_offset(7, 8), 4);
}

double area_of(const Scene& scene, const Primitive& p) {
  double area = 0;
  for (std::uint32_t t = 0; t + 2 < p.index_count; t += 3) {
    const glm::dvec3 a(scene.positions[scene.indices[p.first_index + t]]);
    const glm::dvec3 b(scene.positions[scene.indices[p.first_index + t + 1]]);
    const glm::dvec3 c(scene.positions[scene.indices[p.first_index + t + 2]]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

TEST(Subdivide, CutsEveryTriangleIntoNSquaredPiecesOfTheSameArea) {
  const int n = 3;
  const Scene fine = subdivide_triangles(city(), n);
  EXPECT_EQ(fine.triangle_count(), city().triangle_count() * std::size_t(n * n));
  ASSERT_EQ(fine.primitives.size(), city().primitives.size());
  ASSERT_EQ(fine.objects.size(), city().objects.size());
  ASSERT_EQ(fine.normals.size(), fine.positions.size());
  ASSERT_EQ(fine.uvs.size(), fine.positions.size());
  double total = 0, total_fine = 0;
  for (std::size_t k = 0; k < fine.primitives.size(); ++k) {
    ASSERT_EQ(fine.primitives[k].index_count,
              city().primitives[k].index_count * std::uint32_t(n * n));
    ASSERT_EQ(fine.primitives[k].material, city().primitives[k].material);
    const double original = area_of(city(), city().primitives[k]);
    const double cut = area_of(fine, fine.primitives[k]);
    EXPECT_NEAR(cut, original, 1e-6 * original) << "primitive " << k;
    total += original;
    total_fine += cut;
  }
  EXPECT_NEAR(total_fine, total, 1e-6 * total);
  for (const glm::vec3& normal : fine.normals) ASSERT_NEAR(glm::length(normal), 1.0f, 1e-5f);
  // Same winding: every piece faces the way its triangle does; the first piece of the first
  // triangle has its corner, and its texture coordinates are interpolated.
  const Primitive& p = city().primitives[0];
  const Primitive& q = fine.primitives[0];
  const glm::vec3 a = city().positions[city().indices[p.first_index]];
  const glm::vec3 b = city().positions[city().indices[p.first_index + 1]];
  const glm::vec3 c = city().positions[city().indices[p.first_index + 2]];
  const glm::vec3 fa = fine.positions[fine.indices[q.first_index]];
  const glm::vec3 fb = fine.positions[fine.indices[q.first_index + 1]];
  const glm::vec3 fc = fine.positions[fine.indices[q.first_index + 2]];
  EXPECT_EQ(fa, a);
  EXPECT_GT(glm::dot(glm::cross(fb - fa, fc - fa), glm::cross(b - a, c - a)), 0.0f);
  const glm::vec2 uva = city().uvs[city().indices[p.first_index]];
  const glm::vec2 uvb = city().uvs[city().indices[p.first_index + 1]];
  const glm::vec2 fuvb = fine.uvs[fine.indices[q.first_index + 1]];
  EXPECT_NEAR(glm::length(fuvb - (uva + (uvb - uva) / 3.0f)), 0.0f, 1e-5f);
  // n = 1 keeps every triangle as it is.
  const Scene same = subdivide_triangles(city(), 1);
  ASSERT_EQ(same.indices.size(), city().indices.size());
  for (std::size_t k = 0; k < same.indices.size(); ++k)
    ASSERT_EQ(same.positions[same.indices[k]], city().positions[city().indices[k]]) << k;
  EXPECT_THROW(subdivide_triangles(city(), 0), std::invalid_argument);
}

TEST(SceneNames, ParseTheBuiltInScalesAndFiles) {
  EXPECT_EQ(parse_scene_name("builtin:city").kind, SceneName::Kind::city);
  const SceneName tiles = parse_scene_name("builtin:city:8");
  EXPECT_EQ(tiles.kind, SceneName::Kind::city_tiles);
  EXPECT_EQ(tiles.count, 8);
  EXPECT_TRUE(tiles.builtin_city());
  const SceneName fine = parse_scene_name("builtin:city-fine:4");
  EXPECT_EQ(fine.kind, SceneName::Kind::city_fine);
  EXPECT_EQ(fine.count, 4);
  const SceneName file = parse_scene_name("some/model.glb");
  EXPECT_EQ(file.kind, SceneName::Kind::file);
  EXPECT_FALSE(file.builtin_city());
  // The documented sizes (scene_names.hpp).
  auto triangles = [](const char* name) { return builtin_scene_triangles(parse_scene_name(name)); };
  EXPECT_EQ(triangles("builtin:city"), 34642u);
  EXPECT_EQ(city().triangle_count(), 34642u);
  EXPECT_EQ(triangles("builtin:city:2"), 136864u);
  EXPECT_EQ(triangles("builtin:city:4"), 545008u);
  EXPECT_EQ(triangles("builtin:city:8"), 2175976u);
  EXPECT_EQ(triangles("builtin:city:18"), 11005920u);
  EXPECT_EQ(triangles("builtin:city-fine:4"), 554272u);
  EXPECT_EQ(triangles("builtin:city-fine:8"), 2217088u);
  EXPECT_EQ(triangles("builtin:city-fine:17"), 10011538u);
  EXPECT_EQ(load_scene("builtin:city:2").triangle_count(),
            builtin_scene_triangles(parse_scene_name("builtin:city:2")));
  EXPECT_EQ(load_scene("builtin:city-fine:2").triangle_count(), 4u * 34642u);
}

TEST(SceneNames, RefuseUnknownNamesAndAbsurdSizes) {
  for (const char* bad :
       {"builtin:town", "builtin:city:", "builtin:city:0", "builtin:city:x", "builtin:city:8x",
        "builtin:city:65", "builtin:city:-2", "builtin:city:44", "builtin:city-fine:50",
        "builtin:city-fine:", "model.obj", "builtin:cityfine:2"}) {
    try {
      parse_scene_name(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "scene") << bad;
      EXPECT_NE(e.expected().find("builtin:city:K"), std::string::npos) << bad;
    }
  }
  try {
    parse_scene_name("builtin:city:50");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(e.expected().find("at most 64000000"), std::string::npos) << e.what();
  }
}

TEST(FrameViews, TurnAboutTheCentreOrFollowThePathUnlessStatic) {
  const Scene& scene = city();
  const glm::dvec3 centre(scene.bounds_world().centre());
  SceneView on_the_spot;  // the eye at the centre, turning there
  on_the_spot.pivot_world = centre;
  on_the_spot.T_world_eye = glm::translate(glm::dmat4(1.0), centre);
  const FrameViews turning(on_the_spot, 0.25);
  for (int k : {0, 1, 30, 119}) {
    const glm::dmat4 T = turning.T_world_eye(k);
    EXPECT_NEAR(glm::length(glm::dvec3(T[3]) - centre), 0.0, 1e-9);
    const double yaw = std::atan2(-T[2].x, T[2].z);  // eye z axis turned about world y
    const double expected = 2 * std::numbers::pi * k / FrameViews::kTurnFrames;
    EXPECT_NEAR(std::remainder(yaw + expected, 2 * std::numbers::pi), 0.0, 1e-9) << k;
  }
  EXPECT_NE(turning.T_world_eye(1), turning.T_world_eye(2));
  const FrameViews still(on_the_spot, 0.25, true);
  EXPECT_EQ(still.T_world_eye(5), still.T_world_eye(0));
  SceneView city_path;
  city_path.follows_city_path = true;
  const FrameViews path(city_path, 0.25);
  EXPECT_EQ(path.T_world_eye(3), CityCameraPath().T_world_eye(0.75));
  EXPECT_EQ(FrameViews(city_path, 0.25, true).T_world_eye(3), CityCameraPath().T_world_eye(0));
}

}  // namespace
}  // namespace facet::driver
