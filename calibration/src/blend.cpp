#include "facet/calibration/blend.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "map_sampling.hpp"

namespace facet::calibration {
namespace {

// An uncovered pixel of one projector counts as an edge to fade towards when another projector
// covers its direction at least this far (output pixels) inside its own covered region. Covered
// regions that end together on the screen (where the camera's view ends, or where two images'
// edges cross at a small angle) are a few pixels apart near where they meet: too little room to
// fade across, so neither fades there (see kContinueFlatPx for the step that leaves in the
// other's weight). The warps' coverage follows such edges within about a pixel but bends only
// from node to node, so the margin is at least a little more than a node spacing.
constexpr double kMinOverlapMarginPx = 10;
double overlap_margin_px(const Warp& warp) {
  const double spacing = 0.5 * (double(warp.output_size.x) / (warp.grid_size.x - 1) +
                                double(warp.output_size.y) / (warp.grid_size.y - 1));
  return std::max(kMinOverlapMarginPx, 1.25 * spacing);
}

template <typename Body>
void parallel_rows(int rows, const Body& body) {
  cv::parallel_for_(
      cv::Range(0, rows),
      [&](const cv::Range& range) {
        for (int y = range.start; y < range.end; ++y) body(y);
      },
      std::max(1.0, rows / 8.0));
}

// The covered pixel centres of a warp, padded by one pixel on every side: 1 covered, 0 not
// (the padding stands for the image edge). CV_8U, (W + 2) × (H + 2).
cv::Mat padded_covered(const std::vector<glm::dvec2>& st_of_pixel, glm::ivec2 size) {
  cv::Mat covered(size.y + 2, size.x + 2, CV_8U, cv::Scalar(0));
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      if (!std::isnan(st_of_pixel[std::size_t(y) * size.x + x].x)) {
        covered.at<std::uint8_t>(y + 1, x + 1) = 1;
      }
    }
  }
  return covered;
}

