#include "facet/calibration/decode.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/calib3d.hpp>

#include "facet/calibration/camera_model.hpp"
#include "facet/calibration/capture.hpp"
#include "facet/calibration/patterns.hpp"
#include "facet/projection/errors.hpp"

namespace fc = facet::calibration;

namespace {

struct Scene {
  glm::ivec2 projector_size{100, 60};
  double scale = 1.0;    // camera pixel i sees projector pixel floor((i + 0.5) / scale)
  double gamma = 1.0;    // projector response
  double ambient = 0.0;  // light added everywhere
  double gain = 1.0;     // light of a white projector pixel
  int shadow_rows = 0;   // bottom camera rows that no projector light reaches

  glm::ivec2 camera_size() const {
    return {int(std::lround(projector_size.x * scale)), int(std::lround(projector_size.y * scale))};
  }
  // The projector pixel a camera pixel sees.
  glm::ivec2 seen(int i, int j) const {
    return {std::min(int((i + 0.5) / scale), projector_size.x - 1),
            std::min(int((j + 0.5) / scale), projector_size.y - 1)};
  }
};

// What the camera records, in linear light.
std::vector<cv::Mat> render(const Scene& scene, const std::vector<fc::Pattern>& patterns) {
  std::vector<cv::Mat> images;
  const glm::ivec2 size = scene.camera_size();
  for (const auto& pattern : patterns) {
    const cv::Mat values = fc::render_pattern(pattern, scene.projector_size);
    cv::Mat image(size.y, size.x, CV_32F);
    for (int j = 0; j < size.y; ++j) {
      for (int i = 0; i < size.x; ++i) {
        const glm::ivec2 q = scene.seen(i, j);
        const bool lit = j < size.y - scene.shadow_rows;
        const double v = values.at<float>(q.y, q.x);
        image.at<float>(j, i) =
            float(scene.ambient + (lit ? scene.gain * std::pow(v, scene.gamma) : 0));
      }
    }
    images.push_back(image);
  }
  return images;
}

struct Accuracy {
  double worst_px = 0;
  std::size_t decoded = 0;
};

// Worst distance between the decoded position and the centre of the projector pixel seen.
Accuracy accuracy(const Scene& scene, const fc::DecodedMap& map) {
  Accuracy result;
  for (int j = 0; j < map.camera_size.y; ++j) {
    for (int i = 0; i < map.camera_size.x; ++i) {
      if (map.mask.at<std::uint8_t>(j, i) != 0) continue;
      ++result.decoded;
      const glm::ivec2 q = scene.seen(i, j);
      const cv::Vec2d decoded = map.q_projector.at<cv::Vec2d>(j, i);
      result.worst_px = std::max({result.worst_px, std::abs(decoded[0] - (q.x + 0.5)),
                                  std::abs(decoded[1] - (q.y + 0.5))});
    }
  }
  return result;
}

std::vector<fc::Pattern> without(std::vector<fc::Pattern> patterns, const fc::Pattern& pattern) {
  patterns.erase(std::remove(patterns.begin(), patterns.end(), pattern), patterns.end());
  return patterns;
}

}  // namespace

TEST(Decode, CleanGrayCodeDecodesEveryPixelExactly) {
  for (double scale : {1.0, 1.7}) {
    Scene scene;
    scene.scale = scale;
    const auto patterns = fc::standard_patterns(scene.projector_size);
    const auto map = fc::decode(patterns, render(scene, patterns), scene.projector_size, 1.0);
    EXPECT_TRUE(map.has_x && map.has_y);
    EXPECT_EQ(map.camera_size, scene.camera_size());
    EXPECT_EQ(map.decoded_fraction(), 1.0) << "scale " << scale;
    EXPECT_EQ(accuracy(scene, map).worst_px, 0.0) << "scale " << scale;  // exact column centres
    EXPECT_EQ(cv::countNonZero(map.confidence < 1.0f), 0);
  }
}

