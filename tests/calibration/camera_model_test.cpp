#include "facet/calibration/camera_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "facet/projection/errors.hpp"
#include "support/files.hpp"

namespace fc = facet::calibration;

namespace {

const std::filesystem::path kData(FACET_SHARED_DATA_DIR);

struct RoundTrip {
  double worst_px = 0, sum_squared = 0;
  int samples = 0;
  int failures = 0;
};

// project(unproject(q)) over a grid of pixels inside the model's valid region.
RoundTrip round_trip(const fc::CameraModel& camera, int nx, int ny) {
  RoundTrip result;
  const glm::dvec2 size(camera.imager_size());
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const glm::dvec2 q((i + 0.5) / nx * size.x - 0.5, (j + 0.5) / ny * size.y - 0.5);
      if (!camera.is_valid_pixel(q)) continue;
      ++result.samples;
      const auto v = camera.unproject(q);
      const auto q_back = v ? camera.project(*v) : std::nullopt;
      if (!q_back) {
        ++result.failures;
        continue;
      }
      EXPECT_NEAR(glm::length(*v), 1.0, 1e-12);
      result.worst_px = std::max(result.worst_px, glm::length(*q_back - q));
    }
  }
  return result;
}

}  // namespace

TEST(CameraModel, ReadsRealMrcalModels) {
  const auto opencv8 =
      fc::CameraModel::read(kData / "cameras/mrcal-figueroa/opencv8-0.cameramodel");
  EXPECT_EQ(opencv8.lensmodel(), "LENSMODEL_OPENCV8");
  EXPECT_EQ(opencv8.intrinsics().size(), 12u);
  EXPECT_EQ(opencv8.imager_size(), glm::ivec2(6016, 4016));
  EXPECT_GE(opencv8.valid_intrinsics_region().size(), 10u);
  EXPECT_EQ(opencv8.valid_intrinsics_region().front(), glm::dvec2(622, 0));

  const auto splined =
      fc::CameraModel::read(kData / "cameras/mrcal-figueroa/splined-0.cameramodel");
  EXPECT_EQ(splined.lensmodel(),
            "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=30_Ny=20_fov_x_deg=170");
  EXPECT_EQ(splined.intrinsics().size(), 4u + 2u * 30 * 20);

  const auto board = fc::CameraModel::read(kData / "captures/procam-board/camera.cameramodel");
  EXPECT_EQ(board.lensmodel(), "LENSMODEL_OPENCV5");
  EXPECT_TRUE(board.valid_intrinsics_region().empty());
  // The principal point looks straight ahead.
  const auto v = board.unproject({board.intrinsics()[2], board.intrinsics()[3]});
  ASSERT_TRUE(v.has_value());
  EXPECT_NEAR(glm::length(*v - glm::dvec3(0, 0, 1)), 0.0, 1e-12);
}

TEST(CameraModel, ProjectUnprojectRoundTripWithinOneMicropixel) {
  for (const char* file : {"cameras/mrcal-figueroa/opencv8-0.cameramodel",
                           "cameras/mrcal-figueroa/splined-0.cameramodel",
                           "captures/procam-board/camera.cameramodel"}) {
    const auto camera = fc::CameraModel::read(kData / file);
    const RoundTrip result = round_trip(camera, 41, 31);
    // Worst case over the grid, in camera pixels.
    EXPECT_LT(result.worst_px, 1e-6) << file;
    EXPECT_EQ(result.failures, 0) << file;
    EXPECT_GT(result.samples, 500) << file;
    std::printf("%s: %d samples, worst round trip %.3g px\n", file, result.samples,
                result.worst_px);
  }
}

TEST(CameraModel, PinholeProjectsAsExpected) {
  const fc::CameraModel pinhole("LENSMODEL_PINHOLE", {1000, 900, 320.5, 240.25}, {640, 480});
  const auto q = pinhole.project({1, 2, 4});
  ASSERT_TRUE(q.has_value());
  EXPECT_NEAR(q->x, 1000 * 0.25 + 320.5, 1e-12);
  EXPECT_NEAR(q->y, 900 * 0.5 + 240.25, 1e-12);
  std::vector<glm::dvec2> qs{{0, 0}, {639, 479}};
  std::vector<glm::dvec3> vs(2);
  pinhole.unproject(qs, vs);
  std::vector<glm::dvec2> back(2);
  pinhole.project(vs, back);
  EXPECT_LT(glm::length(back[1] - qs[1]), 1e-9);
  EXPECT_FALSE(pinhole.project(glm::dvec3(0.0)).has_value());
}

