#include "facet/calibration/fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/matx.hpp>
#include <opencv2/imgproc.hpp>

#include "facet/projection/errors.hpp"
#include "facet/projection/screen.hpp"
#include "map_sampling.hpp"

namespace facet::calibration {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kMinTotalSamples = 50;

template <typename Body>
void parallel_range(int count, const Body& body, double grain = 16.0) {
  cv::parallel_for_(
      cv::Range(0, count),
      [&](const cv::Range& range) {
        for (int k = range.start; k < range.end; ++k) body(k);
      },
      std::max(1.0, count / grain));
}

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0;
  const std::size_t k =
      std::min(values.size() - 1, std::size_t(std::ceil(fraction * double(values.size()))) - 1);
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

// The eye-frame direction in which the projector's rows go up (q.y decreasing), from a linear fit
// of q.y over the tangent plane of the mean direction: the cover then lines its base up with the
// projector's image, which keeps the offsets small.
std::optional<glm::dvec3> projector_up(std::span<const FitSample> samples, glm::dvec3 mean) {
  const glm::dvec3 helper = std::abs(mean.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, -1);
  const glm::dvec3 e1 = glm::normalize(glm::cross(helper, mean));
  const glm::dvec3 e2 = glm::cross(mean, e1);
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  const std::size_t stride = std::max<std::size_t>(1, samples.size() / 20000);
  for (std::size_t k = 0; k < samples.size(); k += stride) {
    const double z = glm::dot(samples[k].v_eye, mean);
    if (!(z > 0.2)) continue;
    const cv::Vec3d row(1, glm::dot(samples[k].v_eye, e1) / z, glm::dot(samples[k].v_eye, e2) / z);
    normal += row * row.t();
    rhs += row * samples[k].q.y;
  }
  cv::Vec3d solution;
  if (!cv::solve(normal, rhs, solution, cv::DECOMP_SVD)) return std::nullopt;
  const glm::dvec3 down = solution[1] * e1 + solution[2] * e2;
  if (!(glm::length(down) > 0)) return std::nullopt;
  return -glm::normalize(down);
}

// The homography q ~ H·v by DLT over the samples marked in `use`.
std::optional<cv::Matx33d> fit_homography(std::span<const FitSample> samples,
                                          std::span<const char> use, glm::ivec2 output_size) {
  // Output pixels normalised to about [-1, 1] keep the DLT well conditioned.
  const glm::dvec2 centre = 0.5 * glm::dvec2(output_size);
  const double scale = 0.5 * std::max(output_size.x, output_size.y);
  cv::Matx<double, 9, 9> normal = cv::Matx<double, 9, 9>::zeros();
  std::size_t used = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (!use[k]) continue;
    const glm::dvec3& v = samples[k].v_eye;
    const glm::dvec2 q = (samples[k].q - centre) / scale;
    const cv::Vec<double, 9> a(-v.x, -v.y, -v.z, 0, 0, 0, q.x * v.x, q.x * v.y, q.x * v.z);
    const cv::Vec<double, 9> b(0, 0, 0, -v.x, -v.y, -v.z, q.y * v.x, q.y * v.y, q.y * v.z);
    normal += a * a.t() + b * b.t();
    ++used;
  }
  if (used < 8) return std::nullopt;
  cv::Mat eigenvalues, eigenvectors;
  if (!cv::eigen(cv::Mat(normal), eigenvalues, eigenvectors)) return std::nullopt;
  cv::Matx33d H_normalised;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) H_normalised(r, c) = eigenvectors.at<double>(8, r * 3 + c);
  }
  const cv::Matx33d T_inverse(scale, 0, centre.x, 0, scale, centre.y, 0, 0, 1);
  return T_inverse * H_normalised;
}

// Distance in output pixels between H·v and q; infinite behind the projector.
double homography_residual(const cv::Matx33d& H, const FitSample& sample) {
  const cv::Vec3d v(sample.v_eye.x, sample.v_eye.y, sample.v_eye.z);
  const cv::Vec3d h = H * v;
  if (!(h[2] > 0)) return std::numeric_limits<double>::infinity();
  return std::hypot(h[0] / h[2] - sample.q.x, h[1] / h[2] - sample.q.y);
}