TEST(Decode, GrayCodeIsRobustToGammaAndAmbientLight) {
  Scene scene;
  scene.gamma = 2.4;
  scene.ambient = 0.3;  // brighter than the projector's black, and than a fixed threshold at 0.25
  scene.gain = 0.4;
  const auto patterns = fc::standard_patterns(scene.projector_size);
  const auto map = fc::decode(patterns, render(scene, patterns), scene.projector_size, 2.4);
  EXPECT_EQ(map.decoded_fraction(), 1.0);
  EXPECT_EQ(accuracy(scene, map).worst_px, 0.0);
}

TEST(Decode, GrayCodeWithoutInversesComparesWithWhiteAndBlack) {
  Scene scene;
  scene.ambient = 0.1;
  scene.gamma = 2.2;
  std::vector<fc::Pattern> patterns;
  for (const auto& pattern : fc::standard_patterns(scene.projector_size)) {
    if (!pattern.inverted) patterns.push_back(pattern);
  }
  const auto map = fc::decode(patterns, render(scene, patterns), scene.projector_size, 2.2);
  EXPECT_EQ(map.decoded_fraction(), 1.0);
  EXPECT_EQ(accuracy(scene, map).worst_px, 0.0);
}

TEST(Decode, PhaseRefinesToWithinAHundredthOfAPixel) {
  struct Case {
    double period;
    int steps;
    double gamma;
    bool drop_low_bits;
  };
  for (const Case& c : {Case{16, 4, 1.0, false}, Case{7.3, 5, 2.2, false}, Case{16, 3, 2.2, true},
                        Case{32, 4, 1.8, true}}) {
    Scene scene;
    scene.scale = 1.3;
    scene.gamma = c.gamma;
    scene.ambient = 0.05;
    scene.gain = 0.8;
    fc::PatternSetOptions options;
    options.phase_period = c.period;
    options.phase_steps = c.steps;
    std::vector<fc::Pattern> patterns;
    for (const auto& pattern : fc::standard_patterns(scene.projector_size, options)) {
      // Bits whose blocks are at most a quarter period wide may be left out.
      const bool low =
          pattern.type == fc::PatternType::gray && std::ldexp(1.0, pattern.bit + 1) <= c.period / 2;
      if (!(c.drop_low_bits && low)) patterns.push_back(pattern);
    }
    const auto map = fc::decode(patterns, render(scene, patterns), scene.projector_size, c.gamma);
    const Accuracy result = accuracy(scene, map);
    std::printf("period %.1f, %d steps, gamma %.1f%s: worst error %.2g px\n", c.period, c.steps,
                c.gamma, c.drop_low_bits ? ", low Gray bits left out" : "", result.worst_px);
    EXPECT_EQ(map.decoded_fraction(), 1.0) << "period " << c.period;
    // Worst case over all camera pixels, in projector pixels.
    EXPECT_LT(result.worst_px, 0.01) << "period " << c.period;
    EXPECT_GT(cv::mean(map.confidence)[0], 0.9);
  }
}

TEST(Decode, ShadowIsMasked) {
  Scene scene;
  scene.shadow_rows = 10;
  scene.ambient = 0.2;
  const auto patterns = fc::standard_patterns(scene.projector_size);
  const auto map = fc::decode(patterns, render(scene, patterns), scene.projector_size, 1.0);
  const glm::ivec2 size = scene.camera_size();
  const cv::Mat bottom = map.mask.rowRange(size.y - 10, size.y);
  EXPECT_EQ(cv::countNonZero(bottom == fc::kMaskShadow), 10 * size.x);
  EXPECT_EQ(cv::countNonZero(map.mask.rowRange(0, size.y - 10)), 0);
  EXPECT_TRUE(std::isnan(map.q_projector.at<cv::Vec2d>(size.y - 1, 0)[0]));
  EXPECT_EQ(map.confidence.at<float>(size.y - 1, 0), 0.0f);
}

