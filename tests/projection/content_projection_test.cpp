// Content images in the eye's frame: every format's map and its inverse agree, a dome master's
// layout is the documented one, the cube faces are OpenGL's, and a projector's covering frustum
// holds its directions.
#include "facet/projection/content_projection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;

glm::dvec3 random_direction(std::mt19937& random) {
  std::normal_distribution<double> normal;
  return glm::normalize(glm::dvec3(normal(random), normal(random), normal(random)));
}

// OpenGL 4.5 core, table 8.19, written out apart from kCubeFaces: for direction r, the major
// axis's face, then sc, tc and |ma|. The face order is GL's: +x, -x, +y, -y, +z, -z.
struct GlCubeCoordinates {
  int face;
  double sc, tc, ma;
};
GlCubeCoordinates gl_cube_coordinates(const glm::dvec3& r) {
  const double ax = std::abs(r.x), ay = std::abs(r.y), az = std::abs(r.z);
  if (ax >= ay && ax >= az)
    return r.x >= 0 ? GlCubeCoordinates{0, -r.z, -r.y, ax} : GlCubeCoordinates{1, r.z, -r.y, ax};
  if (ay >= az)
    return r.y >= 0 ? GlCubeCoordinates{2, r.x, r.z, ay} : GlCubeCoordinates{3, r.x, -r.z, ay};
  return r.z >= 0 ? GlCubeCoordinates{4, r.x, -r.y, az} : GlCubeCoordinates{5, -r.x, -r.y, az};
}

// kCubeFaces and cube_face_of, the one table the cubemap content format and the cube-map render
// method both use, are GL's: the same face for every direction and the same sc, tc and |ma| on
// it, exactly (the axes are unit vectors of ±1 and 0). A face or sign that differs fails here.
TEST(CubeFaces, AreOpenGLsFaceSelectionAndAxes) {
  std::mt19937 random(8);
  std::vector<glm::dvec3> directions;
  for (int k = 0; k < 2000; ++k) directions.push_back(random_direction(random));
  // Each axis and the diagonals between them, where the tie rules decide.
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) directions.emplace_back(x, y, z);
  int seen[6] = {};
  for (const glm::dvec3& r : directions) {
    const GlCubeCoordinates gl = gl_cube_coordinates(r);
    const int face = cube_face_of(r);
    ASSERT_EQ(face, gl.face) << r.x << " " << r.y << " " << r.z;
    const CubeFaceAxes& axes = kCubeFaces[std::size_t(face)];
    EXPECT_EQ(glm::dot(axes.a_s, r), gl.sc) << face;
    EXPECT_EQ(glm::dot(axes.a_t, r), gl.tc) << face;
    EXPECT_EQ(glm::dot(axes.a_m, r), gl.ma) << face;
    ++seen[face];
  }
  for (int f = 0; f < 6; ++f) EXPECT_GT(seen[f], 200) << "face " << f;
  // One handedness for every face, which lets the cube-map method draw all six with one winding.
  for (const CubeFaceAxes& axes : kCubeFaces)
    EXPECT_EQ(glm::dot(glm::cross(axes.a_s, axes.a_t), axes.a_m),
              glm::dot(glm::cross(kCubeFaces[0].a_s, kCubeFaces[0].a_t), kCubeFaces[0].a_m));
}

TEST(ContentProjection, EveryFormatInvertsItsMap) {
  DomeOrientation tilted;
  tilted.tilt_deg = 25;
  tilted.orientation_deg = -40;
  Frustum frustum;
  frustum.tan_extent = {-0.7, 1.1, 0.6, -0.4};
  frustum.R_eye_frustum = tilted.R_eye_dome();
  const ContentProjection contents[] = {fisheye_content(180, tilted), fisheye_content(230),
                                        equirect_content(tilted), cubemap_content(tilted),
                                        frustum.content()};
  std::mt19937 random(7);
  for (const ContentProjection& content : contents) {
    int mapped = 0;
    double worst_rad = 0;
    for (int k = 0; k < 2000; ++k) {
      const glm::dvec3 v = random_direction(random);
      const auto point = content.point_from_v_eye(v);
      if (!point) continue;
      ++mapped;
      EXPECT_GE(point->st.x, 0);
      EXPECT_LE(point->st.x, 1);
      EXPECT_GE(point->st.y, 0);
      EXPECT_LE(point->st.y, 1);
      const glm::dvec3 back = content.v_eye_from_point(*point);
      worst_rad = std::max(worst_rad, std::acos(std::clamp(glm::dot(back, v), -1.0, 1.0)));
    }
    EXPECT_GT(mapped, 100) << to_string(content.format);
    EXPECT_LT(worst_rad, 1e-7) << to_string(content.format) << ": worst round trip, radians";
  }
}

