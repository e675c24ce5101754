#include "facet/projection/glc.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

const glm::ivec2 kSize{640, 480};
const std::array<glm::dvec2, 3> kCorners = {glm::dvec2(0, 0), glm::dvec2(640, 0),
                                            glm::dvec2(0, 480)};

GlcFrame turned_frame() {
  // A frame turned 30 degrees about y and moved, so that frame and eye coordinates differ.
  const double c = std::cos(0.5236), s = std::sin(0.5236);
  return {{0.3, -0.2, 0.5},
          glm::dmat3(glm::dvec3(c, 0, -s), glm::dvec3(0, 1, 0), glm::dvec3(s, 0, c))};
}

Glc from_rays(std::array<GlcRay, 3> rays) {
  return Glc::from_generators(turned_frame(), rays, kCorners, "test");
}

struct Case {
  std::string name;
  Glc glc;
  GlcType type;
};

// One camera of every type: from generators, and from the constructors.
std::vector<Case> cameras() {
  const glm::dvec2 plane{1.6, 1.2};
  std::vector<Case> cases;
  // Pinhole through frame point (0.1, 0.2, -1): rays from the corners through it.
  cases.push_back({"pinhole",
                   pinhole_glc(turned_frame(), {0.1, 0.2, -1.0}, plane, kSize, "test", "camera"),
                   GlcType::pinhole});
  cases.push_back({"orthographic",
                   from_rays({GlcRay{{-0.8, 0.6}, {-0.7, 0.65}}, GlcRay{{0.8, 0.6}, {0.9, 0.65}},
                              GlcRay{{-0.8, -0.6}, {-0.7, -0.55}}}),
                   GlcType::orthographic});
  cases.push_back({"cross-slit",
                   cross_slit_glc(turned_frame(), SlitLine{{0, 0, -1}, {0, 1, 0}},
                                  SlitLine{{0, 0, -2}, {1, 0, 0}}, plane, kSize, "test", "camera"),
                   GlcType::cross_slit});
  cases.push_back({"pushbroom",
                   pushbroom_glc(turned_frame(), SlitLine{{0, 0, -1}, {0, 1, 0}}, {0, 1, 0}, plane,
                                 kSize, "test", "camera"),
                   GlcType::pushbroom});
  // Pencil: the rays meet the line x = 0, z = 2, and D has its double root there without the
  // rays meeting in one point.
  cases.push_back({"pencil",
                   from_rays({GlcRay{{-0.8, 0.6}, {-0.4, 0.6}}, GlcRay{{0.8, 0.6}, {0.4, 0.7}},
                              GlcRay{{-0.8, -0.6}, {-0.4, 0.0}}}),
                   GlcType::pencil});
  cases.push_back({"twisted-orthographic",
                   from_rays({GlcRay{{-0.5, -0.5}, {-0.5, -0.5}}, GlcRay{{0.5, -0.5}, {0.5, -0.2}},
                              GlcRay{{-0.5, 0.5}, {-0.5, 0.5}}}),
                   GlcType::twisted_orthographic});
  cases.push_back(
      {"bilinear",
       from_rays({GlcRay{{0, 0}, {0, 0}}, GlcRay{{1, 0}, {1, 0.3}}, GlcRay{{0, 1}, {-0.5, 1}}}),
       GlcType::bilinear});
  return cases;
}

TEST(Glc, ClassifiesEveryTypeByItsCharacteristicEquation) {
  for (const Case& c : cameras()) {
    EXPECT_EQ(glc_type_name(c.glc.type()), glc_type_name(c.type)) << c.name;
  }
  const Case cross = cameras()[2];
  ASSERT_EQ(cross.glc.slit_depths().size(), 2u);
  // The slits lie at frame depths -2 and -1 (the constructor's lines).
  EXPECT_NEAR(cross.glc.slit_depths()[0], -2.0, 1e-12);
  EXPECT_NEAR(cross.glc.slit_depths()[1], -1.0, 1e-12);
  ASSERT_EQ(cameras()[0].glc.slit_depths().size(), 1u);
  EXPECT_NEAR(cameras()[0].glc.slit_depths()[0], -1.0, 1e-12);
}