// A perspective base lined up with the projector: q ≈ H·v (a homography from eye directions to
// output pixels, fitted by DLT) splits as H = K·R_projector_eye with K upper triangular (RQ), and
// the base looks down the projector's axis with its rows. Seen from near its centre, a projector
// is close to a pinhole, so in this base q is nearly affine in st and the offsets are small and
// smooth: bilinear interpolation between nodes then costs little. Samples far from the
// homography (wrong codes, stray light) are left out of the fit and of the extents; the warp fit
// ignores samples outside the base image. nullopt when the fit is ill-posed, mirrored, or the
// consistent samples reach more than max_half_angle_rad off the axis horizontally or vertically
// (margin included).
std::optional<BaseCover> projector_cover(std::span<const FitSample> samples, glm::ivec2 output_size,
                                         double margin_rad, double max_half_angle_rad) {
  std::vector<char> use(samples.size(), 0);
  const std::size_t stride = std::max<std::size_t>(1, samples.size() / 40000);
  for (std::size_t k = 0; k < samples.size(); k += stride) use[k] = 1;
  std::optional<cv::Matx33d> H;
  std::vector<double> residual(samples.size());
  double threshold = 0;
  for (int pass = 0; pass < 3; ++pass) {
    H = fit_homography(samples, use, output_size);
    if (!H) return std::nullopt;
    glm::dvec3 mean(0.0);
    for (std::size_t k = 0; k < samples.size(); k += stride) {
      if (use[k]) mean += samples[k].v_eye;
    }
    const cv::Vec3d h3((*H)(2, 0), (*H)(2, 1), (*H)(2, 2));
    if (h3.dot(cv::Vec3d(mean.x, mean.y, mean.z)) < 0) *H = *H * -1.0;
    std::vector<double> sampled;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      residual[k] = homography_residual(*H, samples[k]);
      if (k % stride == 0) sampled.push_back(residual[k]);
    }
    // The homography misses parallax and lens distortion by a few pixels over the image; wrong
    // codes miss by far more.
    threshold = std::max(0.01 * std::max(output_size.x, output_size.y),
                         4.0 * percentile(std::move(sampled), 0.9));
    for (std::size_t k = 0; k < samples.size(); k += stride) use[k] = residual[k] <= threshold;
  }
  cv::Matx33d K, R;
  cv::RQDecomp3x3(*H, K, R);
  // RQ leaves the signs of K's diagonal free: make it positive.
  for (int r = 0; r < 3; ++r) {
    if (K(r, r) < 0) {
      for (int i = 0; i < 3; ++i) {
        K(i, r) = -K(i, r);
        R(r, i) = -R(r, i);
      }
    }
  }
  if (!(cv::determinant(R) > 0.5)) return std::nullopt;  // a mirrored image
  const glm::dvec3 x_projector(R(0, 0), R(0, 1), R(0, 2)), y_projector(R(1, 0), R(1, 1), R(1, 2)),
      z_projector(R(2, 0), R(2, 1), R(2, 2));
  BaseCover cover;
  // Base: x right, y up, looking down −z; projector: x right, y down, z forward.
  cover.R_eye_base = glm::dmat3(x_projector, -y_projector, -z_projector);
  double left = 1e300, right = -1e300, top = -1e300, bottom = 1e300;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (!(residual[k] <= threshold)) continue;
    const glm::dvec3& v = samples[k].v_eye;
    const double z = glm::dot(v, z_projector);
    if (!(z > 0)) return std::nullopt;
    const double x = std::atan2(glm::dot(v, x_projector), z);
    const double y = std::atan2(-glm::dot(v, y_projector), z);
    left = std::min(left, x);
    right = std::max(right, x);
    top = std::max(top, y);
    bottom = std::min(bottom, y);
  }
  // Far off the axis a perspective base stretches: its nodes crowd into the middle of the image
  // and the few at the sides see few samples each.
  const double limit = max_half_angle_rad;
  if (std::max({-left, right, top, -bottom}) + margin_rad > limit) return std::nullopt;
  cover.base =
      BaseProjection::perspective(std::tan(left - margin_rad), std::tan(right + margin_rad),
                                  std::tan(top + margin_rad), std::tan(bottom - margin_rad));
  return cover;
}

struct NodeFit {
  glm::dvec2 q{kNaN};
  bool supported = false;
  // Second-order terms of the fit in node units: x·du², x·dv², y·du², y·dv².
  cv::Vec4d curvature{0, 0, 0, 0};
};

using Basis = cv::Vec<double, 6>;

Basis quadratic_basis(double du, double dv) { return {1, du, dv, du * du, du * dv, dv * dv}; }

