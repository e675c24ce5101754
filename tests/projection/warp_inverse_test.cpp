// The warp inverse: q → st → q round trips at every output pixel centre, completeness (every
// forward-mapped covered st is found again), exact answers on a shifted map, coverage holes, and
// a real 33×33 dome warp (SimCAD mesh from the shared data).
#include "facet/projection/warp_inverse.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "test_displays.hpp"

namespace facet {
namespace {

// Worst-case q → st → q round-trip error in output pixels over every pixel centre, and how many
// centres were found covered.
struct RoundTrip {
  double worst_px = 0;
  std::size_t covered = 0;
};

RoundTrip round_trip_pixel_centres(const WarpInverse& inverse) {
  const Warp& warp = inverse.warp();
  const auto st = inverse.st_at_pixel_centres();
  RoundTrip result;
  for (int y = 0; y < warp.output_size.y; ++y) {
    for (int x = 0; x < warp.output_size.x; ++x) {
      const glm::dvec2 found = st[std::size_t(y) * warp.output_size.x + x];
      if (std::isnan(found.x)) continue;
      ++result.covered;
      const glm::dvec2 q(x + 0.5, y + 0.5);
      result.worst_px = std::max(result.worst_px, glm::length(warp.q_from_st(found) - q));
    }
  }
  return result;
}

// Forward-maps random covered st, inverts q, and returns the worst st error (in base-image
// units) over the samples; every sample must be found.
double worst_forward_then_inverse(const WarpInverse& inverse, int samples, std::uint32_t seed) {
  const Warp& warp = inverse.warp();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst = 0;
  for (int k = 0; k < samples; ++k) {
    const glm::dvec2 st(unit(rng), unit(rng));
    if (warp.coverage_at(st) < 0.5) continue;
    const glm::dvec2 q = warp.q_from_st(st);
    const auto back = inverse.st_from_q(q);
    if (!back) {
      ADD_FAILURE() << "covered st (" << st.x << ", " << st.y << ") at q (" << q.x << ", " << q.y
                    << ") not found";
      return INFINITY;
    }
    worst = std::max(worst, glm::length(*back - st));
  }
  return worst;
}

TEST(WarpInverse, AnalyticDisplaysRoundTripEveryPixelCentre) {
  std::vector<test::NamedWarp> displays = {
      {"cylinder 360x90 800x600",
       Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {800, 600})},
      {"dome fisheye 180 512x512", Warp::analytic(BaseProjection::fisheye(180), {512, 512})},
  };
  for (const auto& [name, warp] : displays) {
    SCOPED_TRACE(name);
    const WarpInverse inverse(warp);
    const RoundTrip trip = round_trip_pixel_centres(inverse);
    // Full coverage and zero offsets: every pixel centre has a preimage.
    EXPECT_EQ(trip.covered, std::size_t(warp.output_size.x) * warp.output_size.y);
    EXPECT_LE(trip.worst_px, 1e-6);  // worst case, output px
    EXPECT_LE(worst_forward_then_inverse(inverse, 2000, 1), 1e-9);
  }
}

TEST(WarpInverse, SmoothOffsetMapsRoundTripAndFindEveryCoveredPoint) {
  auto displays = test::displays_for_tolerance_tests();
  displays.push_back({"dome fisheye 180 with 12 px offsets on 33x33",
                      test::with_smooth_offsets(
                          Warp::analytic(BaseProjection::fisheye(180), {384, 384}), {33, 33}, 12)});
  for (const auto& [name, warp] : displays) {
    SCOPED_TRACE(name);
    ASSERT_NO_THROW(warp.validate(name));
    const WarpInverse inverse(warp);
    const RoundTrip trip = round_trip_pixel_centres(inverse);
    EXPECT_GT(trip.covered, std::size_t(warp.output_size.x) * warp.output_size.y * 8 / 10);
    EXPECT_LE(trip.worst_px, 1e-6);  // worst case, output px
    // The map is injective, so the st found is the one that was mapped.
    EXPECT_LE(worst_forward_then_inverse(inverse, 4000, 2), 1e-9);
  }
}

TEST(WarpInverse, ConstantShiftHasTheExactInverseAndAnUncoveredStrip) {
  // Every node shifted 20 px right: q = (s·W + 20, t·H). Pixels left of x = 20 have no preimage.
  Warp warp = Warp::analytic(BaseProjection::perspective_fov(90, 70), {320, 240}, {5, 4});
  for (auto& offset : warp.offset_px) offset = glm::vec2(20, 0);
  const WarpInverse inverse(warp);
  for (int y = 0; y < 240; y += 7) {
    for (int x = 0; x < 320; ++x) {
      const glm::dvec2 q(x + 0.5, y + 0.5);
      const auto st = inverse.st_from_q(q);
      if (x < 20) {
        EXPECT_FALSE(st.has_value()) << x << ", " << y;
      } else {
        ASSERT_TRUE(st.has_value()) << x << ", " << y;
        EXPECT_NEAR(st->x, (q.x - 20) / 320, 1e-12);
        EXPECT_NEAR(st->y, q.y / 240, 1e-12);
      }
    }
  }
  // Between pixel centres and on cell edges too.
  const auto on_edge = inverse.st_from_q({20 + 320.0 / 4, 240.0 / 3});
  ASSERT_TRUE(on_edge.has_value());
  EXPECT_NEAR(on_edge->x, 0.25, 1e-12);
  EXPECT_NEAR(on_edge->y, 1.0 / 3, 1e-12);
  EXPECT_FALSE(inverse.st_from_q({-5, 10}).has_value());
  EXPECT_FALSE(inverse.st_from_q({400, 10}).has_value());
  EXPECT_FALSE(inverse.st_from_q({NAN, 10}).has_value());
}

TEST(WarpInverse, UncoveredNodesHaveNoPreimage) {
  Warp warp = test::with_smooth_offsets(
      Warp::analytic(BaseProjection::cylindrical(-90, 90, 0.8, -0.8), {400, 240}), {9, 5}, 4);
  // The left two node columns uncovered: st with coverage_at < 0.5 (s < 0.1875 at these rows).
  for (int j = 0; j < 5; ++j) {
    warp.coverage[warp.node_index(0, j)] = 0;
    warp.coverage[warp.node_index(1, j)] = 0;
  }
  const WarpInverse inverse(warp);
  const auto st = inverse.st_at_pixel_centres();
  std::size_t covered = 0;
  for (const auto& found : st) {
    if (std::isnan(found.x)) continue;
    ++covered;
    EXPECT_GE(warp.coverage_at(found), 0.5);
  }
  // Coverage reaches 0.5 halfway between node columns 1 and 2: s = 1.5/8 of the width is lost,
  // give or take the offsets (at most 4 px).
  const double expected = (1 - 1.5 / 8) * 400 * 240;
  EXPECT_NEAR(double(covered), expected, 4 * 240 + 10);
  EXPECT_LE(worst_forward_then_inverse(inverse, 4000, 3), 1e-9);
}

TEST(WarpInverse, AContinuedInverseKeepsTheCoveredAnswerWhereItsContinuationOverlapsIt) {
  // Node columns 0-4 covered at their own positions (q.x = 40 i); columns 5-8 uncovered, column 5
  // in place (q.x = 200) and 6-8 laid over the covered part (q.x = 0, 40, 80), as an
  // extrapolated offset field may lie: cells 6 and 7 cover q.x in [0, 80] a second time, the
  // right way round.
  Warp warp = Warp::analytic(BaseProjection::perspective_fov(90, 70), {320, 240}, {9, 5});
  for (int j = 0; j < 5; ++j) {
    for (int i = 5; i < 9; ++i) {
      const float folded_x = i == 5 ? 200.0f : 40.0f * float(i - 6);
      warp.offset_px[warp.node_index(i, j)] = glm::vec2(folded_x - 40.0f * float(i), 0);
      warp.coverage[warp.node_index(i, j)] = 0;
    }
  }
  const WarpInverse inverse(warp);
  const WarpInverse continued = continued_inverse(warp);
  std::size_t compared = 0;
  double worst_st = 0;
  for (int y = 0; y < 240; y += 3) {
    for (int x = 0; x < 320; ++x) {
      const glm::dvec2 q(x + 0.5, y + 0.5);
      const auto covered = inverse.st_from_q(q);
      if (!covered) continue;
      const auto either = continued.st_from_q(q);
      ASSERT_TRUE(either.has_value()) << x << ", " << y;
      worst_st = std::max(worst_st, glm::length(*either - *covered));
      ++compared;
    }
  }
  // Coverage reaches 0.5 halfway between columns 4 and 5 (q.x = 180).
  EXPECT_EQ(compared, 180u * 80u);
  EXPECT_LE(worst_st, 1e-12);
  // Past the coverage's edge the partly covered cell (columns 4-5) answers before the fold, and
  // between pixel centres too.
  for (const glm::dvec2 q : {glm::dvec2(190.5, 100.5), glm::dvec2(185.25, 7.75)}) {
    EXPECT_FALSE(inverse.st_from_q(q).has_value());
    const auto past = continued.st_from_q(q);
    ASSERT_TRUE(past.has_value());
    EXPECT_NEAR(past->x, q.x / 320, 1e-12);
    EXPECT_NEAR(past->y, q.y / 240, 1e-12);
  }
  // Only the continuation reaches q.x in (200, 320): nothing there.
  EXPECT_FALSE(continued.st_from_q({250.5, 100.5}).has_value());
}

TEST(WarpInverse, EyeDirectionProjectsBackToQ) {
  Warp warp = test::with_smooth_offsets(
      Warp::analytic(BaseProjection::equirectangular(-120, 120, 60, -60), {480, 240}), {13, 7}, 5);
  // A rotated base: yawed 30° and pitched 10°.
  const double yaw = glm::radians(30.0), pitch = glm::radians(10.0);
  const glm::dmat3 R_yaw(glm::dvec3(std::cos(yaw), 0, -std::sin(yaw)), glm::dvec3(0, 1, 0),
                         glm::dvec3(std::sin(yaw), 0, std::cos(yaw)));
  const glm::dmat3 R_pitch(glm::dvec3(1, 0, 0), glm::dvec3(0, std::cos(pitch), std::sin(pitch)),
                           glm::dvec3(0, -std::sin(pitch), std::cos(pitch)));
  warp.R_eye_base = R_yaw * R_pitch;
  const WarpInverse inverse(warp);
  double worst_px = 0;
  for (int y = 0; y < 240; y += 5) {
    for (int x = 0; x < 480; x += 5) {
      const glm::dvec2 q(x + 0.5, y + 0.5);
      const auto found = inverse.invert(q);
      if (!found) continue;
      EXPECT_NEAR(glm::length(found->v_eye), 1.0, 1e-12);
      const auto projected = warp.project(found->v_eye, found->st.x);
      ASSERT_TRUE(projected.has_value());
      EXPECT_TRUE(projected->covered);
      worst_px = std::max(worst_px, glm::length(projected->q - q));
    }
  }
  // project() goes through atan2/asin, so a few 1e-12 px of rounding on top of the inverse's.
  EXPECT_LE(worst_px, 1e-6);
}

// The SimCAD mesh of the shared dome warps: node (column, row) of a 33×33 grid lands at the
// normalised output position (x, y). As an offset map over the projector's perspective frustum.
Warp simcad_warp(const std::string& mesh_csv, glm::ivec2 output_size) {
  std::ifstream in(mesh_csv);
  EXPECT_TRUE(in.good()) << mesh_csv;
  Warp warp =
      Warp::analytic(BaseProjection::perspective(-1.65543187, 1.65543187, 2.78339720, -0.13522308),
                     output_size, {33, 33});
  std::string line;
  std::getline(in, line);  // header x;y;u;v;column;row
  int nodes = 0;
  while (std::getline(in, line)) {
    std::replace(line.begin(), line.end(), ';', ' ');
    std::istringstream fields(line);
    double x, y, u, v;
    int column, row;
    if (!(fields >> x >> y >> u >> v >> column >> row)) continue;
    warp.offset_px[warp.node_index(column, row)] =
        glm::vec2(float((x - u) * output_size.x), float((y - v) * output_size.y));
    ++nodes;
  }
  EXPECT_EQ(nodes, 33 * 33) << mesh_csv;
  return warp;
}

TEST(WarpInverse, RealSimcadDomeWarpsRoundTrip) {
  for (int channel = 1; channel <= 6; ++channel) {
    const std::string path = std::string(FACET_SHARED_DATA_DIR) +
                             "/warps/sgct-dome/simcad/channel" + std::to_string(channel) +
                             "_warp_mesh.csv";
    SCOPED_TRACE(path);
    const Warp warp = simcad_warp(path, {640, 400});
    ASSERT_NO_THROW(warp.validate(path));
    const WarpInverse inverse(warp);
    const RoundTrip trip = round_trip_pixel_centres(inverse);
    // The warped image reaches out of the output on some sides and leaves black corners on
    // others; most of the output is covered.
    EXPECT_GT(trip.covered, std::size_t(640 * 400) / 2);
    EXPECT_LE(trip.worst_px, 1e-6);  // worst case, output px
    EXPECT_LE(worst_forward_then_inverse(inverse, 4000, 10 + channel), 1e-9);
  }
}

// The pixel-centre inverse shares its rows among threads. Direction lookups cached on disk stay
// valid only if the answer does not depend on how many threads shared them: every thread count
// gives the serial answer to the bit, covered or not (NaN has one bit pattern here).
TEST(WarpInverse, PixelCentresAreTheSameBitsOnAnyNumberOfThreads) {
  for (int channel : {1, 4}) {
    const std::string path = std::string(FACET_SHARED_DATA_DIR) +
                             "/warps/sgct-dome/simcad/channel" + std::to_string(channel) +
                             "_warp_mesh.csv";
    SCOPED_TRACE(path);
    const WarpInverse inverse(simcad_warp(path, {1280, 800}));
    const std::vector<glm::dvec2> serial_st = inverse.st_at_pixel_centres(1);
    const std::vector<glm::vec3> serial_v = inverse.v_eye_at_pixel_centres(1);
    std::size_t covered = 0;
    for (const glm::vec3& v : serial_v) covered += std::isnan(v.x) ? 0 : 1;
    EXPECT_GT(covered, serial_v.size() / 2);
    for (std::size_t threads : {2, 3, 8, 0}) {
      SCOPED_TRACE(threads);
      const std::vector<glm::dvec2> st = inverse.st_at_pixel_centres(threads);
      const std::vector<glm::vec3> v = inverse.v_eye_at_pixel_centres(threads);
      ASSERT_EQ(st.size(), serial_st.size());
      ASSERT_EQ(v.size(), serial_v.size());
      EXPECT_EQ(std::memcmp(st.data(), serial_st.data(), st.size() * sizeof(glm::dvec2)), 0);
      EXPECT_EQ(std::memcmp(v.data(), serial_v.data(), v.size() * sizeof(glm::vec3)), 0);
    }
  }
}

// st_at_pixel_centres starts Newton from the neighbouring pixel's solution; st_from_q, the exact
// per-query path, starts from the middle of the cell. Both must find the same pixel centres and
// the same points to within the inverse's tolerance, on real warps.
TEST(WarpInverse, PixelCentresAgreeWithPerQueryInverseOnRealDomeWarps) {
  for (int channel = 1; channel <= 6; ++channel) {
    const std::string path = std::string(FACET_SHARED_DATA_DIR) +
                             "/warps/sgct-dome/simcad/channel" + std::to_string(channel) +
                             "_warp_mesh.csv";
    SCOPED_TRACE(path);
    const Warp warp = simcad_warp(path, {1280, 800});
    const WarpInverse inverse(warp);
    const auto st = inverse.st_at_pixel_centres();
    const auto v_eye = inverse.v_eye_at_pixel_centres();
    std::size_t covered = 0, disagree = 0;
    double worst_px = 0, worst_v = 0;
    for (int y = 0; y < warp.output_size.y; ++y) {
      for (int x = 0; x < warp.output_size.x; ++x) {
        const std::size_t k = std::size_t(y) * warp.output_size.x + x;
        const auto exact = inverse.st_from_q({x + 0.5, y + 0.5});
        if (exact.has_value() == std::isnan(st[k].x) ||
            exact.has_value() == std::isnan(v_eye[k].x)) {
          ++disagree;
          continue;
        }
        if (!exact) continue;
        ++covered;
        // The two answers' images in the output, and the directions against the exact one.
        worst_px = std::max(worst_px, glm::length(warp.q_from_st(st[k]) - warp.q_from_st(*exact)));
        const glm::vec3 v_exact(glm::normalize(warp.v_eye_from_st(*exact)));
        worst_v = std::max(worst_v, double(glm::length(v_eye[k] - v_exact)));
      }
    }
    EXPECT_EQ(disagree, 0u);
    EXPECT_GT(covered, std::size_t(1280 * 800) / 2);
    // Each answer maps within kTolerancePx of the pixel centre: worst case, output px.
    EXPECT_LE(worst_px, 2 * WarpInverse::kTolerancePx);
    // Unit vectors rounded to float: a few float ulps.
    EXPECT_LE(worst_v, 1e-6);
  }
}

}  // namespace
}  // namespace facet