TEST(Decode, LowContrastAndDisagreementAreMasked) {
  Scene scene;
  fc::PatternSetOptions options;
  options.phase_period = 16;
  const auto patterns = fc::standard_patterns(scene.projector_size, options);
  auto images = render(scene, patterns);
  // Flip Gray bit 4 of x (and its inverse) in a patch: the Gray code moves by 16-31 pixels, the
  // phase stays, so they disagree.
  const auto bit4 = std::find(patterns.begin(), patterns.end(), fc::Pattern::gray(fc::Axis::x, 4));
  const auto index = std::size_t(bit4 - patterns.begin());
  cv::Mat patch = images[index](cv::Rect(10, 10, 5, 5)).clone();
  images[index + 1](cv::Rect(10, 10, 5, 5)).copyTo(images[index](cv::Rect(10, 10, 5, 5)));
  patch.copyTo(images[index + 1](cv::Rect(10, 10, 5, 5)));
  // Wash out the phase of y in another patch: low contrast.
  for (std::size_t k = 0; k < patterns.size(); ++k) {
    if (patterns[k].type == fc::PatternType::phase && patterns[k].axis == fc::Axis::y) {
      images[k](cv::Rect(40, 30, 4, 4)).setTo(0.5f);
    }
  }
  const auto map = fc::decode(patterns, images, scene.projector_size, 1.0);
  EXPECT_EQ(cv::countNonZero(map.mask(cv::Rect(10, 10, 5, 5)) == fc::kMaskDisagreement), 25);
  EXPECT_EQ(cv::countNonZero(map.mask(cv::Rect(40, 30, 4, 4)) & fc::kMaskLowContrast), 16);
  EXPECT_EQ(cv::countNonZero(map.mask), 25 + 16);

  // Without phase, a bit whose pattern and inverse look nearly alike is low contrast.
  const auto gray_only = fc::standard_patterns(scene.projector_size);
  auto gray_images = render(scene, gray_only);
  for (std::size_t k = 0; k < gray_only.size(); ++k) {
    if (gray_only[k] == fc::Pattern::gray(fc::Axis::y, 2)) {
      gray_images[k](cv::Rect(0, 0, 3, 3)).setTo(0.5f);
      gray_images[k + 1](cv::Rect(0, 0, 3, 3)).setTo(0.51f);  // 1% of white − black apart
    }
  }
  const auto gray_map = fc::decode(gray_only, gray_images, scene.projector_size, 1.0);
  EXPECT_EQ(cv::countNonZero(gray_map.mask(cv::Rect(0, 0, 3, 3)) == fc::kMaskLowContrast), 9);
}

TEST(Decode, OutOfRangeCodesAreMasked) {
  // 100 columns need 7 bits, which can name columns up to 127.
  Scene scene;
  const auto patterns = fc::standard_patterns(scene.projector_size);
  auto images = render(scene, patterns);
  const auto bit6 = std::find(patterns.begin(), patterns.end(), fc::Pattern::gray(fc::Axis::x, 6));
  const auto index = std::size_t(bit6 - patterns.begin());
  // Column 0 has Gray code 0; setting bit 6 names binary 127.
  images[index](cv::Rect(0, 0, 1, 60)).setTo(1.0f);
  images[index + 1](cv::Rect(0, 0, 1, 60)).setTo(0.0f);
  const auto map = fc::decode(patterns, images, scene.projector_size, 1.0);
  EXPECT_EQ(cv::countNonZero(map.mask.col(0) == fc::kMaskOutOfRange), 60);
}

