#pragma once
// The whole calibration: a recorded capture (FORMATS.md §1) → an output folder holding
// display.json (§4), `<p>.warp.exr` (§2) and `<p>.blend.exr` (§3) for every projector, plus
// `<p>.black.exr` when black-level maps are asked for, and report/ with `<p>.residual.png` (the fit
// residual as a heat map) and `<p>.coverage.png` (covered, filled holes, refilled and cut folds),
// and for the whole display seen from the eye `composite.png` (every projector blended, in its
// colour) and `preview.png` (the residual), drawn as facet preview draws them
// (calibration/README.md); with an accuracy report against the capture's `truth/` (§5) when it
// has one, and a verdict per projector (judge).
#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/calibration/blend.hpp"
#include "facet/calibration/decode.hpp"
#include "facet/calibration/fit.hpp"
#include "facet/projection/progress.hpp"
#include "facet/projection/warp.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::calibration {

struct CalibrateOptions {
  DecodeOptions decode;
  FitOptions fit;
  BlendOptions blend;
  // The display to write back, warps and blends filled in: its name, eye, screen, outputs,
  // gammas, render settings and cluster are kept. Its projectors must be the capture's (names and
  // sizes). nullopt: the display.json the capture ran with (capture.json's `display`), else a new
  // display named after the capture folder, its projectors side by side as windows.
  std::optional<projection_io::DisplayConfig> display;
  std::string display_name;    // empty: the display's name, else the capture folder's
  double truth_border_px = 8;  // FORMATS.md §5
  // Steps as they finish: ("decoding", p, projectors), ("fitting warps", p, projectors), then
  // ("blending", 0 and 1, 1).
  ProgressSink progress;
};

// Calibrated against true warp, FORMATS.md §5: at the truth's projector pixel centres at least
// border_px from the image edge, the distance in output pixels between the calibrated warp's
// position of the true direction and the pixel centre, over directions both warps cover.
struct AccuracyReport {
  double rms_px = 0, p99_px = 0, max_px = 0;
  glm::dvec2 max_at_px{0.0};      // the truth's pixel centre where max_px occurs
  std::size_t compared = 0;       // pixel centres compared
  double uncovered_fraction = 0;  // share of the truth's pixels the calibrated warp misses
};

AccuracyReport compare_warps(const Warp& truth, const Warp& calibrated, double border_px = 8);

enum class Verdict { good, check, bad };
const char* to_string(Verdict verdict);

// What makes a projector's calibration good, check or bad (calibration/README.md, "Verdict").
// A value past a check_* threshold makes it at least "check", past a bad_* one "bad".
struct VerdictThresholds {
  // Share of the output pixels covered: a camera that sees little of the image.
  double check_coverage_below = 0.9, bad_coverage_below = 0.1;
  // Fit residual of the decoded samples, output pixels: noise and wrong codes.
  double check_residual_p50_px = 0.5, bad_residual_p50_px = 1.0;
  double check_residual_p99_px = 2.0, bad_residual_p99_px = 5.0;
  // RMS residual of the worst 32×32 region: a local defect (a shadow, a reflection).
  double check_worst_region_px = 2.0, bad_worst_region_px = 5.0;
  // Enclosed hole nodes interpolated, as a share of the supported nodes: much of the image was
  // not decoded and is guessed.
  double check_holes_filled_share = 0.05, bad_holes_filled_share = 0.25;
  // Nodes cut back for folding: any makes it "check".
  std::size_t check_folds = 1;
  // Unlit output pixels inside the lit region (see unlit_inside): any is a pin-hole, "bad".
  std::size_t bad_unlit_inside = 1;
};

struct ProjectorVerdict {
  Verdict verdict = Verdict::good;
  std::vector<std::string> reasons;  // one per threshold crossed, e.g. "residual p99 3.4 px > 2"
};

// Unlit output pixels (weight 0) inside the lit region of a W×H weight map: a pixel is inside
// when the 8 pixels at (±r, 0), (0, ±r) and (±r, ±r) from it are all lit, so that any unlit speck
// narrower than r counts while notches in the region's outer edge do not.
std::size_t unlit_inside(const std::vector<float>& weight, glm::ivec2 size, int r = 24);

struct ProjectorReport {
  std::string name;
  glm::ivec2 size{0, 0};
  std::size_t decoded_pixels = 0;  // camera pixels that decoded this projector
  double coverage = 0;           // share of the projector's output pixels the calibrated warp maps
  std::size_t unlit_inside = 0;  // of its blend map, r = 24 px
  FitReport fit;
  std::optional<AccuracyReport> accuracy;
  ProjectorVerdict verdict;  // judge(*this) once the rest is filled in
};

ProjectorVerdict judge(const ProjectorReport& projector, const VerdictThresholds& thresholds = {});

struct CalibrationReport {
  std::vector<ProjectorReport> projectors;
  double blend_sum_max_err = 0;  // see check_blend
  std::size_t blend_overlap_directions = 0;
  std::string blend_worst;  // where blend_sum_max_err occurs: "projector at (x, y)"
  // Where one projector lights alone (see check_blend): directions sampled, how many of them have
  // α below 1 − 0.005 (next to where a neighbour's covered region ends, its weight is carried on
  // for a few pixels), and the least α among them.
  std::size_t blend_single_directions = 0;
  std::size_t blend_single_dim_directions = 0;
  double blend_single_min = 1;
  double seconds = 0;

  Verdict verdict() const;  // the worst of the projectors'
  nlohmann::json to_json() const;
};

// Reads the capture at `capture_path` (capture.json or its folder), decodes, fits and blends
// every projector, and writes the folder `out` atomically: everything goes to a temporary sibling
// folder that is renamed onto `out` at the end, so a failure leaves nothing. `out` must not exist,
// or be an empty folder. Throws InputError naming the file and field on bad input: capture.json
// errors, missing frames, unreadable images or images of different sizes, a missing camera model,
// a projector the camera never sees, a truth warp that cannot be read. After watch_interrupts(),
// SIGINT or SIGTERM stops it between projectors and stages with Interrupted, leaving nothing.
CalibrationReport calibrate(const std::filesystem::path& capture_path,
                            const std::filesystem::path& out, const CalibrateOptions& options = {});

}  // namespace facet::calibration
