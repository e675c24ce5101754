// Our Gray code decoding against OpenCV's structured_light module on the real capture.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/structured_light.hpp>

#include "facet/calibration/capture.hpp"
#include "facet/calibration/decode.hpp"

namespace fc = facet::calibration;

TEST(DecodeAgainstOpenCV, RealProcamBoardCaptureAgreesPixelForPixel) {
  const auto capture =
      fc::read_capture(std::filesystem::path(FACET_SHARED_DATA_DIR) / "captures/procam-board");
  const auto& projector = capture.projectors[0];
  const auto map = fc::decode_capture(capture, 0);

  // The capture is in GrayCodePattern's order (x bits then y bits, most significant first, each
  // followed by its inverse, then white and black), so its frames feed OpenCV directly.
  std::vector<cv::Mat> images;
  for (std::size_t k = 0; k + 2 < projector.frames.size(); ++k) {
    cv::Mat image;
    fc::load_frame(capture, projector.frames[k]).convertTo(image, CV_8U, 255);
    images.push_back(image);
  }
  cv::structured_light::GrayCodePattern::Params params;
  params.width = projector.size.x;
  params.height = projector.size.y;
  auto opencv = cv::structured_light::GrayCodePattern::create(params);
  std::size_t both = 0, agree = 0;
  for (int y = 0; y < map.camera_size.y; y += 3) {
    for (int x = 0; x < map.camera_size.x; x += 3) {
      if (map.mask.at<std::uint8_t>(y, x) != 0) continue;
      cv::Point q;
      if (opencv->getProjPixel(images, x, y, q)) continue;  // true means OpenCV failed here
      ++both;
      const cv::Vec2d ours = map.q_projector.at<cv::Vec2d>(y, x);
      if (ours[0] == q.x + 0.5 && ours[1] == q.y + 0.5) ++agree;
    }
  }
  const double agreement = double(agree) / double(both);
  std::printf("%zu pixels decoded by both, %.5f agree exactly\n", both, agreement);
  ASSERT_GT(both, 50000u);
  // Both compare each bit with its inverse, so where both decode they should agree everywhere;
  // measured: all 82983 sampled pixels agree.
  EXPECT_GT(agreement, 0.999);
}
