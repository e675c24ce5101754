#include "facet/projection/rig.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "facet/projection/errors.hpp"
#include "facet/projection_io/rig_file.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;

// A camera-like frame (x right, y down, z forward) looking from `from` towards `to`, up +y.
glm::dmat3 look(const glm::dvec3& from, const glm::dvec3& to, glm::dvec3 up = {0, 1, 0}) {
  const glm::dvec3 forward = glm::normalize(to - from);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
  return glm::dmat3(right, glm::cross(forward, right), forward);
}

ProjectorModel wide_projector(glm::ivec2 size = {200, 150}) {
  ProjectorModel p;
  p.name = "p0";
  p.size = size;
  p.focal_px = {0.45 * size.x, 0.46 * size.x};
  p.principal_px = {0.52 * size.x, 0.6 * size.y};
  p.k = {-0.08, 0.01, -0.0005};
  p.t_eye_projector = {0.4, -0.3, 0.8};
  p.R_eye_projector = look(p.t_eye_projector, {1, 2, -4});
  p.gamma = 2.2;
  return p;
}

Rig dome_rig() {
  Rig rig;
  rig.screen.type = Screen::Type::sphere;
  rig.screen.radius = 5;
  rig.screen.center = {0, 0.2, 0};
  rig.projectors = {wide_projector()};
  rig.camera.size = {160, 120};
  return rig;
}

TEST(Screen, SphereFromInsideHitsTheOnePositiveRoot) {
  Screen sphere;
  sphere.radius = 2;
  sphere.center = {0.5, 0, 0};
  const glm::dvec3 origin(0.2, 0.3, -0.1);
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  for (int k = 0; k < 100; ++k) {
    const glm::dvec3 v(normal(rng), normal(rng), normal(rng));
    const auto p = screen_hit(sphere, origin, v);
    ASSERT_TRUE(p.has_value());
    EXPECT_NEAR(glm::length(*p - sphere.center), 2.0, 1e-12);
    EXPECT_GT(glm::dot(*p - origin, v), 0);
    // The inward normal faces the origin from the hit point.
    EXPECT_GT(glm::dot(screen_normal(sphere, *p), origin - *p), 0);
  }
  // From outside, the far wall: the larger root.
  const auto t = intersect_screen(sphere, {-5, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 7.5, 1e-12);
  // Pointing away from an outside sphere: no hit.
  EXPECT_FALSE(intersect_screen(sphere, {-5, 0, 0}, {-1, 0, 0}).has_value());
}

TEST(Screen, CylinderAndPlane) {
  Screen cylinder;
  cylinder.type = Screen::Type::cylinder;
  cylinder.radius = 3;
  cylinder.axis = {0, 1, 0};
  const auto p = screen_hit(cylinder, {0, 0, 0}, {1, 10, 0});
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x, 3, 1e-12);
  EXPECT_NEAR(p->y, 30, 1e-12);
  EXPECT_FALSE(intersect_screen(cylinder, {0, 0, 0}, {0, 1, 0}).has_value());  // along the axis

  Screen plane;
  plane.type = Screen::Type::plane;
  plane.point = {0, 0, -3};
  plane.normal = {0, 0, 1};
  const auto q = screen_hit(plane, {1, 1, 0}, {0, 0, -2});
  ASSERT_TRUE(q.has_value());
  EXPECT_NEAR(q->z, -3, 1e-12);
  EXPECT_NEAR(*intersect_screen(plane, {1, 1, 0}, {0, 0, -2}), 1.5, 1e-12);
  EXPECT_FALSE(intersect_screen(plane, {0, 0, 0}, {0, 0, 1}).has_value());  // behind
  EXPECT_FALSE(intersect_screen(plane, {0, 0, 0}, {1, 0, 0}).has_value());  // parallel
}

TEST(ProjectorModel, PixelRayPixelRoundTripWithin1e9Px) {
  const ProjectorModel p = wide_projector({1024, 768});
  ASSERT_TRUE(std::isinf(p.max_undistorted_radius()) ||
              p.max_undistorted_radius() > 2.0);  // well beyond this image's corners
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec2 q(u(rng) * p.size.x, u(rng) * p.size.y);
    const auto v = p.v_eye_from_q(q);
    ASSERT_TRUE(v.has_value());
    const auto back = p.q_from_p_eye(p.t_eye_projector + (1 + 9 * u(rng)) * *v);
    ASSERT_TRUE(back.has_value());
    worst = std::max(worst, glm::length(*back - q));
  }
  EXPECT_LE(worst, 1e-9);
  EXPECT_FALSE(p.q_from_p_eye(p.t_eye_projector - p.R_eye_projector[2]).has_value());  // behind
}