// The pixel whose ray passes through p, found by casting rays: Gauss-Newton on the point where
// the ray of a pixel reaches p's frame depth, with the Jacobian from rays one pixel apart (the
// closed form's 2×2 solve is not used).
glm::dvec2 cast_for(const Glc& glc, const glm::dvec3& p_eye) {
  const glm::dmat3 to_frame = glm::transpose(glc.frame().axes);
  const double z = (to_frame * (p_eye - glc.frame().origin)).z;
  auto reach = [&](glm::dvec2 pixel) {
    const EyeRay r = glc.ray(pixel);
    return glm::dvec2(to_frame * (r.origin + z * r.direction - p_eye));
  };
  glm::dvec2 pixel{320, 240};
  for (int i = 0; i < 4; ++i) {
    const glm::dvec2 f = reach(pixel);
    const glm::dvec2 jx = reach(pixel + glm::dvec2(1, 0)) - f;
    const glm::dvec2 jy = reach(pixel + glm::dvec2(0, 1)) - f;
    pixel -= glm::inverse(glm::dmat2(jx, jy)) * f;
  }
  return pixel;
}

TEST(Glc, ClosedFormProjectionMatchesRayCastingWithinAMicropixel) {
  std::mt19937 random(17);
  for (const Case& c : cameras()) {
    std::uniform_real_distribution<double> pixel_x(-320, 960), pixel_y(-240, 720), depth(0.2, 20);
    double worst_px = 0, worst_m = 0;
    int tested = 0;
    for (int k = 0; k < 2000; ++k) {
      // A point on the ray of a random pixel at a random depth, away from slit depths.
      const double z = depth(random);
      bool near_slit = false;
      for (double s : c.glc.slit_depths()) near_slit |= std::abs(z - s) < 0.05;
      if (near_slit) continue;
      const EyeRay r = c.glc.ray({pixel_x(random), pixel_y(random)});
      const glm::dvec3 p = r.origin + z * r.direction;
      const auto projected = c.glc.project(p);
      ASSERT_TRUE(projected) << c.name;
      EXPECT_NEAR(projected->depth, z, 1e-9 * z) << c.name;
      worst_px = std::max(worst_px, glm::length(projected->pixel - cast_for(c.glc, p)));
      // The projected pixel's own ray passes through the point.
      const EyeRay back = c.glc.ray(projected->pixel);
      const glm::dvec3 d = glm::normalize(back.direction);
      const glm::dvec3 off = p - back.origin;
      worst_m = std::max(worst_m, glm::length(off - glm::dot(off, d) * d));
      ++tested;
    }
    EXPECT_GT(tested, 1500) << c.name;
    EXPECT_LT(worst_px, 1e-6) << c.name << ": worst pixel distance to the cast pixel";
    EXPECT_LT(worst_m, 1e-9) << c.name << ": worst distance from the pixel's ray, metres";
  }
}

TEST(Glc, ProjectionIsSingularOnlyAtSlitDepths) {
  const Glc cross = cameras()[2].glc;
  const glm::dmat3 axes = cross.frame().axes;
  // A frame point at the slit depth -1 projects nowhere (or anywhere on a line).
  EXPECT_FALSE(cross.project(cross.frame().origin + axes * glm::dvec3(0.3, 0.2, -1.0)));
  EXPECT_TRUE(cross.project(cross.frame().origin + axes * glm::dvec3(0.3, 0.2, -1.5)));
  EXPECT_FALSE(cross.project({std::nan(""), 0, 0}));
}