// Distance in output pixels from each pixel centre to the nearest 0 of a padded mask, as the
// distance to that pixel's edge (a pixel centre next to it lies 0.5 px away). CV_32F, W × H.
cv::Mat distance_px(const cv::Mat& padded) {
  cv::Mat distance;
  cv::distanceTransform(padded, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  cv::Mat inner = distance(cv::Rect(1, 1, padded.cols - 2, padded.rows - 2)) - 0.5f;
  return cv::max(inner, 0.0f);
}

constexpr double kFeatherSmoothingPx = 3;
// How steeply an edge rises as the other projector's cover of it thins (px per px).
constexpr double kRaiseGain = 4;

// No edge: farther than any image.
constexpr double kFar = 1e7;

// The lower envelope of the parabolas (x − b)² + f(b) over b, in place on `values` (Felzenszwalb
// and Huttenlocher's squared distance transform, one dimension).
void squared_distance_1d(std::vector<double>& values) {
  const int n = int(values.size());
  std::vector<double> f = values, z(std::size_t(n) + 1);
  std::vector<int> v(static_cast<std::size_t>(n), 0);
  int k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  for (int q = 1; q < n; ++q) {
    double s = 0;
    for (;;) {
      const int r = v[std::size_t(k)];
      s = ((f[std::size_t(q)] + double(q) * q) - (f[std::size_t(r)] + double(r) * r)) /
          (2.0 * (q - r));
      if (s > z[std::size_t(k)] || k == 0) break;
      --k;
    }
    if (s <= z[std::size_t(k)]) s = z[std::size_t(k)];
    ++k;
    v[std::size_t(k)] = q;
    z[std::size_t(k)] = s;
    z[std::size_t(k) + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[std::size_t(k) + 1] < q) ++k;
    const int r = v[std::size_t(k)];
    values[std::size_t(q)] = double(q - r) * (q - r) + f[std::size_t(r)];
  }
}

// For a padded map of edge heights h(b) (CV_64F, kFar where there is no edge), the distance from
// each pixel centre to the nearest edge pixel raised by its height, sqrt(|x − b|² + h(b)²), as
// the distance to that pixel's edge (0.5 px less). CV_32F, the unpadded size. Raising an edge
// instead of switching it on or off keeps the distance, and the weights made from it, smooth
// where an overlap begins.
cv::Mat raised_distance_px(const cv::Mat& height) {
  cv::Mat squared(height.size(), CV_64F);
  for (int y = 0; y < height.rows; ++y) {
    for (int x = 0; x < height.cols; ++x) {
      const double h = height.at<double>(y, x);
      squared.at<double>(y, x) = h >= kFar ? kFar * kFar : h * h;
    }
  }
  parallel_rows(height.rows, [&](int y) {
    std::vector<double> line(squared.ptr<double>(y), squared.ptr<double>(y) + squared.cols);
    squared_distance_1d(line);
    std::copy(line.begin(), line.end(), squared.ptr<double>(y));
  });
  cv::parallel_for_(cv::Range(0, height.cols), [&](const cv::Range& range) {
    std::vector<double> line(std::size_t(height.rows));
    for (int x = range.start; x < range.end; ++x) {
      for (int y = 0; y < height.rows; ++y) line[std::size_t(y)] = squared.at<double>(y, x);
      squared_distance_1d(line);
      for (int y = 0; y < height.rows; ++y) squared.at<double>(y, x) = line[std::size_t(y)];
    }
  });
  cv::Mat distance(height.rows - 2, height.cols - 2, CV_32F);
  for (int y = 0; y < distance.rows; ++y) {
    for (int x = 0; x < distance.cols; ++x) {
      distance.at<float>(y, x) =
          float(std::max(0.0, std::sqrt(squared.at<double>(y + 1, x + 1)) - 0.5));
    }
  }
  return distance;
}

using detail::bilinear;

// How far inside its covered region projector k's position of v lies, in output pixels; 0 where
// k does not cover v.
double covered_depth_px(const Warp& warp, const cv::Mat& depth_px, glm::dvec3 v_eye) {
  const auto projected = warp.project(v_eye);
  if (!projected || !projected->covered) return 0;
  const glm::dvec2 q = projected->q;
  if (!(q.x > 0 && q.y > 0 && q.x < warp.output_size.x && q.y < warp.output_size.y)) return 0;
  return bilinear(depth_px, q);
}

// Output pixels per radian at projector k's position st: the square root of the area ratio of
// output and direction Jacobians, from differences over two cells each way (the bilinear warp's
// own Jacobian jumps from cell to cell, by a few percent with noisy nodes, and a weight that
// jumped with it would break the sum between pixels; over a fixed step the estimate is
// continuous in st). 0 where it is degenerate.
double rad_per_px(const Warp& warp, glm::dvec2 st_at) {
  const glm::dvec2 h(std::min(0.25, 2.0 / (warp.grid_size.x - 1)),
                     std::min(0.25, 2.0 / (warp.grid_size.y - 1)));
  const glm::dvec2 st = glm::clamp(st_at, h, glm::dvec2(1.0) - h);
  const glm::dvec2 ds(h.x, 0), dt(0, h.y);
  const glm::dvec2 dq_ds = warp.q_from_st(st + ds) - warp.q_from_st(st - ds);
  const glm::dvec2 dq_dt = warp.q_from_st(st + dt) - warp.q_from_st(st - dt);
  const glm::dvec3 dv_ds = warp.v_eye_from_st(st + ds) - warp.v_eye_from_st(st - ds);
  const glm::dvec3 dv_dt = warp.v_eye_from_st(st + dt) - warp.v_eye_from_st(st - dt);
  const double area_q = std::abs(dq_ds.x * dq_dt.y - dq_ds.y * dq_dt.x);
  const double area_v = glm::length(glm::cross(dv_ds, dv_dt));
  if (!(area_q > 0) || !(area_v > 0)) return 0;
  return std::sqrt(area_v / area_q);
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// Where projector k's covered region ends inside j's without k having faded out (an edge within
// the overlap margin), j's share would jump there from 1 − α_k to 1, and j's weights, read between
// pixel centres, would break the sum across a band as wide as j's pixels. So in j's sums, k's raw
// weight is carried on past k's edge: unchanged for kContinueFlatPx (output pixels from k's
// covered pixel centres, more than the reach of j's bilinear interpolation across it) and then
// falling to 0 over kContinueFadePx. Where j lights alone within those few pixels, its weight is
// below 1 (check_blend reports how much); a deep edge of k has faded to 0 and carries nothing.
constexpr double kContinueFlatPx = 1.5;
constexpr double kContinueFadePx = 2.5;
constexpr int kContinuePad = int(kContinueFlatPx + kContinueFadePx) + 2;

// Distance in output pixels from each point of the image padded by kContinuePad on every side to
// the nearest covered pixel centre. CV_32F, (W + 2·pad) × (H + 2·pad).
cv::Mat beyond_covered_px(const cv::Mat& padded_covered_mask) {
  const cv::Mat inner = padded_covered_mask(
      cv::Rect(1, 1, padded_covered_mask.cols - 2, padded_covered_mask.rows - 2));
  cv::Mat uncovered(inner.rows + 2 * kContinuePad, inner.cols + 2 * kContinuePad, CV_8U,
                    cv::Scalar(1));
  cv::Mat centre = uncovered(cv::Rect(kContinuePad, kContinuePad, inner.cols, inner.rows));
  centre.setTo(0, inner != 0);
  cv::Mat distance;
  cv::distanceTransform(uncovered, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  return distance;
}

// What a projector needs to weigh a direction: its warp, its feather distance map (output pixels,
// W × H) and its beyond_covered_px map.
struct Weighing {
  const Warp* warp = nullptr;
  cv::Mat feather_px;
  cv::Mat beyond_px;

  // smoothstep(d / feather_rad), d the feather distance at the projector's position q of v times
  // its angle per pixel there; the map is read at the nearest point of the image when q lies
  // outside it (a warp's coverage may end a fraction of a pixel past the image edge, and the
  // weight must follow the warp's coverage, which is what check_blend and the renderer use).
  // Where the projector does not cover v: 0, or with `continued` its weight carried on past its
  // edge, times a factor falling from 1 to 0 between kContinueFlatPx and kContinueFlatPx +
  // kContinueFadePx from its covered pixel centres.
  double raw(glm::dvec3 v_eye, double feather_rad, bool continued) const {
    const auto projected = warp->project(v_eye);
    if (!projected) return 0;
    const glm::dvec2 q = projected->q;
    double carried = 1;
    if (!projected->covered) {
      if (!continued) return 0;
      // Only next to the covered region, where the nodes hold the coverage ramp: farther out the
      // offsets are extrapolated over many nodes and q can land anywhere, even back in the image.
      const bool in_base = projected->st.x >= 0 && projected->st.x <= 1 && projected->st.y >= 0 &&
                           projected->st.y <= 1 && warp->coverage_at(projected->st) > 0;
      const glm::dvec2 padded = q + double(kContinuePad);
      if (!in_base || !(padded.x > 0.5 && padded.y > 0.5 && padded.x < beyond_px.cols - 0.5 &&
                        padded.y < beyond_px.rows - 0.5)) {
        return 0;
      }
      const double beyond = bilinear(beyond_px, padded);
      carried = 1 - smoothstep((beyond - kContinueFlatPx) / kContinueFadePx);
      if (!(carried > 0)) return 0;
    }
    const double d_px = bilinear(feather_px, q);
    if (!(d_px > 0)) return 0;
    return carried * smoothstep(d_px * rad_per_px(*warp, projected->st) / feather_rad);
  }
};

}  // namespace

BlendResult compute_blend(std::span<const Warp> warps, const BlendOptions& options) {
  FACET_ASSERT(options.feather_rad > 0);
  FACET_ASSERT(!options.black_level || (*options.black_level >= 0 && *options.black_level < 1));
  BlendResult result;
  std::vector<std::vector<glm::dvec2>> st_of_pixel;
  for (const Warp& warp : warps) {
    st_of_pixel.push_back(WarpInverse(warp).st_at_pixel_centres());
  }
  // A projector fades out towards the edges of its covered region that lie well inside another
  // projector's, and only those: where covered regions end together (the display's outer edge, or
  // where the camera's view ended for both), fading both would make the weights the ratio of two
  // vanishing numbers, which changes within a pixel.
  std::vector<cv::Mat> depth_px, feather_px;
  for (std::size_t k = 0; k < warps.size(); ++k) {
    depth_px.push_back(distance_px(padded_covered(st_of_pixel[k], warps[k].output_size)));
  }
  for (std::size_t k = 0; k < warps.size(); ++k) {
    const glm::ivec2 size = warps[k].output_size;
    const cv::Mat covered = padded_covered(st_of_pixel[k], size);
    // Every uncovered pixel of k (and the ring just outside the image) whose direction another
    // projector j covers is an edge to fade towards, raised by how little j covers it: by
    // kRaiseGain · (margin − depth_j), so an edge deep inside j counts fully and one j barely
    // reaches hardly at all. Directions from the warp's extrapolated offsets, over the nodes with
    // any coverage (the ramp past the image edge, the rings kept around the seen part) and their
    // neighbours: the nodes filled farther out are guesses that may fold over the image.
    cv::Mat height(size.y + 2, size.x + 2, CV_64F, cv::Scalar(kFar));
    Warp extended = warps[k];
    {
      const glm::ivec2 g = extended.grid_size;
      for (int j = 0; j < g.y; ++j) {
        for (int i = 0; i < g.x; ++i) {
          bool near = false;
          for (int b = std::max(0, j - 1); b <= std::min(g.y - 1, j + 1); ++b) {
            for (int a = std::max(0, i - 1); a <= std::min(g.x - 1, i + 1); ++a) {
              near = near || warps[k].coverage[warps[k].node_index(a, b)] > 0;
            }
          }
          extended.coverage[extended.node_index(i, j)] = near ? 1.0f : 0.0f;
        }
      }
    }
    const WarpInverse inverse(std::move(extended));
    parallel_rows(size.y + 2, [&](int y) {
      const auto* inside = covered.ptr<std::uint8_t>(y);
      auto* row = height.ptr<double>(y);
      for (int x = 0; x < size.x + 2; ++x) {
        if (inside[x] != 0) continue;
        const auto inverted = inverse.invert({x - 0.5, y - 0.5});
        if (!inverted) continue;
        for (std::size_t j = 0; j < warps.size(); ++j) {
          if (j == k) continue;
          const double depth = covered_depth_px(warps[j], depth_px[j], inverted->v_eye);
          if (!(depth > 0)) continue;
          const double raised = kRaiseGain * std::max(0.0, overlap_margin_px(warps[j]) - depth);
          row[x] = std::min(row[x], raised);
        }
      }
    });
    // The distance to the nearest of several edges has kinks where two edges are equally near
    // (and ripples along slanted pixel edges); a weight with a kink breaks the sum between pixel
    // centres by up to 1% on small images. A light blur rounds them off, and moves the distance
    // by under a pixel.
    cv::Mat feather = raised_distance_px(height);
    cv::GaussianBlur(feather, feather, cv::Size(0, 0), kFeatherSmoothingPx, kFeatherSmoothingPx,
                     cv::BORDER_REPLICATE);
    feather_px.push_back(feather);
  }
  std::vector<Weighing> weighing(warps.size());
  for (std::size_t k = 0; k < warps.size(); ++k) {
    weighing[k].warp = &warps[k];
    weighing[k].feather_px = feather_px[k];
    weighing[k].beyond_px = beyond_covered_px(padded_covered(st_of_pixel[k], warps[k].output_size));
  }
  // How many projectors overlap at most, for the black-level target.
  std::vector<cv::Mat> overlap_count;
  for (std::size_t p = 0; p < warps.size(); ++p) {
    const Warp& warp = warps[p];
    projection_io::BlendMap alpha = projection_io::BlendMap::constant(warp.output_size, 0.0f);
    cv::Mat count(warp.output_size.y, warp.output_size.x, CV_8U, cv::Scalar(0));
    parallel_rows(warp.output_size.y, [&](int y) {
      for (int x = 0; x < warp.output_size.x; ++x) {
        const glm::dvec2 st = st_of_pixel[p][std::size_t(y) * warp.output_size.x + x];
        if (std::isnan(st.x)) continue;
        const glm::dvec3 v = warp.v_eye_from_st(st);
        double own = 0, sum = 0;
        int covering = 0;
        for (std::size_t k = 0; k < warps.size(); ++k) {
          const auto projected = warps[k].project(v);
          const bool covers = projected && projected->covered;
          // Another projector's weight is carried on past its edge; p's own is not (p covers v).
          const double raw = weighing[k].raw(v, options.feather_rad, k != p);
          if (covers && raw > 0) ++covering;
          sum += raw;
          if (k == p) own = raw;
        }
        count.at<std::uint8_t>(y, x) = std::uint8_t(std::min(covering, 255));
        alpha.at(x, y) = sum > 0 ? float(std::clamp(own / sum, 0.0, 1.0)) : 0.0f;
      }
    });
    result.alpha.push_back(std::move(alpha));
    overlap_count.push_back(std::move(count));
  }
  if (options.black_level) {
    const double b = *options.black_level;
    double most = 1;
    for (const cv::Mat& count : overlap_count) {
      double max_value = 0;
      cv::minMaxLoc(count, nullptr, &max_value);
      most = std::max(most, max_value);
    }
    for (std::size_t p = 0; p < warps.size(); ++p) {
      projection_io::BlendMap black = projection_io::BlendMap::constant(warps[p].output_size, 0.0f);
      for (int y = 0; y < black.size.y; ++y) {
        for (int x = 0; x < black.size.x; ++x) {
          const int n = overlap_count[p].at<std::uint8_t>(y, x);
          if (n == 0) continue;
          // Each covering projector adds its share α of the missing black; β is a pattern value,
          // and a value β emits b + (1 − b)·β.
          const double missing = b * (most - n);
          black.at(x, y) =
              float(std::clamp(result.alpha[p].at(x, y) * missing / (1 - b), 0.0, 1.0));
        }
      }
      result.black.push_back(std::move(black));
    }
  }
  return result;
}

constexpr double kSingleTolerance = 0.005;

BlendCheck check_blend(std::span<const Warp> warps, std::span<const projection_io::BlendMap> alpha,
                       int stride, double border_px) {
  FACET_ASSERT(warps.size() == alpha.size() && stride >= 1);
  BlendCheck check;
  std::vector<WarpInverse> inverses;
  std::vector<cv::Mat> depth_px;
  for (const Warp& warp : warps) {
    inverses.emplace_back(warp);
    depth_px.push_back(
        distance_px(padded_covered(inverses.back().st_at_pixel_centres(), warp.output_size)));
  }
  for (std::size_t p = 0; p < warps.size(); ++p) {
    const WarpInverse& inverse = inverses[p];
    const glm::ivec2 size = warps[p].output_size;
    std::vector<double> row_error(std::size_t(size.y), 0.0);
    std::vector<std::size_t> row_count(std::size_t(size.y), 0);
    std::vector<glm::dvec2> row_worst(std::size_t(size.y), glm::dvec2(0.0));
    std::vector<std::size_t> row_single(std::size_t(size.y), 0),
        row_single_dim(std::size_t(size.y), 0);
    std::vector<double> row_single_min(std::size_t(size.y), 1.0);
    parallel_rows(size.y, [&](int y) {
      if (y % stride != 0) return;
      for (int x = 0; x < size.x; x += stride) {
        const auto inverted = inverse.invert({x + 0.5, y + 0.5});
        if (!inverted) continue;
        double sum = 0;
        int covering = 0;
        bool near_edge = false;
        for (std::size_t k = 0; k < warps.size(); ++k) {
          const auto projected = warps[k].project(inverted->v_eye);
          if (!projected || !projected->covered) continue;
          const glm::dvec2 q = projected->q;
          if (!(bilinear(depth_px[k], q) >= border_px)) near_edge = true;
          sum += alpha[k].sample(q);
          ++covering;
        }
        if (covering == 0 || near_edge) continue;
        if (covering == 1) {
          // Where one projector lights alone, its α is below 1 only where it carries on a
          // neighbour's weight past that neighbour's edge.
          ++row_single[std::size_t(y)];
          if (sum < 1 - kSingleTolerance) ++row_single_dim[std::size_t(y)];
          row_single_min[std::size_t(y)] = std::min(row_single_min[std::size_t(y)], sum);
          continue;
        }
        if (std::abs(sum - 1) > row_error[std::size_t(y)]) {
          row_error[std::size_t(y)] = std::abs(sum - 1);
          row_worst[std::size_t(y)] = {x + 0.5, y + 0.5};
        }
        ++row_count[std::size_t(y)];
      }
    });
    for (int y = 0; y < size.y; ++y) {
      if (row_error[std::size_t(y)] > check.sum_max_err) {
        check.sum_max_err = row_error[std::size_t(y)];
        check.worst_projector = p;
        check.worst_q = row_worst[std::size_t(y)];
      }
      check.overlap_directions += row_count[std::size_t(y)];
      check.single_directions += row_single[std::size_t(y)];
      check.single_dim_directions += row_single_dim[std::size_t(y)];
      check.single_min_sum = std::min(check.single_min_sum, row_single_min[std::size_t(y)]);
    }
  }
  return check;
}

}  // namespace facet::calibration