TEST(Decode, MissingFramesAreInputErrors) {
  const glm::ivec2 size{100, 60};
  const auto all = fc::standard_patterns(size);
  auto expect_error = [&](const std::vector<fc::Pattern>& patterns, const std::string& words) {
    bool loaded = false;
    try {
      fc::decode(
          patterns,
          [&](std::size_t) {
            loaded = true;
            return cv::Mat(4, 4, CV_32F, 0.5f);
          },
          size, 1.0);
      ADD_FAILURE() << "accepted frames without " << words;
    } catch (const facet::InputError& error) {
      EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
    }
    EXPECT_FALSE(loaded) << "loaded images before finding that frames are missing";
  };
  expect_error(without(all, fc::Pattern::gray(fc::Axis::x, 3)), "Gray bit 3 of axis x");
  expect_error(without(without(all, fc::Pattern::gray(fc::Axis::y, 0)),
                       fc::Pattern::gray(fc::Axis::y, 0, true)),
               "Gray bit 0 of axis y");
  expect_error(without(without(all, fc::Pattern::white()), fc::Pattern::gray(fc::Axis::x, 2, true)),
               "inverse of Gray bit 2 of axis x");
  fc::PatternSetOptions options;
  options.phase_period = 16;
  expect_error(
      without(fc::standard_patterns(size, options), fc::Pattern::phase(fc::Axis::y, 16, 2, 4)),
      "phase step 2");
  // A 16 px period lets bits 0 to 2 go (blocks of 8 px, at most a quarter period off), not 3.
  expect_error(without(fc::standard_patterns(size, options), fc::Pattern::gray(fc::Axis::x, 3)),
               "Gray bit 3 of axis x");
  expect_error({fc::Pattern::white(), fc::Pattern::black()}, "at least one axis");

  // Images of two sizes.
  EXPECT_THROW(
      fc::decode(
          all, [&](std::size_t frame) { return cv::Mat(frame == 5 ? 5 : 4, 4, CV_32F, 0.5f); },
          size, 1.0),
      facet::InputError);
}

// The real capture: a 1024x768 projector's Gray code on a planar board in front of a wall, seen
// by a 1280x1024 camera, with the bottom strip of the image in shadow.
TEST(Decode, RealProcamBoardCapture) {
  const std::filesystem::path folder =
      std::filesystem::path(FACET_SHARED_DATA_DIR) / "captures/procam-board";
  const auto capture = fc::read_capture(folder);
  const auto map = fc::decode_capture(capture, 0);
  ASSERT_EQ(map.camera_size, glm::ivec2(1280, 1024));

  const auto fraction = [](const cv::Mat& mask) {
    return double(cv::countNonZero(mask)) / double(mask.total());
  };
  std::printf("decoded %.3f of the image; shadow %.3f, low contrast %.3f, out of range %.3f\n",
              map.decoded_fraction(), fraction(map.mask & fc::kMaskShadow),
              fraction(map.mask & fc::kMaskLowContrast), fraction(map.mask & fc::kMaskOutOfRange));
  for (int band = 0; band < 16; ++band) {
    const cv::Mat rows = map.mask.rowRange(band * 64, band * 64 + 64);
    std::printf("rows %4d-%4d: masked %.3f (shadow %.3f)\n", band * 64, band * 64 + 63,
                fraction(rows), fraction(rows & fc::kMaskShadow));
  }
  // The shadow covers rows 896-1023 except a lit corner right of column 1180.
  const double shadow_masked = fraction(map.mask(cv::Rect(0, 896, 1150, 128)));
  const double board_decoded = 1 - fraction(map.mask(cv::Rect(260, 200, 780, 560)));
  std::printf("shadow strip masked %.4f, board decoded %.3f\n", shadow_masked, board_decoded);
  // Measured with the default options: 99.1% of the strip masked; 59.5% of the board decoded
  // (its black squares reflect too little light and are masked as shadow).
  EXPECT_GT(shadow_masked, 0.97);
  EXPECT_GT(board_decoded, 0.5);

  // On the board the camera->projector map is a homography once the camera's lens distortion is
  // taken out (the projector's lens is nearly distortion-free at this scale). The wall around it
  // lies in another plane, so only the board's inside is used.
  const auto camera = fc::CameraModel::read(folder / "camera.cameramodel");
  const double f = camera.intrinsics()[0];
  const cv::Rect board(260, 200, 780, 560);
  std::vector<cv::Point2d> q_pinhole, q_projector;
  for (int j = board.y; j < board.y + board.height; j += 2) {
    for (int i = board.x; i < board.x + board.width; i += 2) {
      if (map.mask.at<std::uint8_t>(j, i) != 0) continue;
      const auto v = camera.unproject({double(i), double(j)});
      ASSERT_TRUE(v.has_value());
      const cv::Vec2d q = map.q_projector.at<cv::Vec2d>(j, i);
      q_pinhole.emplace_back(f * v->x / v->z, f * v->y / v->z);
      q_projector.emplace_back(q[0], q[1]);
    }
  }
  ASSERT_GT(q_pinhole.size(), 10000u);
  cv::Mat inliers;
  cv::setRNGSeed(1);
  const cv::Mat H =
      cv::findHomography(q_pinhole, q_projector, cv::RANSAC, 2.0, inliers, 2000, 0.999);
  ASSERT_FALSE(H.empty());
  std::vector<cv::Point2d> predicted;
  cv::perspectiveTransform(q_pinhole, predicted, H);
  std::vector<double> residuals;
  for (std::size_t k = 0; k < predicted.size(); ++k) {
    residuals.push_back(cv::norm(predicted[k] - q_projector[k]));
  }
  std::sort(residuals.begin(), residuals.end());
  const double median = residuals[residuals.size() / 2];
  const double p99 = residuals[residuals.size() * 99 / 100];
  const double inlier_fraction = double(cv::countNonZero(inliers)) / double(inliers.total());
  std::printf("board homography: %zu points, median residual %.3f px, p99 %.3f px, inliers %.3f\n",
              residuals.size(), median, p99, inlier_fraction);
  // Measured: median 0.41 px (Gray code alone rounds to pixel centres: a uniform error in
  // [-0.5, 0.5]² has a median length of 0.38 px), p99 0.99 px, inliers 98-100% (RANSAC
  // threshold 2 px). Bounds with margin, in projector pixels.
  EXPECT_LT(median, 0.6);
  EXPECT_LT(p99, 1.5);
  EXPECT_GT(inlier_fraction, 0.93);
}