TEST(Glc, TriangleBoundsHoldEveryPointOfTheTriangle) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-3, 3), depth(-1, 12), unit(0, 1);
  for (const Case& c : cameras()) {
    int bounded = 0;
    for (int k = 0; k < 300; ++k) {
      const glm::dmat3 axes = c.glc.frame().axes;
      std::array<glm::dvec3, 3> v;
      for (auto& p : v) {
        p = c.glc.frame().origin +
            axes * glm::dvec3(coordinate(random), coordinate(random), depth(random));
      }
      const auto bounds = c.glc.triangle_bounds(v[0], v[1], v[2], 0.05, 0.0);
      if (!bounds) continue;
      bounded += std::isfinite(bounds->min.x);
      for (int s = 0; s < 400; ++s) {
        double a = unit(random), b = unit(random);
        if (a + b > 1) a = 1 - a, b = 1 - b;
        const glm::dvec3 p = v[0] + a * (v[1] - v[0]) + b * (v[2] - v[0]);
        const auto projected = c.glc.project(p);
        if (!projected || projected->depth < 0.05) continue;
        // The bound is exact up to rounding: no pad was asked for.
        const double slack = 1e-7 * (1 + glm::length(projected->pixel));
        ASSERT_GE(projected->pixel.x, bounds->min.x - slack) << c.name << " triangle " << k;
        ASSERT_LE(projected->pixel.x, bounds->max.x + slack) << c.name << " triangle " << k;
        ASSERT_GE(projected->pixel.y, bounds->min.y - slack) << c.name << " triangle " << k;
        ASSERT_LE(projected->pixel.y, bounds->max.y + slack) << c.name << " triangle " << k;
      }
    }
    EXPECT_GT(bounded, 50) << c.name;
  }
  // Wholly behind z_near: no pixels.
  const Glc pinhole = cameras()[0].glc;
  const glm::dmat3 axes = pinhole.frame().axes;
  const glm::dvec3 o = pinhole.frame().origin;
  EXPECT_FALSE(pinhole.triangle_bounds(o + axes * glm::dvec3(0, 0, -0.5),
                                       o + axes * glm::dvec3(1, 0, -0.5),
                                       o + axes * glm::dvec3(0, 1, 0.01), 0.05));
}

TEST(Glc, TriangleAcrossASlitIsUnbounded) {
  const Glc cross = cameras()[2].glc;  // slits at -2 and -1; a camera seeing z > 0 only has none
  const GlcFrame frame = turned_frame();
  // A camera whose slit lies in front: a pinhole with its centre at depth 2.
  const Glc ahead = pinhole_glc(frame, {0, 0, 2}, {1.6, 1.2}, kSize, "test", "camera");
  const glm::dvec3 o = frame.origin;
  const auto across = ahead.triangle_bounds(o + frame.axes * glm::dvec3(-1, 0, 1),
                                            o + frame.axes * glm::dvec3(1, 0, 3),
                                            o + frame.axes * glm::dvec3(0, 1, 3), 0.05);
  ASSERT_TRUE(across);
  EXPECT_TRUE(std::isinf(across->max.x));
  const auto before = ahead.triangle_bounds(o + frame.axes * glm::dvec3(-1, 0, 1),
                                            o + frame.axes * glm::dvec3(1, 0, 1.5),
                                            o + frame.axes * glm::dvec3(0, 1, 1.5), 0.05);
  ASSERT_TRUE(before);
  EXPECT_TRUE(std::isfinite(before->max.x));
  EXPECT_TRUE(cross.triangle_bounds(o + frame.axes * glm::dvec3(-1, 0, 1),
                                    o + frame.axes * glm::dvec3(1, 0, 3),
                                    o + frame.axes * glm::dvec3(0, 1, 3), 0.05));
}

TEST(Glc, IntersectGivesTheFrameDepthOfTheHit) {
  const Glc glc = cameras()[2].glc;
  const EyeRay r = glc.ray({100.5, 200.5});
  const glm::dvec3 hit = r.origin + 3.0 * r.direction;
  const glm::dvec3 u = glm::normalize(glm::cross(r.direction, glm::dvec3(0, 1, 0)));
  const glm::dvec3 w = glm::normalize(glm::cross(r.direction, u));
  const auto t = Glc::intersect(r, hit - u - w, hit + 2.0 * u - w, hit + 2.0 * w, 0.05);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 3.0, 1e-12);
  EXPECT_FALSE(Glc::intersect(r, hit - u - w, hit + 2.0 * u - w, hit + 2.0 * w, 3.5));
  EXPECT_FALSE(Glc::intersect(r, hit + u, hit + 2.0 * u, hit + u + w, 0.05));
}

// The error's field, for checks that name it.
template <typename F>
std::string refused_field(F make) {
  try {
    make();
  } catch (const InputError& e) {
    return e.field();
  }
  return "(accepted)";
}