// Signed distance in output pixels from each output pixel centre to the edge of the part of the
// image the camera saw, positive inside: CV_32F, W × H. `q_seen` are decoded positions that agree
// with the fitted warp. Pixels holding one are closed over gaps of a few sample spacings (the
// camera samples the image at its own resolution) and at least `close_px`. Positions within
// `band_px` of the image edge are pulled inwards by defocus and dropped by the fit, so the band is
// not judged from them: the region seen just inside it is carried straight out to the image edge.
// Unseen holes enclosed by the seen region whose points all lie within `bridge_px` of it count as
// seen.
cv::Mat seen_signed_distance(std::span<const glm::dvec2> q_seen, glm::ivec2 size, int band_px,
                             double close_px, double bridge_px) {
  cv::Mat seen(size.y, size.x, CV_8U, cv::Scalar(0));
  for (const glm::dvec2& q : q_seen) {
    const int x = int(std::floor(q.x)), y = int(std::floor(q.y));
    if (x >= 0 && y >= 0 && x < size.x && y < size.y) seen.at<std::uint8_t>(y, x) = 1;
  }
  // Samples per pixel where there are any, from 8×8 blocks holding at least one.
  std::size_t blocks = 0;
  for (int by = 0; by < size.y; by += 8) {
    for (int bx = 0; bx < size.x; bx += 8) {
      const cv::Rect block(bx, by, std::min(8, size.x - bx), std::min(8, size.y - by));
      blocks += cv::countNonZero(seen(block)) > 0 ? 1 : 0;
    }
  }
  const double density =
      blocks == 0 ? 1.0 : std::min(1.0, double(cv::countNonZero(seen)) / (64.0 * double(blocks)));
  // Gaps between the samples, and where a few decoded badly, are closed; the coverage ramp
  // cannot follow finer detail than about a node spacing anyway.
  const int radius = std::max(int(std::ceil(1.5 / std::sqrt(density))), int(std::lround(close_px)));
  const cv::Mat disc = cv::getStructuringElement(
      cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1), cv::Point(radius, radius));
  {
    // Padded as it meets the image edge, so that closing does not eat into the edge.
    cv::Mat padded;
    cv::copyMakeBorder(seen, padded, radius, radius, radius, radius, cv::BORDER_REPLICATE);
    cv::morphologyEx(padded, padded, cv::MORPH_CLOSE, disc);
    padded(cv::Rect(radius, radius, size.x, size.y)).copyTo(seen);
  }
  const int band = std::min({band_px, (size.x - 1) / 2, (size.y - 1) / 2});
  if (band > 0) {
    const cv::Rect inner(band, band, size.x - 2 * band, size.y - 2 * band);
    cv::Mat carried;
    cv::copyMakeBorder(seen(inner), carried, band, band, band, band,
                       cv::BORDER_REPLICATE | cv::BORDER_ISOLATED);
    seen = carried;
  }
  // Holes enclosed by what was seen (a speck of dust, an occluder) are bridged from every side by
  // the node fits: small ones count as seen.
  {
    const cv::Mat unseen = 1 - seen;
    cv::Mat labels, stats, centroids, gap;
    const int count = cv::connectedComponentsWithStats(unseen, labels, stats, centroids, 8, CV_32S);
    cv::distanceTransform(unseen, gap, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
    std::vector<float> widest(std::size_t(count), 0.0f);
    for (int y = 0; y < size.y; ++y) {
      for (int x = 0; x < size.x; ++x) {
        const int label = labels.at<std::int32_t>(y, x);
        if (label > 0)
          widest[std::size_t(label)] = std::max(widest[std::size_t(label)], gap.at<float>(y, x));
      }
    }
    for (int label = 1; label < count; ++label) {
      const int left = stats.at<std::int32_t>(label, cv::CC_STAT_LEFT);
      const int top = stats.at<std::int32_t>(label, cv::CC_STAT_TOP);
      const bool enclosed = left > 0 && top > 0 &&
                            left + stats.at<std::int32_t>(label, cv::CC_STAT_WIDTH) < size.x &&
                            top + stats.at<std::int32_t>(label, cv::CC_STAT_HEIGHT) < size.y;
      if (enclosed && widest[std::size_t(label)] <= bridge_px) seen.setTo(1, labels == label);
    }
  }
  // Beyond the image the region goes on as it meets the edge: the image edge itself is no edge
  // of what the camera saw.
  constexpr int kPad = 2;
  cv::Mat padded, inside, outside;
  cv::copyMakeBorder(seen, padded, kPad, kPad, kPad, kPad, cv::BORDER_REPLICATE);
  cv::distanceTransform(padded, inside, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  cv::distanceTransform(1 - padded, outside, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  const cv::Rect image(kPad, kPad, size.x, size.y);
  inside = inside(image);
  outside = outside(image);
  // Pixel centres next to the edge lie half a pixel from it.
  cv::Mat signed_distance(size.y, size.x, CV_32F);
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      // (A distance transform with nothing to measure to gives a huge value.)
      const float distance = seen.at<std::uint8_t>(y, x) != 0 ? inside.at<float>(y, x) - 0.5f
                                                              : 0.5f - outside.at<float>(y, x);
      signed_distance.at<float>(y, x) = std::clamp(distance, -1e4f, 1e4f);
    }
  }
  return signed_distance;
}

// Harmonic (membrane) interpolation over the node grid: every node marked in `free` takes the
// mean of its 4-neighbours in the grid, the others stay fixed and hold it in place (Laplace's
// equation with the fixed nodes as boundary values, by successive over-relaxation). An affine
// map is harmonic, so where the warp is close to one (a projector seen through its own optics
// is nearly a homography) the filled nodes follow it, and a membrane stretched over a convex
// boundary does not fold.
void harmonic_fill(std::vector<glm::dvec2>& values, std::span<const char> free, glm::ivec2 grid) {
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < free.size(); ++k) {
    if (free[k]) order.push_back(k);
  }
  if (order.empty()) return;
  constexpr double kOverRelaxation = 1.8, kTolerancePx = 1e-5;
  constexpr int kMaxSweeps = 5000;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    double largest_change = 0;
    for (const std::size_t k : order) {
      const int i = int(k % std::size_t(grid.x)), j = int(k / std::size_t(grid.x));
      glm::dvec2 sum(0.0);
      int count = 0;
      auto add = [&](std::size_t n) {
        sum += values[n];
        ++count;
      };
      if (i > 0) add(k - 1);
      if (i + 1 < grid.x) add(k + 1);
      if (j > 0) add(k - std::size_t(grid.x));
      if (j + 1 < grid.y) add(k + std::size_t(grid.x));
      const glm::dvec2 change = kOverRelaxation * (sum / double(count) - values[k]);
      values[k] += change;
      largest_change = std::max({largest_change, std::abs(change.x), std::abs(change.y)});
    }
    if (largest_change < kTolerancePx) break;
  }
}

// The cells of the node grid whose four nodes are covered and that map to the output with
// reversed orientation or zero area (the test of Warp::find_fold), as the index of their
// top-left node.
std::vector<std::size_t> folded_cells(const Warp& warp) {
  std::vector<std::size_t> folded;
  const glm::ivec2 grid = warp.grid_size;
  const glm::dvec2 step{double(warp.output_size.x) / (grid.x - 1),
                        double(warp.output_size.y) / (grid.y - 1)};
  auto q_node = [&](int i, int j) {
    return glm::dvec2(i * step.x, j * step.y) + glm::dvec2(warp.offset_px[warp.node_index(i, j)]);
  };
  auto cross = [](glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; };
  for (int j = 0; j + 1 < grid.y; ++j) {
    for (int i = 0; i + 1 < grid.x; ++i) {
      if (warp.coverage[warp.node_index(i, j)] < 0.5f ||
          warp.coverage[warp.node_index(i + 1, j)] < 0.5f ||
          warp.coverage[warp.node_index(i, j + 1)] < 0.5f ||
          warp.coverage[warp.node_index(i + 1, j + 1)] < 0.5f) {
        continue;
      }
      const glm::dvec2 q00 = q_node(i, j), q10 = q_node(i + 1, j), q01 = q_node(i, j + 1),
                       q11 = q_node(i + 1, j + 1);
      const double least = std::min({cross(q10 - q00, q01 - q00), cross(q11 - q10, q00 - q10),
                                     cross(q01 - q11, q10 - q11), cross(q00 - q01, q11 - q01)});
      if (!(least > 1e-9 * step.x * step.y)) folded.push_back(warp.node_index(i, j));
    }
  }
  return folded;
}

