// The built-in city: deterministic, in the triangle and material budget of the paper's test
// model, well-formed, with tight bounds, buildings all around the origin, and a camera path that
// loops along the streets.
#include "facet/driver/city.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>
#include <set>

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