TEST(Glc, DegenerateGeneratorsAreRefusedNamingTheField) {
  const GlcFrame frame;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::array<GlcRay, 3> good = {GlcRay{{0, 0}, {0, 0}}, GlcRay{{1, 0}, {1, 0.3}},
                                      GlcRay{{0, 1}, {0.5, 1}}};
  auto with = [&](std::size_t k, GlcRay r) {
    auto rays = good;
    rays[k] = r;
    return rays;
  };
  EXPECT_EQ(refused_field([&] {
              Glc::from_generators(frame, with(1, {{nan, 0}, {1, 0}}), kCorners, "c.json",
                                   "camera.generators");
            }),
            "camera.generators[1]");
  EXPECT_EQ(refused_field([&] {
              Glc::from_generators(frame, with(2, good[0]), kCorners, "c.json",
                                   "camera.generators");
            }),
            "camera.generators[2]");
  // Parallel to the image plane: no two-plane form.
  EXPECT_EQ(refused_field([&] {
              Glc::from_frame_rays(frame,
                                   {EyeRay{{0, 0, 0}, {0, 0, 1}}, EyeRay{{1, 0, 0}, {1, 0, 0}},
                                    EyeRay{{0, 1, 0}, {0, 0, 1}}},
                                   kCorners, "c.json", "camera.generators");
            }),
            "camera.generators[1].direction");
  EXPECT_EQ(refused_field([&] {
              Glc::from_frame_rays(frame,
                                   {EyeRay{{0, 0, 0}, {0, 0, 1}}, EyeRay{{1, 0, 0}, {0, 0, 0}},
                                    EyeRay{{0, 1, 0}, {0, 0, 1}}},
                                   kCorners, "c.json", "camera.generators");
            }),
            "camera.generators[1].direction");
  // Three parallel rays in one plane: an epipolar-plane camera.
  EXPECT_EQ(refused_field([&] {
              Glc::from_generators(
                  frame,
                  {GlcRay{{0, 0}, {0.1, 0}}, GlcRay{{1, 0}, {1.1, 0}}, GlcRay{{2, 0}, {2.1, 0}}},
                  kCorners, "c.json", "camera.generators");
            }),
            "camera.generators");
  EXPECT_EQ(refused_field([&] {
              Glc::from_generators(frame, good, {glm::dvec2(0, 0), {1, 1}, {2, 2}}, "c.json",
                                   "camera.generators");
            }),
            "camera.generators");
  EXPECT_EQ(refused_field([&] {
              Glc::from_generators(frame, good, {glm::dvec2(0, 0), {1, nan}, {2, 2}}, "c.json",
                                   "camera.generators");
            }),
            "camera.generators[1].pixel");
  GlcFrame skew;
  skew.axes[2] = glm::dvec3(0, 0.5, 1);
  EXPECT_EQ(refused_field(
                [&] { Glc::from_generators(skew, good, kCorners, "c.json", "camera.generators"); }),
            "camera.generators.frame");
  // Slits that are parallel, or meet.
  EXPECT_EQ(refused_field([&] {
              cross_slit_glc(frame, {{0, 0, -1}, {0, 1, 0}}, {{0, 0, -2}, {0, 2, 0}}, {1, 1}, kSize,
                             "c.json", "camera");
            }),
            "camera.slit2");
  EXPECT_EQ(refused_field([&] {
              cross_slit_glc(frame, {{0, 0, -1}, {0, 1, 0}}, {{0, 0, -1}, {1, 0, 0}}, {1, 1}, kSize,
                             "c.json", "camera");
            }),
            "camera.slit2");
  EXPECT_EQ(refused_field([&] {
              cross_slit_glc(frame, {{0, 0, -1}, {nan, 1, 0}}, {{0, 0, -2}, {1, 0, 0}}, {1, 1},
                             kSize, "c.json", "camera");
            }),
            "camera.slit1");
  EXPECT_EQ(refused_field([&] {
              cross_slit_glc(frame, {{0, 0, -1}, {0, 1, 0}}, {{0, 0, -2}, {1, 0, 0}}, {1, 1},
                             {100000, 100000}, "c.json", "camera");
            }),
            "camera.size");
}

