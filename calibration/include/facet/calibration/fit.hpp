#pragma once
// Warp fitting: from decoded correspondences (eye direction v → projector position q) to the
// offset map of one projector (FORMATS.md §2).
//
// A base projection and node grid are chosen to cover the projector's footprint (facet::
// cover_directions). Every node's output position is a robust local fit of the decoded projector
// positions around the node's direction: a weighted quadratic in the base coordinates st, with a
// tricube kernel over a disc of a few node spacings, the decode confidence, and Tukey biweights
// (IRLS) that drop wrong Gray codes. Noise is averaged by the fit, never blurred afterwards.
// Binning the samples by st and taking a node's neighbours from the bins is the same as
// projecting the node's direction into the camera and taking the camera pixels around it, but
// works unchanged when the camera is offset from the eye. The covered region ends at the nearer
// of the image edge and the edge of what the camera saw of the image (the decoded positions that
// agree with the fit), each within about a pixel.
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "facet/calibration/camera_model.hpp"
#include "facet/calibration/capture.hpp"
#include "facet/calibration/decode.hpp"
#include "facet/projection/footprint.hpp"
#include "facet/projection/warp.hpp"

namespace facet::calibration {

// One decoded correspondence.
struct FitSample {
  glm::dvec3 v_eye;    // unit eye-frame direction the camera pixel sees
  glm::dvec2 q;        // projector position in output pixels (pixel c spans [c, c+1))
  float weight = 1.f;  // relative confidence in (0, 1]
};

struct FitOptions {
  // Node grid (Gw, Gh); {0, 0} picks one node about every node_spacing_px output pixels.
  glm::ivec2 grid{0, 0};
  double node_spacing_px = 16;
  // With the grid chosen from node_spacing_px: when the bilinear interpolation between nodes
  // would miss the fitted map's curvature by more than this (90th percentile over the nodes,
  // estimated from the quadratic terms of their fits), the grid is refined once, down to
  // min_node_spacing_px. 0 keeps the spacing.
  double max_interpolation_error_px = 0.02;
  double min_node_spacing_px = 4;
  // Radius of a node's neighbourhood, in node spacings. Larger averages more noise and bends
  // less with the warp's curvature; the quadratic model keeps the bias small either way.
  double radius_nodes = 1.6;
  // A node is supported when its kernel weights add up to at least this many samples and its
  // fit is well-posed (see max_gain); unsupported nodes are extrapolated and not covered.
  double min_samples = 12;
  // Noise gain of the fitted value, [N⁻¹]₀₀·Σw: 1 for a plain mean, a few for a centred
  // quadratic, large when the node lies beyond the samples and the fit would extrapolate.
  double max_gain = 40;
  // Unsupported nodes are filled by extrapolating outwards, ring by ring; the rings beyond this
  // many output pixels of the supported nodes (at least one ring) are uncovered, whatever the
  // image edge and the camera's view say.
  double extrapolate_px = 8;
  // The covered region ends where the camera's view of the image ends (within about a pixel), not
  // where the extrapolated nodes do. Holes in that view enclosed by it, every point within this
  // many output pixels of a seen one, are interpolated from all sides by the fit and stay covered.
  double bridge_px = 24;
  int irls_iterations = 3;
  // Tukey biweight cut-off: max(tukey_sigmas · robust σ, min_cutoff_px).
  double tukey_sigmas = 4.685;
  double min_cutoff_px = 0.75;
  // Samples decoded within this many output pixels of the image edge are left out: projector
  // defocus and camera blur mix the edge with the dark beyond it, which pulls the positions
  // decoded there inwards (up to 1 px error within 5 px of the edge on the simulated rigs, with
  // 1 px projector defocus and 0.5 camera pixel blur). The fit extrapolates the last few pixels
  // smoothly instead.
  double edge_guard_px = 5;
  // Residuals above this count as outliers in the report (output pixels).
  double outlier_px = 2.0;
  // Base projection: a perspective lined up with the projector (its axis and rows, from a
  // homography fitted to the samples) when the samples stay within max_aligned_half_angle_rad of
  // its axis horizontally and vertically (margin included); otherwise, or when disabled,
  // cover_directions with `cover`.
  bool projector_aligned_base = true;
  double max_aligned_half_angle_rad = 1.22;  // about 70°
  CoverOptions cover;
};

struct FitReport {
  std::size_t samples = 0;    // correspondences given
  glm::ivec2 grid{0, 0};      // node grid chosen
  std::size_t supported = 0;  // nodes with a well-posed fit
  std::size_t filled = 0;     // unsupported nodes inside the image, extrapolated and kept covered
  std::size_t holes = 0;      // unsupported nodes inside the image left uncovered
  std::size_t holes_filled = 0;    // of `filled`, nodes enclosed by supported ones, interpolated
  std::size_t folds_refilled = 0;  // nodes of folded cells interpolated again from around them
  std::size_t folds = 0;           // nodes uncovered because their cell still folded after that
  double residual_rms_px = 0;      // RMS |warp(v) − q| over samples the warp covers
  double residual_p50_px = 0;      // median of the same
  double residual_p99_px = 0;      // 99th percentile of the same
  double outlier_fraction = 0;     // share of those samples with residual > outlier_px
  // RMS residual per block of kResidualBlockPx × kResidualBlockPx output pixels, by the samples'
  // decoded positions (CV_32F, ⌈W/8⌉ × ⌈H/8⌉); NaN where no covered sample falls.
  static constexpr int kResidualBlockPx = 8;
  cv::Mat residual_map;
  // The kWorstRegionPx-square region of output pixels (on a grid from the origin) with the largest
  // RMS residual, among those holding at least 32 covered samples: its centre and that RMS.
  static constexpr int kWorstRegionPx = 32;
  glm::dvec2 worst_region_px{0.0};
  double worst_region_rms_px = 0;
};

// Where a node's offset comes from.
enum class NodeOrigin : std::uint8_t {
  fitted,         // its own fit of the samples around it
  extrapolated,   // filled outwards ring by ring from fitted nodes (covered or not)
  hole_filled,    // enclosed by fitted nodes, interpolated from all sides and covered
  fold_refilled,  // in a folded cell, interpolated again from the nodes around it
  fold_cut,       // uncovered because its cell still folded
};

struct WarpFit {
  Warp warp;
  FitReport report;
  std::vector<NodeOrigin> node_origin;  // per node, the layout of Warp::offset_px
};

// Fits the warp of a projector of `output_size` pixels. Throws InputError(source, "projectors",
// ...) when there are too few samples to fit (the camera never sees the projector). The warp
// passes Warp::validate(): cells that would fold are left uncovered and counted in the report.
WarpFit fit_warp(std::span<const FitSample> samples, glm::ivec2 output_size,
                 const FitOptions& options = {}, const std::string& source = "samples");

// The eye-frame unit direction of each camera pixel (CV_64FC3, size camera_size): the model's ray
// rotated by R_eye_camera when the camera sits at the eye; otherwise the ray from t_eye_camera is
// intersected with the screen (nearest hit in front of the camera) and the direction taken from
// the eye. NaN where there is no direction (outside the model's valid region, no hit) and where
// `wanted` (CV_8U, optional) is 0. Runs in parallel over rows.
cv::Mat eye_directions(const CameraModel& model, const CaptureCamera& camera,
                       const std::optional<Screen>& screen, glm::ivec2 camera_size,
                       const cv::Mat& wanted = {});

// The correspondences of a decoded map: every decoded camera pixel with both axes measured and a
// finite direction. Weights are the decode confidence squared (noise of a phase goes as
// 1/modulation), floored at 0.01.
std::vector<FitSample> fit_samples(const DecodedMap& decoded, const cv::Mat& v_eye);

}  // namespace facet::calibration