using detail::bilinear;

}  // namespace

cv::Mat eye_directions(const CameraModel& model, const CaptureCamera& camera,
                       const std::optional<Screen>& screen, glm::ivec2 camera_size,
                       const cv::Mat& wanted) {
  FACET_ASSERT(camera_size.x > 0 && camera_size.y > 0);
  FACET_ASSERT(wanted.empty() || (wanted.type() == CV_8U && wanted.cols == camera_size.x &&
                                  wanted.rows == camera_size.y));
  const bool at_eye = camera.t_eye_camera == glm::dvec3(0.0);
  FACET_ASSERT(at_eye || screen.has_value());
  cv::Mat v_eye(camera_size.y, camera_size.x, CV_64FC3, cv::Scalar::all(kNaN));
  parallel_range(camera_size.y, [&](int y) {
    std::vector<glm::dvec2> q;
    std::vector<int> columns;
    const std::uint8_t* want = wanted.empty() ? nullptr : wanted.ptr<std::uint8_t>(y);
    for (int x = 0; x < camera_size.x; ++x) {
      if (want != nullptr && want[x] == 0) continue;
      if (!model.is_valid_pixel({x, y})) continue;
      q.emplace_back(x, y);
      columns.push_back(x);
    }
    std::vector<glm::dvec3> v_camera(q.size());
    model.unproject(q, v_camera);
    auto* row = v_eye.ptr<cv::Vec3d>(y);
    for (std::size_t k = 0; k < q.size(); ++k) {
      const glm::dvec3 v = camera.R_eye_camera * v_camera[k];
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) continue;
      glm::dvec3 direction = v;
      if (!at_eye) {
        const auto t = facet::intersect_screen(*screen, camera.t_eye_camera, v);
        if (!t) continue;
        direction = camera.t_eye_camera + *t * v;
      }
      const double length = glm::length(direction);
      if (!(length > 0)) continue;
      direction /= length;
      row[columns[k]] = cv::Vec3d(direction.x, direction.y, direction.z);
    }
  });
  return v_eye;
}

std::vector<FitSample> fit_samples(const DecodedMap& decoded, const cv::Mat& v_eye) {
  FACET_ASSERT(v_eye.type() == CV_64FC3 && v_eye.size() == decoded.q_projector.size());
  std::vector<FitSample> samples;
  if (!decoded.has_x || !decoded.has_y) return samples;
  for (int y = 0; y < decoded.camera_size.y; ++y) {
    const auto* q = decoded.q_projector.ptr<cv::Vec2d>(y);
    const auto* confidence = decoded.confidence.ptr<float>(y);
    const auto* mask = decoded.mask.ptr<std::uint8_t>(y);
    const auto* v = v_eye.ptr<cv::Vec3d>(y);
    for (int x = 0; x < decoded.camera_size.x; ++x) {
      if (mask[x] != 0 || !std::isfinite(q[x][0]) || !std::isfinite(q[x][1]) ||
          !std::isfinite(v[x][0])) {
        continue;
      }
      const float weight = std::clamp(confidence[x] * confidence[x], 0.01f, 1.0f);
      samples.push_back(
          {glm::dvec3(v[x][0], v[x][1], v[x][2]), glm::dvec2(q[x][0], q[x][1]), weight});
    }
  }
  return samples;
}

