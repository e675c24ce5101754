#pragma once
// Reading per-pixel maps (distances, weights) of an output image at continuous positions.
#include <algorithm>
#include <glm/glm.hpp>
#include <opencv2/core.hpp>

namespace facet::calibration::detail {

// A CV_32F map read bilinearly between pixel centres at output position q (pixel (x, y) holds the
// value at (x + 0.5, y + 0.5)), clamped at the edge.
inline double bilinear(const cv::Mat& map, glm::dvec2 q) {
  const double fx = std::clamp(q.x - 0.5, 0.0, double(map.cols - 1));
  const double fy = std::clamp(q.y - 0.5, 0.0, double(map.rows - 1));
  const int x0 = std::min(int(fx), std::max(0, map.cols - 2));
  const int y0 = std::min(int(fy), std::max(0, map.rows - 2));
  const int x1 = std::min(x0 + 1, map.cols - 1), y1 = std::min(y0 + 1, map.rows - 1);
  const double ax = fx - x0, ay = fy - y0;
  return (1 - ay) * ((1 - ax) * map.at<float>(y0, x0) + ax * map.at<float>(y0, x1)) +
         ay * ((1 - ax) * map.at<float>(y1, x0) + ax * map.at<float>(y1, x1));
}

}  // namespace facet::calibration::detail