TEST(ProjectorModel, DomainEndsWhereTheDistortionFoldsBack) {
  ProjectorModel p = wide_projector();
  p.k = {-0.2, 0, 0};  // r(1 − 0.2 r²) peaks at r = sqrt(1/0.6)
  EXPECT_NEAR(p.max_undistorted_radius(), std::sqrt(1 / 0.6), 1e-9);
  EXPECT_TRUE(p.monotonic_up_to(1.2));
  EXPECT_FALSE(p.monotonic_up_to(1.4));
  const glm::dvec3 p_far = p.R_eye_projector * glm::dvec3(1.4, 0, 1) + p.t_eye_projector;
  EXPECT_FALSE(p.q_from_p_eye(p_far).has_value());
  // Pixels beyond the fold's distorted radius have no ray.
  const double r_d_max = p.distorted_radius(p.max_undistorted_radius());
  EXPECT_FALSE(p.v_eye_from_q(p.principal_px + glm::dvec2(1.01 * r_d_max * p.focal_px.x, 0)));
  EXPECT_TRUE(p.v_eye_from_q(p.principal_px + glm::dvec2(0.99 * r_d_max * p.focal_px.x, 0)));
  // A rig whose image corners lie beyond the fold is rejected, naming the field.
  Rig rig = dome_rig();
  rig.projectors[0].k = {-0.6, 0, 0};
  try {
    rig.validate("r.json");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "projectors[0].distortion");
  }
}

// Worst distance between the warp and the exact geometry over random covered directions.
double worst_warp_error(const Rig& rig, const Warp& warp, int samples, int* covered_count) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  *covered_count = 0;
  const ProjectorModel& p = rig.projectors[0];
  for (int k = 0; k < samples; ++k) {
    const glm::dvec2 st(u(rng), u(rng));
    const glm::dvec3 v = warp.v_eye_from_st(st);
    const auto exact = exact_projector_pixel(rig.screen, p, v);
    if (!exact || exact->x < 0 || exact->y < 0 || exact->x > p.size.x || exact->y > p.size.y) {
      continue;
    }
    const auto projected = warp.project(v, st.x);
    if (!projected) {
      ADD_FAILURE() << "no warp value at covered st " << st.x << "," << st.y;
      continue;
    }
    ++*covered_count;
    worst = std::max(worst, glm::length(projected->q - *exact));
  }
  return worst;
}

TEST(TrueWarp, BilinearWarpWithin001PxOfTheExactGeometryWorstCase) {
  for (const auto type : {Screen::Type::sphere, Screen::Type::cylinder, Screen::Type::plane}) {
    Rig rig = dome_rig();
    rig.screen.type = type;
    if (type == Screen::Type::cylinder) rig.screen.axis = glm::normalize(glm::dvec3(0.1, 1, 0));
    if (type == Screen::Type::plane) {
      rig.screen.point = {0, 0, -4};
      rig.screen.normal = glm::normalize(glm::dvec3(-0.2, -0.3, 1));
      rig.projectors[0].R_eye_projector = look(rig.projectors[0].t_eye_projector, {1, 1, -4});
    }
    TrueWarpReport report;
    const Warp warp = true_warp(rig, 0, {}, &report);
    EXPECT_NO_THROW(warp.validate("true warp"));
    int covered = 0;
    const double worst = worst_warp_error(rig, warp, 40000, &covered);
    SCOPED_TRACE(to_string(warp.base.kind));
    EXPECT_GT(covered, 4000);  // the base is not mostly wasted
    EXPECT_LE(worst, 0.01);
    EXPECT_LE(report.max_checked_error_px, 0.004);
  }
}

TEST(TrueWarp, CoverageMatchesTheProjectorImage) {
  const Rig rig = dome_rig();
  const Warp warp = true_warp(rig, 0);
  const ProjectorModel& p = rig.projectors[0];
  // Directions through pixel centres one pixel inside the edge are covered; directions one
  // node spacing plus one pixel outside are not.
  const double node_px = std::max(double(p.size.x) / (warp.grid_size.x - 1),
                                  double(p.size.y) / (warp.grid_size.y - 1));
  EXPECT_LT(node_px, 20);
  for (int k = 0; k <= 50; ++k) {
    const double f = k / 50.0;
    for (const glm::dvec2 q : {glm::dvec2(1.5, 1 + f * (p.size.y - 2)),
                               glm::dvec2(p.size.x - 1.5, 1 + f * (p.size.y - 2))}) {
      const auto v = p.v_eye_from_q(q);
      const auto hit = screen_hit(rig.screen, p.t_eye_projector, *v);
      const auto projected = warp.project(*hit);
      ASSERT_TRUE(projected.has_value());
      EXPECT_TRUE(projected->covered) << q.x << "," << q.y;
    }
  }
}