TEST(CameraModel, WriteThenReadGivesTheSameModel) {
  const facet::test::TempFolder temp;
  const auto splined =
      fc::CameraModel::read(kData / "cameras/mrcal-figueroa/splined-0.cameramodel");
  splined.write(temp.path() / "copy.cameramodel");
  const auto copy = fc::CameraModel::read(temp.path() / "copy.cameramodel");
  EXPECT_EQ(copy.lensmodel(), splined.lensmodel());
  EXPECT_EQ(copy.imager_size(), splined.imager_size());
  ASSERT_EQ(copy.intrinsics().size(), splined.intrinsics().size());
  double worst = 0;
  for (std::size_t k = 0; k < copy.intrinsics().size(); ++k) {
    worst = std::max(worst, std::abs(copy.intrinsics()[k] - splined.intrinsics()[k]) /
                                std::max(1.0, std::abs(splined.intrinsics()[k])));
  }
  EXPECT_EQ(worst, 0.0);
  EXPECT_EQ(copy.valid_intrinsics_region(), splined.valid_intrinsics_region());
  const glm::dvec2 q(1000.25, 3000.75);
  EXPECT_EQ(*copy.unproject(q), *splined.unproject(q));
}

TEST(CameraModel, BadModelsAreInputErrors) {
  const facet::test::TempFolder temp;
  EXPECT_THROW(fc::CameraModel::read(temp.path() / "missing.cameramodel"), facet::InputError);
  std::ofstream(temp.path() / "bad.cameramodel") << "{ 'lensmodel': 'LENSMODEL_OPENCV8', }";
  EXPECT_THROW(fc::CameraModel::read(temp.path() / "bad.cameramodel"), facet::InputError);
  EXPECT_THROW(fc::CameraModel("LENSMODEL_NOPE", {1, 1, 0, 0}, {10, 10}), facet::InputError);
  EXPECT_THROW(fc::CameraModel("LENSMODEL_OPENCV4", {1, 1, 0, 0}, {10, 10}), facet::InputError);
  EXPECT_THROW(fc::CameraModel("LENSMODEL_PINHOLE", {1, 1, 0, 0}, {0, 10}), facet::InputError);
}

// calibration/README.md's "Making a camera model with mrcal", step 4, run with mrcal's own tool
// (installed by tools/dev deps) on a synthetic chessboard capture: 10x10 corners at 0.0588 m in
// 40 poses of a LENSMODEL_OPENCV8 camera, with 0.2 px of Gaussian noise on every corner
// (mrcal_readme_calibration.py). The model mrcal-calibrate-cameras writes projects within
// 0.1 px RMS and 0.25 px at worst of the true camera over the central 80% of the imager (mrcal's
// projection_diff, which aligns the two camera frames; 4,000 corners at 0.2 px each). facet reads
// that model and projects as mrcal's Python API does, within a micropixel.
TEST(CameraModel, ReadsTheModelThatTheReadmesMrcalCommandWrites) {
  const facet::test::TempFolder folder;
  const std::string script =
      std::string(FACET_SOURCE_DIR) + "/tests/calibration/mrcal_readme_calibration.py";
  const std::string command =
      "/usr/bin/python3 '" + script + "' '" + folder.path().string() + "' > /dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0)
      << command << " failed: mrcal-calibrate-cameras and python3-mrcal come with the Debian "
      << "package mrcal (tools/dev deps)";
  double rms_px = -1, worst_px = -1;
  std::ifstream(folder.path() / "difference.txt") >> rms_px >> worst_px;
  std::printf("mrcal-calibrate-cameras model against the truth: RMS %.3f px, worst %.3f px\n",
              rms_px, worst_px);
  EXPECT_GE(rms_px, 0.0);
  EXPECT_LT(rms_px, 0.1);
  EXPECT_LT(worst_px, 0.25);

  const fc::CameraModel fitted = fc::CameraModel::read(folder.path() / "camera-0.cameramodel");
  EXPECT_EQ(fitted.lensmodel(), "LENSMODEL_OPENCV8");
  EXPECT_EQ(fitted.imager_size(), glm::ivec2(1280, 1024));
  std::ifstream projections(folder.path() / "projections.txt");
  glm::dvec3 v;
  glm::dvec2 q;
  int samples = 0;
  while (projections >> v.x >> v.y >> v.z >> q.x >> q.y) {
    const auto q_facet = fitted.project(v);
    ASSERT_TRUE(q_facet.has_value());
    EXPECT_LT(glm::length(*q_facet - q), 1e-6) << samples;
    ++samples;
  }
  EXPECT_EQ(samples, 48);
}
