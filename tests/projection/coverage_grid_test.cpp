// The coverage grid against the hierarchy walk it replaces: the same facets for every triangle
// (both test candidates exactly), on every base and layout, with the triangles that defeat
// bounding boxes: across the 360° seam, through the eye, through the cylinder axis, around the
// poles of a fisheye, partly behind the eye, and far larger than a facet.
#include "facet/projection/coverage_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <random>

#include "facet/projection/coverage.hpp"
#include "facet/projection/facets.hpp"
#include "random_geometry.hpp"
#include "test_displays.hpp"

namespace facet {
namespace {

using Triangle = std::array<glm::dvec3, 3>;

using test::log_uniform;
using test::random_unit;

// Directions that stress the chart: the base's poles and seam, and the eye-frame axes.
std::vector<glm::dvec3> special_directions(const Warp& warp) {
  std::vector<glm::dvec3> d = {{0, 1, 0}, {0, -1, 0}, {0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {-1, 0, 0}};
  for (glm::dvec3 v : std::vector<glm::dvec3>(d)) d.push_back(warp.R_eye_base * v);
  for (double s : {0.0, 1.0, 0.5})
    for (double t : {0.0, 0.5, 1.0}) d.push_back(warp.v_eye_from_st({s, t}));
  return d;
}

Triangle hostile_triangle(std::mt19937_64& random, const std::vector<glm::dvec3>& special, int k) {
  std::uniform_real_distribution<double> unit(0, 1);
  const double distance = log_uniform(random, 1e-2, 1e4);
  const double size = distance * log_uniform(random, 1e-5, 3);
  glm::dvec3 centre = distance * random_unit(random);
  switch (k % 8) {
    case 0:  // around a special direction (pole, seam, axis)
    case 1:
      centre = distance * special[std::size_t(k / 8) % special.size()];
      break;
    case 2:  // through the vertical axis
      centre = {0.0, centre.y, 0.0};
      break;
    default:
      break;
  }
  Triangle t;
  for (auto& p : t) p = centre + size * random_unit(random);
  if (k % 8 == 3) t[2] = -(t[0] + t[1]) * (0.5 + unit(random));  // surrounds or passes the eye
  if (k % 8 == 4) t[0] = glm::dvec3(0.0);                        // a corner at the eye
  return t;
}

struct Tally {
  std::size_t triangles = 0, by_grid = 0, pairs = 0, differing = 0;
  bool cells = false;
};

Tally compare(const std::string& name, const Warp& warp, const FacetMesh& mesh, int count,
              std::uint64_t seed) {
  const CoverageIndex index(mesh);
  const CoverageGrid grid(mesh, warp.base, warp.R_eye_base);
  const auto special = special_directions(warp);
  std::mt19937_64 random(seed);
  Tally tally;
  std::vector<std::uint32_t> expected, got;
  for (int k = 0; k < count; ++k) {
    const Triangle t = hostile_triangle(random, special, k);
    for (bool cull : {false, true}) {
      expected.clear();
      got.clear();
      index.query(t, expected, cull);
      tally.by_grid += grid.query(t, index, got, cull);
      ++tally.triangles;
      tally.pairs += expected.size();
      if (got != expected) {
        if (++tally.differing < 4) {
          ADD_FAILURE() << name << " triangle " << k << (cull ? " culled" : "") << ": grid "
                        << got.size() << " facets, walk " << expected.size() << "; (" << t[0].x
                        << ", " << t[0].y << ", " << t[0].z << ") (" << t[1].x << ", " << t[1].y
                        << ", " << t[1].z << ") (" << t[2].x << ", " << t[2].y << ", " << t[2].z
                        << ")";
        }
      }
    }
  }
  tally.cells = grid.cell_buckets();
  std::printf(
      "%s: %zu facets, %s %ux%u (pads %.2g, %.2g), %zu queries, %.1f%% by the grid, "
      "%zu pairs\n",
      name.c_str(), mesh.facets.size(), tally.cells ? "cells" : "uniform buckets", grid.columns(),
      grid.rows(), grid.pad_p(), grid.pad_q(), tally.triangles,
      100.0 * double(tally.by_grid) / double(tally.triangles), tally.pairs);
  return tally;
}

TEST(CoverageGrid, EqualsTheWalkOnEveryBaseAndLayout) {
  struct Case {
    std::string name;
    Warp warp;
    FacetLayout layout;
  };
  const glm::dmat3 tilt = glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.5, glm::dvec3(1, 0.3, 0.2)));
  std::vector<Case> cases = {
      {"cylinder 360 strips",
       Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {400, 300}), FacetStrips{40}},
      {"cylinder 360 0.25 px",
       Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {400, 300}),
       FacetTolerance{0.25}},
      {"cylinder 120 behind, tilted",
       Warp::analytic(BaseProjection::cylindrical(120, 240, 0.6, -0.6), {400, 200}, {2, 2}, tilt),
       FacetGrid{12, 4}},
      {"dome 180 16x16", Warp::analytic(BaseProjection::fisheye(180), {256, 256}),
       FacetGrid{16, 16}},
      {"dome 180 28,800 facets", Warp::analytic(BaseProjection::fisheye(180), {256, 256}),
       FacetGrid{120, 120}},
      {"fisheye 220 tilted bisection",
       Warp::analytic(BaseProjection::fisheye(220), {192, 192}, {2, 2}, tilt),
       FacetTolerance{0.5, FacetTolerance::Builder::bisection}},
      {"equirectangular 360x150",
       Warp::analytic(BaseProjection::equirectangular(-180, 180, 75, -75), {384, 192}),
       FacetTolerance{0.5}},
  };
  for (const auto& named : test::displays_for_tolerance_tests()) {
    if (named.name.find("offsets") != std::string::npos)
      cases.push_back({named.name, named.warp, FacetTolerance{0.5}});
  }
  cases.push_back(
      {"perspective 100x70 tilted",
       Warp::analytic(BaseProjection::perspective_fov(100, 70), {400, 300}, {2, 2}, tilt),
       FacetGrid{8, 6}});
  std::uint64_t seed = 1;
  for (const Case& c : cases) {
    const FacetMesh mesh = build_facets(c.warp, {c.layout});
    const Tally tally = compare(c.name, c.warp, mesh, 4000, seed++);
    EXPECT_EQ(tally.differing, 0u) << c.name;
    // Tensor layouts bucket by cell, except on a periodic chart they do not go round.
    const bool part_of_a_turn = c.name.starts_with("cylinder 120");
    EXPECT_EQ(tally.cells, !mesh.s_breaks.empty() && !part_of_a_turn) << c.name;
    // The grid, not the walk, answers most triangles (the rest are huge or pass the eye).
    EXPECT_GT(double(tally.by_grid), 0.5 * double(tally.triangles)) << c.name;
  }
}