TEST(Decode, CaptureWithMissingFramesNamesTheFieldAndLoadsNothing) {
  const std::filesystem::path folder =
      std::filesystem::path(FACET_SHARED_DATA_DIR) / "captures/procam-board";
  auto capture = fc::read_capture(folder);
  // Drop the inverse of y bit 4 and the black frame: nothing to compare bit 4 with.
  auto& frames = capture.projectors[0].frames;
  std::erase_if(frames, [](const fc::CaptureFrame& frame) {
    return frame.pattern == fc::Pattern::gray(fc::Axis::y, 4, true) ||
           frame.pattern == fc::Pattern::black();
  });
  try {
    fc::decode_capture(capture, 0);
    FAIL() << "decoded a capture with missing frames";
  } catch (const facet::InputError& error) {
    EXPECT_EQ(error.source(), (folder / "capture.json").string());
    EXPECT_EQ(error.field(), "projectors[0].frames");
    EXPECT_NE(std::string(error.what()).find("inverse of Gray bit 4 of axis y"), std::string::npos)
        << error.what();
  }
  // A frame whose file is missing is named before decoding starts.
  capture = fc::read_capture(folder);
  capture.projectors[0].frames[7].file = "graycode_missing.png";
  try {
    fc::decode_capture(capture, 0);
    FAIL() << "decoded a capture with a missing image";
  } catch (const facet::InputError& error) {
    EXPECT_NE(error.source().find("graycode_missing.png"), std::string::npos) << error.what();
  }
}

// The 8-bit pattern files that `facet patterns` writes, seen through an identity "camera": the
// rounding to 256 levels is the only error left.
TEST(Decode, QuantisedPatternFilesDecodeWithinTwoHundredthsOfAPixel) {
  const glm::ivec2 size{96, 40};
  fc::PatternSetOptions options;
  options.phase_period = 12;
  const auto patterns = fc::standard_patterns(size, options);
  std::vector<cv::Mat> images;
  for (const auto& pattern : patterns) {
    cv::Mat quantised;
    fc::render_pattern(pattern, size).convertTo(quantised, CV_8U, 255);  // rounds to nearest
    images.push_back(quantised);
  }
  const auto map = fc::decode(patterns, images, size, 1.0);
  Scene scene;
  scene.projector_size = size;
  const Accuracy result = accuracy(scene, map);
  std::printf("8-bit phase patterns: worst error %.4f px\n", result.worst_px);
  EXPECT_EQ(map.decoded_fraction(), 1.0);
  // Worst case over all pixels, in projector pixels. Measured: 0.0085 px.
  EXPECT_LT(result.worst_px, 0.02);
}