TEST(ContentProjection, DomeMasterLayout) {
  const ContentProjection master = fisheye_content();
  auto st_of = [&](glm::dvec3 v) { return master.point_from_v_eye(v)->st; };
  // Zenith at the centre, the front at the bottom edge, behind at the top, right at the right.
  EXPECT_NEAR(glm::length(st_of({0, 1, 0}) - glm::dvec2(0.5, 0.5)), 0, 1e-12);
  EXPECT_NEAR(glm::length(st_of({0, 0, -1}) - glm::dvec2(0.5, 1.0)), 0, 1e-12);
  EXPECT_NEAR(glm::length(st_of({0, 0, 1}) - glm::dvec2(0.5, 0.0)), 0, 1e-12);
  EXPECT_NEAR(glm::length(st_of({1, 0, 0}) - glm::dvec2(1.0, 0.5)), 0, 1e-12);
  // Equidistant: 45° from the zenith is half way to the rim.
  EXPECT_NEAR(st_of({0, 1, -1}).y, 0.75, 1e-12);
  EXPECT_FALSE(master.point_from_v_eye({0, -1, 0.1}));  // below the spring line of a 180° master
  // Tilted forward by 30°: the zenith of the content is 30° toward the front.
  DomeOrientation tilt;
  tilt.tilt_deg = 30;
  const glm::dvec3 tilted_zenith(0, std::cos(kPi / 6), -std::sin(kPi / 6));
  EXPECT_NEAR(glm::length(fisheye_content(180, tilt).point_from_v_eye(tilted_zenith)->st -
                          glm::dvec2(0.5, 0.5)),
              0, 1e-12);
  // Equirect: ahead at the centre, straight up at the top row, right at s = 0.75.
  const ContentProjection panorama = equirect_content();
  EXPECT_NEAR(glm::length(panorama.point_from_v_eye({0, 0, -1})->st - glm::dvec2(0.5, 0.5)), 0,
              1e-12);
  EXPECT_NEAR(panorama.point_from_v_eye({0, 1, 0})->st.y, 0, 1e-12);
  EXPECT_NEAR(panorama.point_from_v_eye({1, 0, 0})->st.x, 0.75, 1e-12);
  // Cube: +x face centre.
  const auto face = cubemap_content().point_from_v_eye({2, 0.2, 0.1});
  EXPECT_EQ(face->face, 0);
}

TEST(ContentProjection, BadFieldOfViewIsAnInputError) {
  EXPECT_THROW(fisheye_content(0).validate("test"), InputError);
  EXPECT_THROW(fisheye_content(361).validate("test"), InputError);
  EXPECT_THROW(content_format_from_string("mercator", "test", "--format"), InputError);
}

TEST(CoveringFrustum, HoldsEveryDirectionOfTheProjector) {
  // A tilted perspective projector whose warp has offsets: the frustum holds all its directions
  // and is not much wider than they are.
  Warp warp = Warp::analytic(BaseProjection::perspective(-0.8, 0.5, 0.6, -0.3), {320, 200}, {5, 4},
                             DomeOrientation{20, 35}.R_eye_dome());
  for (std::size_t i = 0; i < warp.offset_px.size(); ++i)
    warp.offset_px[i] = glm::vec2(float(i % 3) * 2.0f, float(i % 2) * -3.0f);
  const Frustum frustum = covering_frustum(warp, "test");
  const ContentProjection content = frustum.content();
  for (int j = 0; j <= 50; ++j) {
    for (int i = 0; i <= 50; ++i) {
      const glm::dvec2 st(i / 50.0, j / 50.0);
      const auto point = content.point_from_v_eye(warp.v_eye_from_st(st));
      ASSERT_TRUE(point) << "st " << st.x << ", " << st.y << " outside the frustum";
    }
  }
  const double width = frustum.tan_extent[1] - frustum.tan_extent[0];
  const double height = frustum.tan_extent[2] - frustum.tan_extent[3];
  EXPECT_LT(width * height, 1.2 * 1.3 * 0.9 * 1.15);  // the projector's own image, 15 % slack
  // Its GL matrix maps the frustum's corners to the clip cube's.
  const glm::dmat4 P = frustum.gl_projection(0.1, 100);
  const glm::dvec4 corner =
      P * glm::dvec4(frustum.tan_extent[0] * 2, frustum.tan_extent[2] * 2, -2, 1);
  EXPECT_NEAR(corner.x / corner.w, -1, 1e-12);
  EXPECT_NEAR(corner.y / corner.w, 1, 1e-12);
}

TEST(CoveringFrustum, RefusesAHemisphere) {
  const Warp dome = Warp::analytic(BaseProjection::fisheye(180), {64, 64});
  EXPECT_THROW(covering_frustum(dome, "dome"), InputError);
}

}  // namespace
}  // namespace facet