TEST(RigFile, RoundTripIsExact) {
  Rig rig = dome_rig();
  rig.projectors.push_back(wide_projector());
  rig.projectors[1].name = "p1";
  rig.projectors[1].k = {0.01, 0, 0};
  rig.camera.lensmodel = "LENSMODEL_OPENCV8";
  rig.camera.intrinsics = {100, 101, 79.5, 59.5, 0.1, -0.01, 0, 0, 0, 0, 0, 0};
  rig.camera.t_eye_camera = {0.1 / 3, 0.2, -1.0 / 7};
  rig.simulation.noise = 0.0123456789;
  rig.simulation.seed = 1234567890123ull;
  rig.simulation.bits = 8;
  const Rig back = parse_rig(format_rig(rig), "round trip");
  EXPECT_EQ(back, rig);
}

TEST(RigFile, LookAtAndFovDegMakeTheSamePoseAsMatrices) {
  const std::string text = R"({"format": "facet-rig/1",
    "screen": {"type": "plane", "point": [0, 0, -3], "normal": [0, 0, 2]},
    "projectors": [{"name": "a", "size": [100, 50], "fov_deg": 90,
                    "t_eye_projector": [0, 0, 1], "look_at": [0, 0, -3]}],
    "camera": {"lensmodel": "LENSMODEL_PINHOLE", "size": [64, 48], "fov_deg": 60}})";
  const Rig rig = parse_rig(text, "inline");
  const ProjectorModel& p = rig.projectors[0];
  EXPECT_NEAR(p.focal_px.x, 50, 1e-12);
  EXPECT_EQ(p.principal_px, glm::dvec2(50, 25));
  EXPECT_NEAR(glm::length(p.R_eye_projector[2] - glm::dvec3(0, 0, -1)), 0, 1e-12);
  EXPECT_NEAR(glm::length(p.R_eye_projector[1] - glm::dvec3(0, -1, 0)), 0, 1e-12);  // y down
  EXPECT_NEAR(rig.screen.normal.z, 1, 1e-12);                                       // normalised
  EXPECT_EQ(rig.simulation, SimulationSettings{});
}

void expect_error(const std::string& text, const std::string& field) {
  try {
    parse_rig(text, "bad.json");
    ADD_FAILURE() << "expected an InputError naming " << field;
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "bad.json");
    EXPECT_EQ(error.field(), field) << error.what();
  }
}

