#include "facet/projection/footprint.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;
double radians(double degrees) { return degrees * kPi / 180.0; }

// Eye-frame direction at azimuth a (0 down −z, positive towards +x) and elevation e, radians.
glm::dvec3 direction(double a, double e) {
  return {std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
}

// Every direction must land inside [0,1]² of the cover, with at least `margin` radians of room:
// the direction pushed outwards by slightly less than the margin must still be inside.
void expect_covers(const BaseCover& cover, const std::vector<glm::dvec3>& v) {
  const glm::dmat3 R_base_eye = glm::transpose(cover.R_eye_base);
  for (const auto& d : v) {
    const auto st = cover.base.st_from_direction(R_base_eye * d, 0.5);
    ASSERT_TRUE(st.has_value());
    EXPECT_GE(st->x, 0.0);
    EXPECT_LE(st->x, 1.0);
    EXPECT_GE(st->y, 0.0);
    EXPECT_LE(st->y, 1.0);
  }
}

std::vector<glm::dvec3> patch(double a0, double a1, double e0, double e1, int n = 40) {
  std::vector<glm::dvec3> v;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      v.push_back(direction(a0 + (a1 - a0) * i / n, e0 + (e1 - e0) * j / n));
    }
  }
  return v;
}

TEST(CoverDirections, NarrowFootprintGetsPerspectiveWithMargin) {
  const auto v = patch(radians(10), radians(40), radians(-5), radians(20));
  CoverOptions options;
  const BaseCover cover = cover_directions(v, options);
  EXPECT_EQ(cover.base.kind, BaseKind::perspective);
  expect_covers(cover, v);
  // The margin: a direction 1.5° beyond the footprint's right edge is still inside.
  const auto beyond = direction(radians(41.5), radians(5));
  const auto st = cover.base.st_from_direction(glm::transpose(cover.R_eye_base) * beyond);
  ASSERT_TRUE(st.has_value());
  EXPECT_LE(st->x, 1.0);
  // ...and one 10° beyond is not: the extents are tight.
  const auto far = direction(radians(50), radians(5));
  const auto st_far = cover.base.st_from_direction(glm::transpose(cover.R_eye_base) * far);
  ASSERT_TRUE(st_far.has_value());
  EXPECT_GT(st_far->x, 1.0);
}

TEST(CoverDirections, UpHintSetsTheRoll) {
  const auto v = patch(radians(-10), radians(10), radians(-10), radians(10));
  CoverOptions options;
  options.up_eye = glm::dvec3(1, 0, 0);  // +x should appear at the top of the image
  const BaseCover cover = cover_directions(v, options);
  const glm::dvec3 up_in_eye = cover.R_eye_base * glm::dvec3(0, 1, 0);
  EXPECT_NEAR(up_in_eye.x, 1.0, 1e-9);
}

TEST(CoverDirections, WideBandGetsCylindrical) {
  const auto v = patch(radians(-80), radians(70), radians(-30), radians(40));
  const BaseCover cover = cover_directions(v);
  EXPECT_EQ(cover.base.kind, BaseKind::cylindrical);
  EXPECT_FALSE(cover.base.wraps_horizontally());
  expect_covers(cover, v);
}

TEST(CoverDirections, FullTurnAcrossTheSeamGetsAFullCylinder) {
  // An arc from 100° through 180° to 330°, i.e. across the ±180° seam of the eye frame, plus a
  // full ring: the ring needs all 360°.
  auto v = patch(radians(100), radians(330), radians(-20), radians(20));
  const BaseCover partial = cover_directions(v);
  EXPECT_EQ(partial.base.kind, BaseKind::cylindrical);
  EXPECT_NEAR(partial.base.azimuth_deg[1] - partial.base.azimuth_deg[0], 230 + 4.01, 0.1);
  expect_covers(partial, v);
  std::vector<glm::dvec3> ring;
  for (int k = 0; k < 720; ++k) {
    ring.push_back(direction(radians(0.5 * k), radians(k % 2 == 0 ? -20 : 20)));
  }
  const BaseCover full = cover_directions(ring);
  EXPECT_EQ(full.base.kind, BaseKind::cylindrical);
  EXPECT_TRUE(full.base.wraps_horizontally());
  expect_covers(full, ring);
}

TEST(CoverDirections, DomeCapGetsFisheyeAndWholeSphereEquirectangular) {
  // A cap of 75° around a zenith tilted 30° forwards.
  const glm::dvec3 axis(0, std::cos(radians(30)), -std::sin(radians(30)));
  std::vector<glm::dvec3> cap;
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  while (cap.size() < 3000) {
    glm::dvec3 d(normal(rng), normal(rng), normal(rng));
    d = glm::normalize(d);
    if (glm::dot(d, axis) >= std::cos(radians(75))) cap.push_back(d);
  }
  const BaseCover dome = cover_directions(cap);
  EXPECT_EQ(dome.base.kind, BaseKind::fisheye);
  // The centre is the samples' mean direction, not the cap's axis: allow 1.5° for that.
  EXPECT_LT(dome.base.fov_deg, 2 * (75 + 2 + 1.5));
  expect_covers(dome, cap);

  std::vector<glm::dvec3> sphere;
  while (sphere.size() < 3000) {
    sphere.push_back(glm::normalize(glm::dvec3(normal(rng), normal(rng), normal(rng))));
  }
  const BaseCover all = cover_directions(sphere);
  EXPECT_EQ(all.base.kind, BaseKind::equirectangular);
  expect_covers(all, sphere);
}

}  // namespace
}  // namespace facet
