#pragma once
// The whole calibration: a recorded capture (FORMATS.md §1) → an output folder holding
// display.json (§4), `<p>.warp.exr` (§2) and `<p>.blend.exr` (§3) for every projector, plus
// `<p>.black.exr` when black-level maps are asked for; with an accuracy report against the
// capture's `truth/` (§5) when it has one.
#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/calibration/blend.hpp"
#include "facet/calibration/decode.hpp"
#include "facet/calibration/fit.hpp"
#include "facet/projection/warp.hpp"

namespace facet::calibration {

struct CalibrateOptions {
  DecodeOptions decode;
  FitOptions fit;
  BlendOptions blend;
  std::string display_name;    // empty: the capture folder's name
  double truth_border_px = 8;  // FORMATS.md §5
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

struct ProjectorReport {
  std::string name;
  glm::ivec2 size{0, 0};
  std::size_t decoded_pixels = 0;  // camera pixels that decoded this projector
  double coverage = 0;  // share of the projector's output pixels the calibrated warp maps
  FitReport fit;
  std::optional<AccuracyReport> accuracy;
};

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