TEST(RigFile, BadFieldsNameFileAndField) {
  const std::string head = R"({"format": "facet-rig/1", "screen": )";
  const std::string sphere = R"({"type": "sphere", "center": [0,0,0], "radius": 5})";
  const std::string projector =
      R"({"name": "p0", "size": [64, 48], "fov_deg": 90, "look_at": [0, 0, -1]})";
  const std::string camera =
      R"({"lensmodel": "LENSMODEL_STEREOGRAPHIC", "size": [160, 120], "fov_deg": 180})";
  auto rig = [&](const std::string& screen, const std::string& p, const std::string& c,
                 const std::string& extra = "") {
    return head + screen + R"(, "projectors": [)" + p + R"(], "camera": )" + c + extra + "}";
  };
  EXPECT_NO_THROW(parse_rig(rig(sphere, projector, camera), "good.json"));
  expect_error("{", "");
  expect_error(R"({"format": "facet-rig/1", "x-big": 1e999})", "");  // beyond a double's range
  expect_error(R"({"format": "facet-rig/2"})", "format");
  expect_error(rig(R"({"type": "sphere", "center": [0,0,0], "radius": -1})", projector, camera),
               "screen.radius");
  expect_error(rig(R"({"type": "sphere", "center": [0,0,0], "radius": 1e300})", projector, camera),
               "screen.radius");
  expect_error(rig(R"({"type": "plane", "point": [0,0,-3], "normal": [0,0,0]})", projector, camera),
               "screen.normal");
  expect_error(rig(R"({"type": "sphere", "center": [0,0,0], "radius": 5, "axis": [0,1,0]})",
                   projector, camera),
               "screen.axis");
  expect_error(rig(R"({"type": "cone"})", projector, camera), "screen.type");
  expect_error(rig(sphere, R"({"name": "p0", "size": [64, 48], "look_at": [0,0,-1]})", camera),
               "projectors[0].focal_px");
  expect_error(
      rig(sphere, R"({"name": "p/0", "size": [64, 48], "fov_deg": 90, "look_at": [0,0,-1]})",
          camera),
      "projectors[0].name");
  expect_error(
      rig(sphere, R"({"name": "p0", "size": [64], "fov_deg": 90, "look_at": [0,0,-1]})", camera),
      "projectors[0].size");
  expect_error(
      rig(sphere,
          R"({"name": "p0", "size": [64, 48], "fov_deg": 90, "look_at": [0,1,0], "up": [0,1,0]})",
          camera),
      "projectors[0].up");
  expect_error(
      rig(sphere,
          R"({"name": "p0", "size": [64, 48], "fov_deg": 90, "R_eye_projector": [[1,0,0],[0,1,0],[0,0,2]]})",
          camera),
      "projectors[0].R_eye_projector");
  expect_error(rig(sphere, projector + "," + projector, camera), "projectors[1].name");
  expect_error(
      rig(sphere, projector, R"({"lensmodel": "LENSMODEL_STEREOGRAPHIC", "size": [0, 120]})"),
      "camera.size");
  expect_error(rig(sphere, projector, camera, R"(, "simulation": {"bits": 12})"),
               "simulation.bits");
  expect_error(rig(sphere, projector, camera, R"(, "simulation": {"noise": "high"})"),
               "simulation.noise");
  expect_error(rig(sphere, projector, camera, R"(, "simulation": {"phase_steps": 2})"),
               "simulation.phase_steps");

  // Unknown keys are refused by their path, with the nearest known key; "x-" keys are notes.
  expect_error(rig(sphere, projector, camera, R"(, "simulaton": {})"), "simulaton");
  expect_error(rig(sphere, projector, camera, R"(, "simulation": {"nosie": 0.1})"),
               "simulation.nosie");
  expect_error(rig(R"({"type": "sphere", "center": [0,0,0], "radius": 5, "axis": [0,1,0]})",
                   projector, camera),
               "screen.axis");
  const std::string typo =
      R"({"lensmodel": "LENSMODEL_STEREOGRAPHIC", "size": [160, 120], "fov_dge": 180})";
  expect_error(rig(sphere, projector, typo), "camera.fov_dge");
  try {
    parse_rig(rig(sphere, projector, typo), "bad.json");
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "bad.json: field 'camera.fov_dge': unknown field 'fov_dge'; did you mean 'fov_deg'? "
              "(keys starting with \"x-\" are free for notes)");
  }
  expect_error(rig(sphere, R"({"name": "p0", "size": [64, 48], "fov_deg": 90, "lookat": [0,0,-1],
                               "R_eye_projector": [[1,0,0],[0,1,0],[0,0,1]]})",
                   camera),
               "projectors[0].lookat");
  EXPECT_NO_THROW(parse_rig(
      rig(sphere,
          R"({"name": "p0", "size": [64, 48], "fov_deg": 90, "look_at": [0, 0, -1], "x-lamp": 900})",
          camera, R"(, "x-note": {"by": "me"}, "simulation": {"x-why": "dim room"})"),
      "notes.json"));
  // Alternatives a reader skips stay known: focal_px wins over fov_deg, a matrix over look_at.
  EXPECT_NO_THROW(parse_rig(rig(sphere,
                                R"({"name": "p0", "size": [64, 48], "focal_px": [40, 40],
                                    "fov_deg": 90, "R_eye_projector": [[1,0,0],[0,1,0],[0,0,1]],
                                    "look_at": [0, 0, -1], "up": [0, 1, 0]})",
                                camera),
                            "both.json"));
}

TEST(RigFile, ShippedRigsLoad) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(
           std::filesystem::path(FACET_SOURCE_DIR) / "configs/rigs")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    const Rig rig = read_rig(entry.path());
    EXPECT_EQ(parse_rig(format_rig(rig), "round trip"), rig);
    // The same rig is compiled in under its file name, so it loads from any folder.
    EXPECT_EQ(load_rig("builtin:" + entry.path().stem().string()), rig);
    ++loaded;
  }
  EXPECT_EQ(loaded, 3);
  EXPECT_EQ(builtin_rig_names(), (std::vector<std::string>{"cylinder3", "dome4", "wall2x2"}));
}

TEST(RigFile, UnknownBuiltinRigNamesTheKnownOnes) {
  try {
    load_rig("builtin:dome5");
    FAIL() << "builtin:dome5 loaded";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("builtin:dome5"), std::string::npos) << message;
    EXPECT_NE(message.find("builtin:cylinder3, builtin:dome4, builtin:wall2x2"), std::string::npos)
        << message;
  }
  // Without the prefix a name is a path.
  EXPECT_THROW(load_rig("dome4"), InputError);
}

}  // namespace
}  // namespace facet
