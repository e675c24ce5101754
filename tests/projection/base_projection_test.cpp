// Base projections and the exact warp map: round trips and domain checks.
#include "facet/projection/base_projection.hpp"

#include <gtest/gtest.h>

#include <random>

#include "facet/projection/dome_orientation.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/warp.hpp"

namespace facet {
namespace {

double angle_between(glm::dvec3 a, glm::dvec3 b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

struct NamedBase {
  const char* name;
  BaseProjection base;
  double st_margin;  // keep away from singular edges (the back pole of a 360° fisheye)
};

std::vector<NamedBase> all_bases() {
  return {{"perspective", BaseProjection::perspective(-1.2, 0.8, 0.9, -0.7), 0},
          {"perspective fov 170", BaseProjection::perspective_fov(170, 120), 0},
          {"fisheye 180", BaseProjection::fisheye(180), 0},
          {"fisheye 360", BaseProjection::fisheye(360), 0.16},  // corners past ρ=1 alias
          {"cylinder 360", BaseProjection::cylindrical(-180, 180, 1, -1), 0},
          {"cylinder 90 reversed", BaseProjection::cylindrical(45, -45, -0.3, 0.8), 0},
          {"equirectangular 360x180", BaseProjection::equirectangular(-180, 180, 90, -90), 1e-6},
          {"equirectangular part", BaseProjection::equirectangular(-30, 200, 40, -10), 0}};
}

// direction → st → direction within 1e-9 rad (worst case), and st → direction → st.
TEST(BaseProjection, RoundTripsWithinOneNanoradian) {
  std::mt19937_64 random(1);
  for (const auto& [name, base, margin] : all_bases()) {
    SCOPED_TRACE(name);
    base.validate();
    std::uniform_real_distribution<double> unit(margin, 1 - margin);
    double worst_rad = 0, worst_st = 0;
    for (int k = 0; k < 20000; ++k) {
      glm::dvec2 st{unit(random), unit(random)};
      if (base.kind == BaseKind::fisheye && base.fov_deg >= 360) {
        // Only the inscribed disc is one-to-one for a 360° fisheye.
        if (glm::length(2.0 * st - 1.0) > 0.98) continue;
      }
      const glm::dvec3 v = base.direction(st);
      const auto st_back = base.st_from_direction(v);
      ASSERT_TRUE(st_back.has_value());
      worst_st = std::max(worst_st, glm::length(*st_back - st));
      worst_rad = std::max(worst_rad, angle_between(base.direction(*st_back), v));
    }
    EXPECT_LE(worst_rad, 1e-9);
    EXPECT_LE(worst_st, 1e-9);
  }
}

TEST(BaseProjection, FormulasMatchFormatsDocument) {
  // Azimuth 0 looks down -z and positive azimuth turns towards +x.
  const auto cylinder = BaseProjection::cylindrical(-180, 180, 1, -1);
  const glm::dvec3 ahead = cylinder.direction({0.5, 0.5});
  EXPECT_NEAR(ahead.z, -1, 1e-15);
  const glm::dvec3 right = cylinder.direction({0.75, 0.5});
  EXPECT_NEAR(right.x, 1, 1e-15);
  const glm::dvec3 up = cylinder.direction({0.5, 0.0});
  EXPECT_NEAR(angle_between(up, glm::dvec3(0, 1, -1)), 0, 1e-15);
  // Fisheye: the top edge's midpoint is fov/2 up from -z.
  const auto fisheye = BaseProjection::fisheye(180);
  EXPECT_NEAR(angle_between(fisheye.direction({0.5, 0.0}), glm::dvec3(0, 1, 0)), 0, 1e-15);
  // Equirectangular: elevation is linear in t.
  const auto equirect = BaseProjection::equirectangular(-180, 180, 90, -90);
  EXPECT_NEAR(equirect.direction({0.5, 0.25}).y, std::sin(M_PI / 4), 1e-15);
}

TEST(BaseProjection, SeamOfA360CylinderPicksTheHintedBranch) {
  const auto cylinder = BaseProjection::cylindrical(-180, 180, 1, -1);
  const glm::dvec3 behind = cylinder.direction({1.0, 0.5});
  EXPECT_NEAR(cylinder.st_from_direction(behind, 0.999)->x, 1.0, 1e-12);
  EXPECT_NEAR(cylinder.st_from_direction(behind, 0.001)->x, 0.0, 1e-12);
}

TEST(BaseProjection, OutOfDomainGivesNoValue) {
  EXPECT_FALSE(BaseProjection::perspective_fov(90, 90).st_from_direction({0, 0, 1}));
  EXPECT_FALSE(BaseProjection::cylindrical(-180, 180, 1, -1).st_from_direction({0, 1, 0}));
  EXPECT_FALSE(BaseProjection::fisheye(180).st_from_direction({NAN, 0, -1}));
  EXPECT_FALSE(BaseProjection::fisheye(180).st_from_direction({0, 0, 0}));
}

TEST(BaseProjection, PerspectiveOf180DegreesOrMoreIsRejected) {
  EXPECT_THROW(BaseProjection::perspective_fov(180, 90), InputError);
  EXPECT_THROW(BaseProjection::perspective_fov(90, 200), InputError);
  EXPECT_NO_THROW(BaseProjection::perspective_fov(179, 90));
  auto infinite = BaseProjection::perspective(-INFINITY, 1, 1, -1);
  EXPECT_THROW(infinite.validate("test"), InputError);
  try {
    BaseProjection::perspective(1, -1, 1, -1).validate("display.warp.exr");
    FAIL() << "left > right accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "display.warp.exr");
    EXPECT_EQ(e.field(), "tan_extent");
  }
}

TEST(BaseProjection, InvalidParametersAreRejected) {
  EXPECT_THROW(BaseProjection::fisheye(0).validate(), InputError);
  EXPECT_THROW(BaseProjection::fisheye(361).validate(), InputError);
  EXPECT_THROW(BaseProjection::cylindrical(-180, 190, 1, -1).validate(), InputError);
  EXPECT_THROW(BaseProjection::cylindrical(0, 0, 1, -1).validate(), InputError);
  EXPECT_THROW(BaseProjection::equirectangular(-10, 10, 95, 0).validate(), InputError);
  EXPECT_THROW(base_kind_from_string("orthographic"), InputError);
}

// The warp's exact map: direction → pixel → direction within 1e-9 rad, with offsets.
TEST(Warp, DirectionPixelDirectionRoundTrip) {
  Warp warp = Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {1600, 1200});
  std::mt19937_64 random(2);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int k = 0; k < 5000; ++k) {
    const glm::dvec2 st{unit(random), unit(random)};
    const glm::dvec3 v = warp.v_eye_from_st(st);
    const auto projected = warp.project(v, st.x);
    ASSERT_TRUE(projected && projected->covered);
    EXPECT_NEAR(projected->q.x, st.x * 1600, 1e-6);
    EXPECT_NEAR(projected->q.y, st.y * 1200, 1e-6);
    EXPECT_LE(angle_between(warp.v_eye_from_st(projected->q / glm::dvec2(1600, 1200)), v), 1e-9);
  }
}

// A fisheye master on a dome (DomeOrientation, R_dome_fisheye): the master's centre is the zenith
// (+y) or straight ahead (−z); a tilt moves the zenith toward the front, an orientation turns the
// front toward the right. Exact rotations, so within 1e-12 rad.
TEST(DomeOrientation, PlacesAFisheyeMastersCentreAndFront) {
  const BaseProjection master = BaseProjection::fisheye(180);
  const glm::dvec2 centre{0.5, 0.5}, bottom_middle{0.5, 1.0}, right_middle{1.0, 0.5};
  const glm::dmat3 R_centre = R_dome_fisheye(FisheyeZenith::centre);
  EXPECT_LE(angle_between(R_centre * master.direction(centre), {0, 1, 0}), 1e-12);
  EXPECT_LE(angle_between(R_centre * master.direction(bottom_middle), {0, 0, -1}), 1e-12);
  EXPECT_LE(angle_between(R_centre * master.direction(right_middle), {1, 0, 0}), 1e-12);
  const glm::dmat3 R_front = R_dome_fisheye(FisheyeZenith::front);
  EXPECT_LE(angle_between(R_front * master.direction(centre), {0, 0, -1}), 1e-12);
  for (const double tilt : {-90.0, -20.0, 0.0, 15.0, 30.0, 90.0}) {
    for (const double orientation : {-360.0, -45.0, 0.0, 90.0, 200.0}) {
      SCOPED_TRACE(std::to_string(tilt) + "°, " + std::to_string(orientation) + "°");
      const DomeOrientation dome{tilt, orientation};
      EXPECT_NO_THROW(dome.validate("test"));
      const glm::dmat3 R = dome.R_eye_dome();
      EXPECT_LE(glm::length(glm::dvec3(glm::transpose(R) * R * glm::dvec3(1, 2, 3)) -
                            glm::dvec3(1, 2, 3)),
                1e-12);
      EXPECT_NEAR(glm::determinant(R), 1, 1e-12);
      const double t = glm::radians(tilt), o = glm::radians(orientation);
      const glm::dvec3 zenith{std::sin(o) * std::sin(t), std::cos(t), -std::cos(o) * std::sin(t)};
      EXPECT_LE(angle_between(R * R_centre * master.direction(centre), zenith), 1e-12);
      // The untilted front, turned: −z toward +x by the orientation.
      const glm::dvec3 front = DomeOrientation{0, orientation}.R_eye_dome() * glm::dvec3(0, 0, -1);
      EXPECT_LE(angle_between(front, {std::sin(o), 0, -std::cos(o)}), 1e-12);
    }
  }
  for (const DomeOrientation bad : {DomeOrientation{90.5, 0}, DomeOrientation{-200, 0},
                                    DomeOrientation{0, 361}, DomeOrientation{std::nan(""), 0}}) {
    try {
      bad.validate("command line");
      ADD_FAILURE() << "no error for " << bad.tilt_deg << ", " << bad.orientation_deg;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), bad.orientation_deg == 361 ? "orientation_deg" : "tilt_deg");
    }
  }
  EXPECT_EQ(fisheye_zenith_from_string("center", "s", "--zenith"), FisheyeZenith::centre);
  EXPECT_THROW(fisheye_zenith_from_string("sideways", "s", "--zenith"), InputError);
}

}  // namespace
}  // namespace facet