TEST(CoverageGrid, BoxesContainEveryDirectionOfTheTriangle) {
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> unit(0, 1);
  for (CoverageChart chart : {CoverageChart::cylindrical, CoverageChart::fisheye}) {
    for (int k = 0; k < 20000; ++k) {
      Triangle t;
      const glm::dvec3 centre = random_unit(random);
      const double size = log_uniform(random, 1e-4, 2);
      for (auto& p : t) p = glm::normalize(centre + size * random_unit(random));
      const DirectionBox box = CoverageGrid::direction_box(t, chart, 0);
      if (box.walk) continue;
      const glm::dvec3 axis =
          chart == CoverageChart::fisheye ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
      for (int s = 0; s < 32; ++s) {
        double a = unit(random), b = unit(random);
        if (a + b > 1) a = 1 - a, b = 1 - b;
        const glm::dvec3 v = glm::normalize(t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]));
        const double theta = std::acos(std::clamp(glm::dot(v, axis), -1.0, 1.0));
        ASSERT_GE(theta, box.theta_lo - 1e-12) << k;
        ASSERT_LE(theta, box.theta_hi + 1e-12) << k;
        if (box.full_phi) continue;
        const double phi =
            chart == CoverageChart::fisheye ? std::atan2(v.y, v.x) : std::atan2(v.x, -v.z);
        const double shifted = box.phi_lo + std::fmod(phi - box.phi_lo + 8 * M_PI, 2 * M_PI);
        ASSERT_LE(shifted, box.phi_hi + 1e-12) << k;
      }
    }
  }
}

// The gnomonic chart box of a triangle in front of a perspective base holds every direction of
// the triangle, and none is given for a triangle with a corner near or behind the base's plane.
TEST(CoverageGrid, GnomonicBoxesContainEveryDirectionOfTheTriangle) {
  const Warp warp = Warp::analytic(BaseProjection::perspective_fov(100, 70), {400, 300});
  const FacetMesh mesh = build_facets(warp, {FacetGrid{8, 6}});
  const CoverageGrid grid(mesh, warp.base, warp.R_eye_base);
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> unit(0, 1);
  int boxed = 0;
  for (int k = 0; k < 20000; ++k) {
    Triangle u;
    const glm::dvec3 centre = random_unit(random);
    const double size = log_uniform(random, 1e-4, 2);
    for (auto& p : u) p = glm::normalize(centre + size * random_unit(random));
    const auto box = grid.gnomonic_box(u);
    const double least_depth = std::min({-u[0].z, -u[1].z, -u[2].z});
    ASSERT_EQ(box.has_value(), least_depth > CoverageGrid::kGnomonicMinDepth) << k;
    if (!box) continue;
    ++boxed;
    for (int s = 0; s < 32; ++s) {
      double a = unit(random), b = unit(random);
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const glm::dvec3 v = u[0] + a * (u[1] - u[0]) + b * (u[2] - u[0]);
      const glm::dvec2 c = glm::dvec2(v.x, v.y) / -v.z;
      ASSERT_GE(c.x, box->p_lo) << k;
      ASSERT_LE(c.x, box->p_hi) << k;
      ASSERT_GE(c.y, box->q_lo) << k;
      ASSERT_LE(c.y, box->q_hi) << k;
    }
  }
  EXPECT_GT(boxed, 2000);
  const Warp cylinder = Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {400, 300});
  const CoverageGrid polar(build_facets(cylinder, {FacetStrips{8}}), cylinder.base,
                           cylinder.R_eye_base);
  const Triangle ahead = {glm::dvec3(0, 0, -1), glm::normalize(glm::dvec3(0.1, 0, -1)),
                          glm::normalize(glm::dvec3(0, 0.1, -1))};
  EXPECT_FALSE(polar.gnomonic_box(ahead).has_value());
  EXPECT_TRUE(grid.gnomonic_box(ahead).has_value());
}

}  // namespace
}  // namespace facet