WarpFit fit_warp(std::span<const FitSample> samples, glm::ivec2 output_size,
                 const FitOptions& options, const std::string& source) {
  FACET_ASSERT(output_size.x > 0 && output_size.y > 0);
  FACET_ASSERT(options.radius_nodes >= 1 && options.node_spacing_px > 0);
  if (samples.size() < kMinTotalSamples) {
    throw InputError(source, "projectors",
                     "a projector the camera sees, but only " + std::to_string(samples.size()) +
                         " camera pixels decoded its patterns (at least " +
                         std::to_string(kMinTotalSamples) + " are needed)");
  }
  WarpFit result;
  result.report.samples = samples.size();

  // Base and rotation covering the footprint.
  glm::dvec3 mean(0.0);
  for (const FitSample& sample : samples) mean += sample.v_eye;
  CoverOptions cover_options = options.cover;
  if (glm::length(mean) > 1e-6 * double(samples.size())) {
    mean = glm::normalize(mean);
    if (!cover_options.up_eye) cover_options.up_eye = projector_up(samples, mean);
  }
  std::vector<glm::dvec3> directions;
  const std::size_t stride = std::max<std::size_t>(1, samples.size() / 50000);
  directions.reserve(samples.size() / stride + 1);
  for (std::size_t k = 0; k < samples.size(); k += stride) directions.push_back(samples[k].v_eye);
  std::optional<BaseCover> aligned;
  if (options.projector_aligned_base) {
    aligned = projector_cover(samples, output_size, cover_options.margin_rad,
                              options.max_aligned_half_angle_rad);
  }
  const BaseCover cover = aligned ? *aligned : cover_directions(directions, cover_options);
  Warp& warp = result.warp;
  warp.base = cover.base;
  warp.R_eye_base = cover.R_eye_base;
  warp.output_size = output_size;

  // Base coordinates of every sample.
  const glm::dmat3 R_base_eye = glm::transpose(cover.R_eye_base);
  // st_any: every sample in the base image; st: those the fit uses.
  std::vector<glm::dvec2> st(samples.size(), glm::dvec2(kNaN)), st_any = st;
  parallel_range(int((samples.size() + 4095) / 4096), [&](int block) {
    const std::size_t end = std::min(samples.size(), std::size_t(block + 1) * 4096);
    for (std::size_t k = std::size_t(block) * 4096; k < end; ++k) {
      const auto value = cover.base.st_from_direction(R_base_eye * samples[k].v_eye, 0.5);
      if (value && value->x >= 0 && value->x <= 1 && value->y >= 0 && value->y <= 1) {
        st_any[k] = *value;
      }
      const glm::dvec2 q = samples[k].q;
      const double guard = options.edge_guard_px;
      if (q.x < guard || q.y < guard || q.x > output_size.x - guard ||
          q.y > output_size.y - guard) {
        continue;
      }
      if (value && value->x >= 0 && value->x <= 1 && value->y >= 0 && value->y <= 1) {
        st[k] = *value;
      }
    }
  });

  // Grid: from the average scale of output pixels per unit of s and t (a linear fit q ~ st).
  double px_per_s = output_size.x, px_per_t = output_size.y;
  {
    cv::Matx33d normal = cv::Matx33d::zeros();
    cv::Matx<double, 3, 2> rhs = cv::Matx<double, 3, 2>::zeros();
    for (std::size_t k = 0; k < samples.size(); k += stride) {
      if (std::isnan(st[k].x)) continue;
      const cv::Vec3d row(1, st[k].x, st[k].y);
      normal += row * row.t();
      rhs += row * cv::Matx12d(samples[k].q.x, samples[k].q.y);
    }
    cv::Matx<double, 3, 2> solution;
    cv::solve(normal, rhs, solution, cv::DECOMP_SVD);
    const double s_scale = std::hypot(solution(1, 0), solution(1, 1));
    const double t_scale = std::hypot(solution(2, 0), solution(2, 1));
    if (std::isfinite(s_scale) && s_scale > 0) px_per_s = s_scale;
    if (std::isfinite(t_scale) && t_scale > 0) px_per_t = t_scale;
  }
  auto grid_for = [&](double spacing_px) {
    auto count = [&](double px) {
      return std::clamp(int(std::ceil(px / spacing_px)) + 1, 4, 1024);
    };
    return glm::ivec2(count(px_per_s), count(px_per_t));
  };
  const bool chosen_grid = options.grid.x == 0 || options.grid.y == 0;
  glm::ivec2 grid_nodes = chosen_grid ? grid_for(options.node_spacing_px) : options.grid;

  auto fit_nodes = [&](const glm::ivec2 grid) {
    FACET_ASSERT(grid.x >= 2 && grid.y >= 2);
    const glm::ivec2 cells = grid - 1;

    // Bin samples by the cell that holds them (counting sort).
    std::vector<std::uint32_t> start(std::size_t(cells.x) * cells.y + 1, 0);
    std::vector<std::int32_t> cell_of(samples.size(), -1);
    for (std::size_t k = 0; k < samples.size(); ++k) {
      if (std::isnan(st[k].x)) continue;
      const int i = std::min(int(st[k].x * cells.x), cells.x - 1);
      const int j = std::min(int(st[k].y * cells.y), cells.y - 1);
      cell_of[k] = j * cells.x + i;
      ++start[std::size_t(cell_of[k]) + 1];
    }
    for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    std::vector<std::uint32_t> order(start.back());
    {
      std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
      for (std::size_t k = 0; k < samples.size(); ++k) {
        if (cell_of[k] >= 0) order[fill[std::size_t(cell_of[k])]++] = std::uint32_t(k);
      }
    }

    // Per-node robust local fits.
    std::vector<NodeFit> nodes(std::size_t(grid.x) * grid.y);
    const double radius = options.radius_nodes;
    parallel_range(grid.y, [&](int j) {
      std::vector<std::uint32_t> near;
      std::vector<double> kernel, robust, du, dv, residual;
      for (int i = 0; i < grid.x; ++i) {
        near.clear();
        kernel.clear();
        du.clear();
        dv.clear();
        const int i0 = std::max(0, int(std::floor(i - radius))),
                  i1 = std::min(cells.x - 1, int(std::ceil(i + radius)) - 1);
        const int j0 = std::max(0, int(std::floor(j - radius))),
                  j1 = std::min(cells.y - 1, int(std::ceil(j + radius)) - 1);
        double kernel_sum = 0;
        for (int cj = j0; cj <= j1; ++cj) {
          for (int ci = i0; ci <= i1; ++ci) {
            const std::size_t cell = std::size_t(cj) * cells.x + ci;
            for (std::uint32_t n = start[cell]; n < start[cell + 1]; ++n) {
              const std::uint32_t k = order[n];
              const double a = st[k].x * cells.x - i, b = st[k].y * cells.y - j;
              const double d = std::sqrt(a * a + b * b) / radius;
              if (d >= 1) continue;
              const double tricube = std::pow(1 - d * d * d, 3);
              const double w = tricube * samples[k].weight;
              near.push_back(k);
              kernel.push_back(w);
              du.push_back(a);
              dv.push_back(b);
              kernel_sum += tricube;
            }
          }
        }
        NodeFit& node = nodes[std::size_t(j) * grid.x + i];
        if (kernel_sum < options.min_samples) continue;
        robust.assign(near.size(), 1.0);
        residual.assign(near.size(), 0.0);
        for (int iteration = 0; iteration <= options.irls_iterations; ++iteration) {
          cv::Matx66d normal = cv::Matx66d::zeros();
          Basis rhs_x = Basis::all(0), rhs_y = Basis::all(0);
          double weight_sum = 0;
          for (std::size_t n = 0; n < near.size(); ++n) {
            const double w = kernel[n] * robust[n];
            if (w <= 0) continue;
            const Basis basis = quadratic_basis(du[n], dv[n]);
            for (int r = 0; r < 6; ++r) {
              const double wb = w * basis[r];
              for (int c = r; c < 6; ++c) normal(r, c) += wb * basis[c];
              rhs_x[r] += wb * samples[near[n]].q.x;
              rhs_y[r] += wb * samples[near[n]].q.y;
            }
            weight_sum += w;
          }
          for (int r = 0; r < 6; ++r) {
            for (int c = 0; c < r; ++c) normal(r, c) = normal(c, r);
          }
          cv::Matx66d inverse;
          if (cv::invert(normal, inverse, cv::DECOMP_CHOLESKY) == 0) {
            node.supported = false;
            break;
          }
          // The noise gain of the value at the node: large when the node lies outside the samples.
          const double gain = inverse(0, 0) * weight_sum;
          if (!(gain <= options.max_gain)) {
            node.supported = false;
            break;
          }
          const Basis coefficient_x = inverse * rhs_x, coefficient_y = inverse * rhs_y;
          node.q = {coefficient_x[0], coefficient_y[0]};
          node.supported = true;
          // Bilinear error of the quadratic terms (node units) at the worst point of a cell.
          node.curvature = {coefficient_x[3], coefficient_x[5], coefficient_y[3], coefficient_y[5]};
          if (iteration == options.irls_iterations) break;
          for (std::size_t n = 0; n < near.size(); ++n) {
            const Basis basis = quadratic_basis(du[n], dv[n]);
            residual[n] = std::hypot(coefficient_x.dot(basis) - samples[near[n]].q.x,
                                     coefficient_y.dot(basis) - samples[near[n]].q.y);
          }
          std::vector<double> sorted = residual;
          const double sigma = 1.4826 * percentile(std::move(sorted), 0.5);
          const double cutoff = std::max(options.tukey_sigmas * sigma, options.min_cutoff_px);
          for (std::size_t n = 0; n < near.size(); ++n) {
            const double u = residual[n] / cutoff;
            robust[n] = u < 1 ? (1 - u * u) * (1 - u * u) : 0.0;
          }
        }
      }
    });
    return nodes;
  };

  std::vector<NodeFit> nodes = fit_nodes(grid_nodes);
  if (chosen_grid && options.max_interpolation_error_px > 0) {
    // Bilinear interpolation between nodes misses the curvature of the map: from the quadratic
    // terms of the node fits, the error at cell centres and edge midpoints. A smaller spacing
    // cuts it with the square of the spacing (at the price of fewer samples per node).
    // Each node's terms are noisy; averaged over the 5×5 nodes around it, the noise drops
    // five-fold while the map's curvature, smooth over such distances, stays.
    std::vector<double> curvature;
    const glm::ivec2 g = grid_nodes;
    for (int j = 0; j < g.y; ++j) {
      for (int i = 0; i < g.x; ++i) {
        cv::Vec4d sum(0, 0, 0, 0);
        int count = 0;
        for (int b = std::max(0, j - 2); b <= std::min(g.y - 1, j + 2); ++b) {
          for (int a = std::max(0, i - 2); a <= std::min(g.x - 1, i + 2); ++a) {
            const NodeFit& node = nodes[std::size_t(b) * g.x + a];
            if (!node.supported) continue;
            sum += node.curvature;
            ++count;
          }
        }
        if (count < 13) continue;
        const cv::Vec4d c = sum / double(count);
        // Bilinear error of a·du² + b·dv² (node units) at cell centres and edge midpoints.
        auto worst = [](double a, double b) {
          return std::max({std::abs(a), std::abs(b), std::abs(a + b)}) / 4;
        };
        curvature.push_back(std::hypot(worst(c[0], c[1]), worst(c[2], c[3])));
      }
    }
    const double error = percentile(std::move(curvature), 0.9);
    if (error > options.max_interpolation_error_px) {
      const double spacing =
          std::max(options.min_node_spacing_px,
                   options.node_spacing_px * std::sqrt(options.max_interpolation_error_px / error));
      const glm::ivec2 finer = grid_for(spacing);
      if (finer.x > grid_nodes.x || finer.y > grid_nodes.y) {
        grid_nodes = glm::max(grid_nodes, finer);
        nodes = fit_nodes(grid_nodes);
      }
    }
  }
  const glm::ivec2 grid = grid_nodes;
  warp.grid_size = grid;
  result.report.grid = grid;
  const glm::ivec2 cells = grid - 1;

  // Offsets of supported nodes; the rest are filled outwards from them, each unsupported node
  // taking the mean of the linear extrapolations (or, failing those, the values) of its
  // already-filled neighbours, ring by ring.
  const glm::dvec2 step{double(output_size.x) / cells.x, double(output_size.y) / cells.y};
  std::vector<glm::dvec2> offset(nodes.size(), glm::dvec2(kNaN));
  std::vector<char> known(nodes.size(), 0);
  std::vector<int> ring(nodes.size(), 0);  // 0 supported, n filled in the n-th pass
  for (int j = 0; j < grid.y; ++j) {
    for (int i = 0; i < grid.x; ++i) {
      const std::size_t k = std::size_t(j) * grid.x + i;
      if (nodes[k].supported) {
        offset[k] = nodes[k].q - glm::dvec2(i * step.x, j * step.y);
        known[k] = 1;
        ++result.report.supported;
      }
    }
  }
  if (result.report.supported == 0) {
    throw InputError(source, "projectors",
                     "a projector whose decoded pixels support a fit, but no node of its " +
                         std::to_string(grid.x) + "x" + std::to_string(grid.y) +
                         " grid has enough samples around it");
  }
  for (int pass = 1, changed = 1; changed; ++pass) {
    changed = 0;
    std::vector<std::size_t> filled;
    std::vector<glm::dvec2> values;
    for (int j = 0; j < grid.y; ++j) {
      for (int i = 0; i < grid.x; ++i) {
        const std::size_t k = std::size_t(j) * grid.x + i;
        if (known[k]) continue;
        glm::dvec2 extrapolated(0.0), nearest(0.0);
        int extrapolations = 0, neighbours = 0;
        static constexpr int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
        for (int d = 0; d < 4; ++d) {
          const int i1 = i + di[d], j1 = j + dj[d], i2 = i + 2 * di[d], j2 = j + 2 * dj[d];
          if (i1 < 0 || i1 >= grid.x || j1 < 0 || j1 >= grid.y) continue;
          const std::size_t k1 = std::size_t(j1) * grid.x + i1;
          if (!known[k1]) continue;
          nearest += offset[k1];
          ++neighbours;
          if (i2 < 0 || i2 >= grid.x || j2 < 0 || j2 >= grid.y) continue;
          const std::size_t k2 = std::size_t(j2) * grid.x + i2;
          if (!known[k2]) continue;
          extrapolated += 2.0 * offset[k1] - offset[k2];
          ++extrapolations;
        }
        if (neighbours == 0) continue;
        filled.push_back(k);
        values.push_back(extrapolations > 0 ? extrapolated / double(extrapolations)
                                            : nearest / double(neighbours));
      }
    }
    for (std::size_t n = 0; n < filled.size(); ++n) {
      offset[filled[n]] = values[n];
      known[filled[n]] = 1;
      ring[filled[n]] = pass;
      changed = 1;
    }
  }

  // Unsupported nodes enclosed by supported ones (4-connected groups touching no side of the
  // grid: where decoding failed inside the image, e.g. on a printed chessboard's black squares) are
  // interpolated from all sides rather than extrapolated ring by ring from one, and the ring limit
  // does not uncover them: whether they are covered is the camera's view's call alone (see
  // bridge_px).
  std::vector<char> enclosed(nodes.size(), 0);
  {
    cv::Mat unsupported(grid.y, grid.x, CV_8U, cv::Scalar(0));
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      if (!nodes[k].supported) unsupported.at<std::uint8_t>(int(k) / grid.x, int(k) % grid.x) = 1;
    }
    cv::Mat labels;
    const int count = cv::connectedComponents(unsupported, labels, 4, CV_32S);
    std::vector<char> open(std::size_t(count), 0);
    for (int j = 0; j < grid.y; ++j) {
      for (int i = 0; i < grid.x; ++i) {
        if (i == 0 || j == 0 || i + 1 == grid.x || j + 1 == grid.y) {
          open[std::size_t(labels.at<std::int32_t>(j, i))] = 1;
        }
      }
    }
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const int label = labels.at<std::int32_t>(int(k) / grid.x, int(k) % grid.x);
      enclosed[k] = label > 0 && !open[std::size_t(label)] ? 1 : 0;
    }
    harmonic_fill(offset, enclosed, grid);
  }

  // Coverage: A at each node from the signed distance of its output position to the edge of what
  // the projector can light there, the nearer of the image edge and the edge of the part of the
  // image the camera saw, as 0.5 + distance / ramp. Within a cell, q is bilinear in st, so a
  // distance to a straight edge is bilinear too, and with no node of a cell clamped (the ramp
  // spans more than a cell either way) the interpolated A = 0.5 falls on the edge itself. The
  // camera's view ends at the same place on the screen for every projector, so neighbouring
  // projectors' covered regions end together there (to within a pixel), not at node-sized steps
  // a node or two beyond the last samples, which were extrapolated. Filled nodes more than
  // extrapolate_px rings out are uncovered whatever the distance says.
  warp.offset_px.resize(nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) warp.offset_px[k] = glm::vec2(offset[k]);
  warp.coverage.assign(nodes.size(), 1.0f);
  std::vector<glm::dvec2> q_seen;
  q_seen.reserve(samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (std::isnan(st_any[k].x)) continue;
    if (glm::length(warp.q_from_st(st_any[k]) - samples[k].q) <= options.outlier_px) {
      q_seen.push_back(samples[k].q);
    }
  }
  const double spacing_px = 0.5 * (step.x + step.y);
  const cv::Mat seen_px =
      seen_signed_distance(q_seen, output_size, int(std::ceil(options.edge_guard_px)) + 3,
                           0.75 * spacing_px, options.bridge_px);
  q_seen = {};
  const double ramp_px = 3 * std::max(step.x, step.y);
  const int extrapolate_rings = std::max(1, int(std::ceil(options.extrapolate_px / spacing_px)));
  result.node_origin.assign(nodes.size(), NodeOrigin::fitted);
  for (int j = 0; j < grid.y; ++j) {
    for (int i = 0; i < grid.x; ++i) {
      const std::size_t k = std::size_t(j) * grid.x + i;
      const glm::dvec2 q = glm::dvec2(i * step.x, j * step.y) + offset[k];
      const double inside_image =
          std::min(std::min(q.x, output_size.x - q.x), std::min(q.y, output_size.y - q.y));
      const double inside = std::min(inside_image, bilinear(seen_px, q));
      double coverage = std::clamp(0.5 + inside / ramp_px, 0.0, 1.0);
      if (ring[k] > extrapolate_rings && !enclosed[k]) coverage = 0;
      warp.coverage[k] = float(coverage);
      if (ring[k] > 0 && inside_image > 0) {
        ++(coverage < 0.5 ? result.report.holes : result.report.filled);
        if (enclosed[k] && coverage >= 0.5) ++result.report.holes_filled;
      }
      result.node_origin[k] = ring[k] == 0                     ? NodeOrigin::fitted
                              : enclosed[k] && coverage >= 0.5 ? NodeOrigin::hole_filled
                                                               : NodeOrigin::extrapolated;
    }
  }

  // Folds: a covered cell that reverses orientation holds a node fit that disagrees with its
  // neighbours (wrong codes along a shadow's edge, extrapolated rings crossing). Its four nodes
  // are interpolated again, once, from the nodes around them (harmonic_fill); what still folds
  // after that is uncovered. (Growing the refilled region while a fold remains moves good nodes:
  // on procam-board three rounds took the residual p99 from 3.4 to 4.8 px.)
  {
    std::vector<char> refill(nodes.size(), 0);
    for (const std::size_t k : folded_cells(warp)) {
      for (const std::size_t n : {k, k + 1, k + std::size_t(grid.x), k + std::size_t(grid.x) + 1}) {
        refill[n] = 1;
      }
    }
    harmonic_fill(offset, refill, grid);
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      if (!refill[k]) continue;
      warp.offset_px[k] = glm::vec2(offset[k]);
      result.node_origin[k] = NodeOrigin::fold_refilled;
      ++result.report.folds_refilled;
    }
  }
  while (const auto fold = warp.find_fold()) {
    const std::size_t k = warp.node_index(fold->x, fold->y);
    warp.coverage[k] = 0.0f;
    result.node_origin[k] = NodeOrigin::fold_cut;
    ++result.report.folds;
  }

  // Residuals of the decoded samples against the fitted warp.
  // Per block of output pixels (at the decoded position) their sum of squares and count.
  constexpr int kBlock = FitReport::kResidualBlockPx;
  const cv::Size blocks((output_size.x + kBlock - 1) / kBlock,
                        (output_size.y + kBlock - 1) / kBlock);
  cv::Mat block_sum_sq(blocks, CV_64F, cv::Scalar(0)), block_count(blocks, CV_64F, cv::Scalar(0));
  std::vector<double> residuals;
  residuals.reserve(samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (std::isnan(st[k].x) || warp.coverage_at(st[k]) < 0.5) continue;
    residuals.push_back(glm::length(warp.q_from_st(st[k]) - samples[k].q));
    const int bx = std::clamp(int(std::floor(samples[k].q.x)) / kBlock, 0, blocks.width - 1);
    const int by = std::clamp(int(std::floor(samples[k].q.y)) / kBlock, 0, blocks.height - 1);
    block_sum_sq.at<double>(by, bx) += residuals.back() * residuals.back();
    block_count.at<double>(by, bx) += 1;
  }
  result.report.residual_map.create(blocks, CV_32F);
  for (int by = 0; by < blocks.height; ++by) {
    for (int bx = 0; bx < blocks.width; ++bx) {
      const double n = block_count.at<double>(by, bx);
      result.report.residual_map.at<float>(by, bx) =
          n > 0 ? float(std::sqrt(block_sum_sq.at<double>(by, bx) / n)) : float(kNaN);
    }
  }
  // The worst region: the 32×32 output pixels (4×4 blocks, on their grid) with the largest RMS
  // residual among those holding at least kMinRegionSamples covered samples, so that a few
  // stray samples do not make one.
  {
    constexpr int kRegionBlocks = FitReport::kWorstRegionPx / kBlock;
    constexpr double kMinRegionSamples = 32;
    for (int ry = 0; ry < blocks.height; ry += kRegionBlocks) {
      for (int rx = 0; rx < blocks.width; rx += kRegionBlocks) {
        const cv::Rect region(rx, ry, std::min(kRegionBlocks, blocks.width - rx),
                              std::min(kRegionBlocks, blocks.height - ry));
        const double n = cv::sum(block_count(region))[0];
        if (n < kMinRegionSamples) continue;
        const double rms = std::sqrt(cv::sum(block_sum_sq(region))[0] / n);
        if (rms > result.report.worst_region_rms_px) {
          result.report.worst_region_rms_px = rms;
          result.report.worst_region_px =
              glm::dvec2(std::min(double(output_size.x), (rx + kRegionBlocks) * double(kBlock)) +
                             rx * double(kBlock),
                         std::min(double(output_size.y), (ry + kRegionBlocks) * double(kBlock)) +
                             ry * double(kBlock)) *
              0.5;
        }
      }
    }
  }
  if (!residuals.empty()) {
    double sum = 0;
    std::size_t outliers = 0;
    for (const double r : residuals) {
      sum += r * r;
      outliers += r > options.outlier_px ? 1 : 0;
    }
    result.report.residual_rms_px = std::sqrt(sum / double(residuals.size()));
    result.report.outlier_fraction = double(outliers) / double(residuals.size());
    result.report.residual_p50_px = percentile(residuals, 0.5);
    result.report.residual_p99_px = percentile(std::move(residuals), 0.99);
  }
  warp.validate(source);
  return result;
}

}  // namespace facet::calibration