TEST(Glc, PanoramaStripsAreCrossSlitsThatMeetAtTheirSeams) {
  for (double angle : {270.0, 360.0}) {
    const PiecewiseGlc pano = circular_panorama(angle, 0.2, 90, 40, {800, 600}, "test", "camera");
    ASSERT_EQ(pano.pieces.size(), 40u);
    for (std::size_t k = 0; k < pano.pieces.size(); ++k) {
      EXPECT_EQ(glc_type_name(pano.pieces[k].type()), "cross-slit") << k;
      // At a seam both strips give the same ray (their generators are the exact rays there).
      if (k + 1 < pano.pieces.size()) {
        const double x = pano.piece_boxes[k].z;
        for (double y : {0.0, 150.5, 600.0}) {
          // One line: parallel directions, and b's origin on a's line (the strips' image planes
          // differ, so the origins do).
          const EyeRay a = pano.pieces[k].ray({x, y}), b = pano.pieces[k + 1].ray({x, y});
          const glm::dvec3 da = glm::normalize(a.direction), db = glm::normalize(b.direction);
          EXPECT_LT(glm::length(da - db), 1e-12) << angle << " seam " << k;
          const glm::dvec3 off = b.origin - a.origin;
          EXPECT_LT(glm::length(off - glm::dot(off, da) * da), 1e-12) << angle << " seam " << k;
        }
      }
    }
    EXPECT_EQ(pano.wraps_horizontally, angle == 360.0);
    // Every pixel has a piece; the middle column looks down -z, level at the middle row.
    for (std::int32_t p : pano.piece_of_pixel) ASSERT_GE(p, 0);
    const auto middle = pano.ray(400, 300);
    ASSERT_TRUE(middle);
    const glm::dvec3 d = glm::normalize(middle->direction);
    EXPECT_NEAR(d.z, -1.0, 1e-4);
  }
  EXPECT_EQ(refused_field([] {
              circular_panorama(360, 0.2, 90, 2, {800, 600}, "t", "camera");
            }),
            "camera.strips");
  EXPECT_EQ(refused_field([] {
              circular_panorama(400, 0.2, 90, 40, {800, 600}, "t", "camera");
            }),
            "camera.angle_deg");
}

TEST(Glc, MirrorSphereReflectsAtEveryPiecesVertices) {
  const glm::dvec3 centre{0, 0, -3};
  const PiecewiseGlc mirror = mirror_sphere(centre, 1.0, 60, 24, {512, 512}, "test", "camera");
  ASSERT_GT(mirror.pieces.size(), 300u);
  std::size_t covered = 0;
  for (std::int32_t p : mirror.piece_of_pixel) covered += p >= 0;
  // The sphere's disc: tan(asin(1/3)) = 1/sqrt(8) against tan(30°) of the half-width, a radius
  // of 156.8 px: 77240 pixels, less the silhouette band left out and the inscribed mesh's loss.
  EXPECT_GT(covered, 60000u);
  EXPECT_LT(covered, 77240u);
  // The centre pixel looks straight at the sphere and is reflected straight back.
  const auto back = mirror.ray(256, 256);
  ASSERT_TRUE(back);
  EXPECT_NEAR(back->origin.z, -2.0, 0.02);
  EXPECT_GT(glm::normalize(back->direction).z, 0.999);
  // At every piece's generator pixels the ray starts on the sphere and obeys the mirror law.
  for (const Glc& piece : mirror.pieces) {
    for (const glm::dvec2 pixel : {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(0, 1)}) {
      const glm::dvec2 image = glm::dvec2(piece.pixel_from_ab() * glm::dvec3(pixel, 1.0));
      const EyeRay r = piece.ray(image);
      ASSERT_NEAR(glm::length(r.origin - centre), 1.0, 1e-9);
      const glm::dvec3 n = glm::normalize(r.origin - centre);
      const glm::dvec3 in = glm::normalize(r.origin);
      const glm::dvec3 out = glm::normalize(r.direction);
      ASSERT_NEAR(glm::length(out - (in - 2 * glm::dot(in, n) * n)), 0.0, 1e-9);
    }
  }
  EXPECT_EQ(refused_field([] {
              mirror_sphere({0, 0, -0.5}, 1.0, 60, 24, {64, 64}, "t", "c");
            }),
            "c.centre");
}

}  // namespace
}  // namespace facet
