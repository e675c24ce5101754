#include "facet/calibration/calibrate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <opencv2/imgproc.hpp>
#include <span>
#include <tuple>

#include "facet/calibration/camera_model.hpp"
#include "facet/calibration/capture.hpp"
#include "facet/calibration/image_io.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/display_preview.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet::calibration {
namespace {

namespace fs = std::filesystem;

double percentile(std::vector<double>& values, double fraction) {
  if (values.empty()) return 0;
  const std::size_t k =
      std::min(values.size() - 1, std::size_t(std::ceil(fraction * double(values.size()))) - 1);
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

// The pixels unlit_inside counts, row-major.
std::vector<char> unlit_inside_mask(const std::vector<float>& weight, glm::ivec2 size, int r) {
  FACET_ASSERT(weight.size() == std::size_t(size.x) * std::size_t(size.y) && r > 0);
  auto lit = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < size.x && y < size.y &&
           weight[std::size_t(y) * std::size_t(size.x) + std::size_t(x)] > 0;
  };
  std::vector<char> unlit(weight.size(), 0);
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      if (lit(x, y)) continue;
      bool inside = true;
      for (int dy = -r; dy <= r && inside; dy += r) {
        for (int dx = -r; dx <= r && inside; dx += r) {
          if (dx != 0 || dy != 0) inside = lit(x + dx, y + dy);
        }
      }
      unlit[std::size_t(y) * std::size_t(size.x) + std::size_t(x)] = inside ? 1 : 0;
    }
  }
  return unlit;
}

// The colour of report/<p>.residual.png and report/preview.png (calibration/README.md): RMS
// residual in output pixels on the preview's heat scale.
cv::Vec3b residual_colour(double px) {
  const glm::u8vec3 rgb = residual_heat_srgb(px);
  return {rgb.x, rgb.y, rgb.z};
}

// Colours of report/<p>.coverage.png (calibration/README.md).
const cv::Vec3b kUncovered(0, 0, 0), kCovered(160, 160, 160), kHoleFilled(0, 110, 255),
    kFoldRefilled(255, 200, 0), kFoldCut(255, 0, 0), kPinHole(255, 0, 255);
const cv::Scalar kWorstRegionOutline(255, 0, 255);

// The fit's RMS residual per 8×8 block of output pixels in the colours of kResidualScale, black
// where no covered sample falls, the worst region outlined in magenta: CV_8UC3, RGB.
cv::Mat residual_image(const FitReport& fit, glm::ivec2 size) {
  cv::Mat image(size.y, size.x, CV_8UC3, cv::Scalar(0, 0, 0));
  const int block = FitReport::kResidualBlockPx;
  for (int y = 0; y < size.y; ++y) {
    auto* row = image.ptr<cv::Vec3b>(y);
    for (int x = 0; x < size.x; ++x) {
      const float rms = fit.residual_map.at<float>(y / block, x / block);
      if (std::isfinite(rms)) row[x] = residual_colour(rms);
    }
  }
  if (fit.worst_region_rms_px > 0) {
    const glm::dvec2 corner = fit.worst_region_px - 0.5 * FitReport::kWorstRegionPx;
    cv::rectangle(image,
                  cv::Rect(int(std::lround(corner.x)), int(std::lround(corner.y)),
                           FitReport::kWorstRegionPx, FitReport::kWorstRegionPx),
                  kWorstRegionOutline, 1);
  }
  return image;
}

// An RGBA8 image of render_preview as CV_8UC3, RGB.
cv::Mat rgb_of(const std::vector<std::uint8_t>& rgba, glm::ivec2 size) {
  cv::Mat rgb(size.y, size.x, CV_8UC3);
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      const std::uint8_t* pixel = &rgba[(std::size_t(y) * size.x + x) * 4];
      rgb.at<cv::Vec3b>(y, x) = {pixel[0], pixel[1], pixel[2]};
    }
  return rgb;
}

// What the audience sees from the eye, every projector composited on fitted_preview_view (768
// rows), as facet preview computes and draws it (preview_display, render_preview): `composite`
// each projector in its colour weighted by its blend (facet preview's default, --show
// projectors), `residual` each direction coloured by the fit residual of the projector with the
// largest blend weight there. CV_8UC3, RGB.
struct EyeViews {
  cv::Mat composite, residual;
};
EyeViews eye_views(const std::vector<Warp>& warps,
                   const std::vector<projection_io::BlendMap>& alpha,
                   const CalibrationReport& report) {
  std::vector<cv::Mat> residuals(warps.size());
  std::vector<PreviewProjector> projectors;
  for (std::size_t p = 0; p < warps.size(); ++p) {
    const FitReport& fit = report.projectors[p].fit;
    residuals[p] = fit.residual_map.isContinuous() ? fit.residual_map : fit.residual_map.clone();
    PreviewProjector projector;
    projector.name = report.projectors[p].name;
    projector.warp = &warps[p];
    projector.alpha_size = alpha[p].size;
    projector.alpha_channels = alpha[p].channels;
    projector.alpha = alpha[p].values;
    if (!residuals[p].empty()) {
      projector.residual_blocks = {residuals[p].cols, residuals[p].rows};
      projector.residual_block_px = FitReport::kResidualBlockPx;
      projector.residual_px = {residuals[p].ptr<float>(), residuals[p].total()};
    }
    projectors.push_back(projector);
  }
  PreviewOptions options;
  options.view = fitted_preview_view(projectors);
  options.height_px = 768;
  const DisplayPreview preview = preview_display(projectors, options, "calibration");
  return {rgb_of(render_preview(preview, PreviewShow::projectors, options.view), preview.size),
          rgb_of(render_preview(preview, PreviewShow::residual, options.view), preview.size)};
}

// Lit pixels grey, unlit black; over them, at each node's output position, a disc half a node
// spacing wide in the colour of where its offset comes from: filled holes and refilled folds
// over lit pixels, cut folds anywhere; unlit pixels inside the lit region (pin-holes) on top.
cv::Mat coverage_image(const Warp& warp, std::span<const NodeOrigin> origin,
                       const projection_io::BlendMap& alpha) {
  const glm::ivec2 size = alpha.size;
  cv::Mat image(size.y, size.x, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::Mat lit(size.y, size.x, CV_8U, cv::Scalar(0));
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const bool on = alpha.at(x, y) > 0;
      lit.at<std::uint8_t>(y, x) = on ? 1 : 0;
      image.at<cv::Vec3b>(y, x) = on ? kCovered : kUncovered;
    }
  }
  const glm::ivec2 grid = warp.grid_size;
  const glm::dvec2 step{double(warp.output_size.x) / (grid.x - 1),
                        double(warp.output_size.y) / (grid.y - 1)};
  const int radius = std::max(1, int(std::lround(0.5 * std::min(step.x, step.y))));
  for (const auto& [kind, colour, only_lit] :
       {std::tuple{NodeOrigin::fold_refilled, kFoldRefilled, true},
        std::tuple{NodeOrigin::hole_filled, kHoleFilled, true},
        std::tuple{NodeOrigin::fold_cut, kFoldCut, false}}) {
    cv::Mat marks(size.y, size.x, CV_8U, cv::Scalar(0));
    for (int j = 0; j < grid.y; ++j) {
      for (int i = 0; i < grid.x; ++i) {
        const std::size_t k = warp.node_index(i, j);
        if (origin[k] != kind) continue;
        const glm::dvec2 q = glm::dvec2(i * step.x, j * step.y) + glm::dvec2(warp.offset_px[k]);
        cv::circle(marks, cv::Point(int(std::floor(q.x)), int(std::floor(q.y))), radius,
                   cv::Scalar(1), cv::FILLED);
      }
    }
    if (only_lit) marks &= lit;
    image.setTo(cv::Scalar(colour[0], colour[1], colour[2]), marks);
  }
  const std::vector<char> pin_holes = unlit_inside_mask(alpha.values, size, 24);
  for (std::size_t n = 0; n < pin_holes.size(); ++n) {
    if (pin_holes[n]) image.at<cv::Vec3b>(int(n) / size.x, int(n) % size.x) = kPinHole;
  }
  return image;
}
}  // namespace

const char* to_string(Verdict verdict) {
  switch (verdict) {
    case Verdict::good:
      return "good";
    case Verdict::check:
      return "check";
    case Verdict::bad:
      return "bad";
  }
  return "bad";
}

std::size_t unlit_inside(const std::vector<float>& weight, glm::ivec2 size, int r) {
  const std::vector<char> unlit = unlit_inside_mask(weight, size, r);
  return std::size_t(std::count(unlit.begin(), unlit.end(), 1));
}

ProjectorVerdict judge(const ProjectorReport& projector, const VerdictThresholds& thresholds) {
  ProjectorVerdict result;
  char text[160];
  // Raises the verdict to `level` with a reason: what, its value, the threshold crossed.
  auto raise = [&](Verdict level, const char* what, double value, const char* relation,
                   double threshold, const char* unit) {
    std::snprintf(text, sizeof text, "%s %.3g%s %s %.3g%s (%s)", what, value, unit, relation,
                  threshold, unit, to_string(level));
    result.reasons.emplace_back(text);
    result.verdict = std::max(result.verdict, level);
  };
  // The bad threshold first: one reason per quantity.
  auto above = [&](const char* what, double value, double check, double bad, const char* unit) {
    if (value > bad) {
      raise(Verdict::bad, what, value, ">", bad, unit);
    } else if (value > check) {
      raise(Verdict::check, what, value, ">", check, unit);
    }
  };
  const FitReport& fit = projector.fit;
  if (projector.coverage < thresholds.bad_coverage_below) {
    raise(Verdict::bad, "coverage", 100 * projector.coverage, "<",
          100 * thresholds.bad_coverage_below, " %");
  } else if (projector.coverage < thresholds.check_coverage_below) {
    raise(Verdict::check, "coverage", 100 * projector.coverage, "<",
          100 * thresholds.check_coverage_below, " %");
  }
  above("residual p50", fit.residual_p50_px, thresholds.check_residual_p50_px,
        thresholds.bad_residual_p50_px, " px");
  above("residual p99", fit.residual_p99_px, thresholds.check_residual_p99_px,
        thresholds.bad_residual_p99_px, " px");
  above("worst region rms", fit.worst_region_rms_px, thresholds.check_worst_region_px,
        thresholds.bad_worst_region_px, " px");
  const double holes_share =
      fit.supported == 0 ? 0.0 : double(fit.holes_filled) / double(fit.supported);
  above("holes filled, share of supported nodes,", 100 * holes_share,
        100 * thresholds.check_holes_filled_share, 100 * thresholds.bad_holes_filled_share, " %");
  if (fit.folds >= thresholds.check_folds) {
    raise(Verdict::check, "folds cut", double(fit.folds), ">=", double(thresholds.check_folds),
          " nodes");
  }
  if (projector.unlit_inside >= thresholds.bad_unlit_inside) {
    raise(Verdict::bad, "unlit pixels inside the lit region", double(projector.unlit_inside),
          ">=", double(thresholds.bad_unlit_inside), "");
  }
  return result;
}

Verdict CalibrationReport::verdict() const {
  Verdict worst = Verdict::good;
  for (const ProjectorReport& p : projectors) worst = std::max(worst, p.verdict.verdict);
  return worst;
}

AccuracyReport compare_warps(const Warp& truth, const Warp& calibrated, double border_px) {
  const std::vector<glm::dvec2> st = WarpInverse(truth).st_at_pixel_centres();
  std::vector<double> errors;
  std::size_t truth_pixels = 0;
  double worst = -1;
  glm::dvec2 worst_at(0.0);
  const glm::ivec2 size = truth.output_size;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const glm::dvec2 q(x + 0.5, y + 0.5);
      if (q.x < border_px || q.y < border_px || q.x > size.x - border_px ||
          q.y > size.y - border_px) {
        continue;
      }
      const glm::dvec2 st_truth = st[std::size_t(y) * size.x + x];
      if (std::isnan(st_truth.x)) continue;
      ++truth_pixels;
      const auto projected = calibrated.project(truth.v_eye_from_st(st_truth));
      if (!projected || !projected->covered) continue;
      errors.push_back(glm::length(projected->q - q));
      if (errors.back() > worst) {
        worst = errors.back();
        worst_at = q;
      }
    }
  }
  AccuracyReport report;
  report.compared = errors.size();
  report.uncovered_fraction =
      truth_pixels == 0 ? 1.0 : 1.0 - double(errors.size()) / double(truth_pixels);
  if (errors.empty()) return report;
  double sum = 0;
  for (const double e : errors) sum += e * e;
  report.rms_px = std::sqrt(sum / double(errors.size()));
  report.max_px = worst;
  report.max_at_px = worst_at;
  report.p99_px = percentile(errors, 0.99);
  return report;
}

nlohmann::json CalibrationReport::to_json() const {
  nlohmann::json items = nlohmann::json::array();
  for (const ProjectorReport& p : projectors) {
    nlohmann::json item = {{"name", p.name},
                           {"size", {p.size.x, p.size.y}},
                           {"coverage", p.coverage},
                           {"decoded_pixels", p.decoded_pixels},
                           {"grid", {p.fit.grid.x, p.fit.grid.y}},
                           {"residual_px", p.fit.residual_rms_px},
                           {"residual_p50_px", p.fit.residual_p50_px},
                           {"residual_p99_px", p.fit.residual_p99_px},
                           {"outlier_fraction", p.fit.outlier_fraction},
                           {"filled", p.fit.filled},
                           {"holes", p.fit.holes},
                           {"holes_filled", p.fit.holes_filled},
                           {"folds_refilled", p.fit.folds_refilled},
                           {"folds", p.fit.folds},
                           {"unlit_inside", p.unlit_inside},
                           {"worst_region_px", {p.fit.worst_region_px.x, p.fit.worst_region_px.y}},
                           {"worst_region_rms_px", p.fit.worst_region_rms_px},
                           {"verdict", to_string(p.verdict.verdict)},
                           {"reasons", p.verdict.reasons}};
    if (p.accuracy) {
      item["rms_px"] = p.accuracy->rms_px;
      item["p99_px"] = p.accuracy->p99_px;
      item["max_px"] = p.accuracy->max_px;
      item["max_at_px"] = {p.accuracy->max_at_px.x, p.accuracy->max_at_px.y};
      item["compared_pixels"] = p.accuracy->compared;
      item["uncovered_fraction"] = p.accuracy->uncovered_fraction;
    }
    items.push_back(std::move(item));
  }
  return {{"projectors", items},
          {"verdict", to_string(verdict())},
          {"blend_sum_max_err", blend_sum_max_err},
          {"blend_overlap_directions", blend_overlap_directions},
          {"blend_worst", blend_worst},
          {"blend_single_directions", blend_single_directions},
          {"blend_single_dim_directions", blend_single_dim_directions},
          {"blend_single_min", blend_single_min},
          {"seconds", seconds}};
}

namespace {

// InputError naming the display file unless its projectors are the capture's: the same names,
// each with the size it was captured at.
void check_display_matches_capture(const projection_io::DisplayConfig& display,
                                   const Capture& capture) {
  const std::string source = (display.folder / "display.json").string();
  for (const CaptureProjector& projector : capture.projectors) {
    const auto it = std::find_if(
        display.projectors.begin(), display.projectors.end(),
        [&](const projection_io::DisplayProjector& p) { return p.name == projector.name; });
    if (it == display.projectors.end())
      throw InputError(source, "projectors",
                       "a projector named '" + projector.name + "', as in the capture");
    if (it->size != projector.size)
      throw InputError(source,
                       "projectors[" + std::to_string(it - display.projectors.begin()) + "].size",
                       std::to_string(projector.size.x) + "x" + std::to_string(projector.size.y) +
                           ", the size '" + projector.name + "' was captured at");
  }
  if (display.projectors.size() != capture.projectors.size())
    throw InputError(
        source, "projectors",
        "the capture's " + std::to_string(capture.projectors.size()) + " projectors and no others");
}

// The display facet calibrate writes (before its file names are set): `base` with its name
// overridden by options.display_name, or a new one of windows side by side.
projection_io::DisplayConfig written_display(
    const Capture& capture, const std::optional<projection_io::DisplayConfig>& base,
    const CalibrateOptions& options) {
  projection_io::DisplayConfig display;
  if (base) {
    display = *base;
    if (!display.screen) display.screen = capture.screen;
  } else {
    display.name = fs::absolute(capture.folder).filename().string();
    display.screen = capture.screen;
    int x = 0;
    for (const CaptureProjector& projector : capture.projectors) {
      projection_io::DisplayProjector item;
      item.name = projector.name;
      item.size = projector.size;
      // Until the outputs are assigned, projectors sit side by side as windows on the desktop.
      item.output.kind = projection_io::DisplayOutput::Kind::window;
      item.output.window = {x, 0, projector.size.x, projector.size.y};
      x += projector.size.x;
      display.projectors.push_back(std::move(item));
    }
  }
  if (!options.display_name.empty()) display.name = options.display_name;
  if (display.name.empty()) display.name = "display";
  return display;
}

}  // namespace

CalibrationReport calibrate(const fs::path& capture_path, const fs::path& out,
                            const CalibrateOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  const Capture capture = read_capture(capture_path);
  const std::string capture_json = (capture.folder / "capture.json").string();
  // Checked before any heavy work, and again when written.
  OutputFolderRules out_rules;
  out_rules.field = OptionName{"out"};
  out_rules.inputs = {capture.folder};
  check_output_folder(out, out_rules);
  // Polled between projectors and stages; write_folder_atomically then removes the temporary.
  const std::string stopped = "stopped before the end; nothing written to " + out.string();
  const CameraModel model = CameraModel::read(capture.resolve(capture.camera.model));
  // The display to write back, checked against the capture before any heavy work.
  std::optional<projection_io::DisplayConfig> base_display = options.display;
  if (!base_display && capture.display)
    base_display = projection_io::read_display_template(capture.resolve(*capture.display));
  if (base_display) check_display_matches_capture(*base_display, capture);

  // Check every projector's frames and image headers before any heavy work.
  for (std::size_t p = 0; p < capture.projectors.size(); ++p) {
    const glm::ivec2 camera_size = check_capture_images(capture, p);
    if (camera_size != model.imager_size()) {
      throw InputError(capture_json, "camera.model",
                       "a camera model of the images' size " + std::to_string(camera_size.x) + "x" +
                           std::to_string(camera_size.y) + ", but the model's imager is " +
                           std::to_string(model.imager_size().x) + "x" +
                           std::to_string(model.imager_size().y));
    }
  }
  const std::uint64_t projectors = capture.projectors.size();
  const auto report_step = [&options](std::string_view what, std::uint64_t done,
                                      std::uint64_t total) {
    if (options.progress) options.progress({what, done, total});
  };
  std::vector<DecodedMap> decoded;
  report_step("decoding", 0, projectors);
  for (std::size_t p = 0; p < capture.projectors.size(); ++p) {
    throw_if_interrupted(stopped);
    decoded.push_back(decode_capture(capture, p, options.decode));
    report_step("decoding", p + 1, projectors);
    const DecodedMap& map = decoded.back();
    if (!map.has_x || !map.has_y) {
      throw InputError(capture_json, "projectors[" + std::to_string(p) + "].frames",
                       "patterns on both axes (x and y), to locate every pixel");
    }
  }
  // Unproject each camera pixel once, for every projector that decoded it.
  const glm::ivec2 camera_size = decoded.front().camera_size;
  cv::Mat wanted(camera_size.y, camera_size.x, CV_8U, cv::Scalar(0));
  for (const DecodedMap& map : decoded) wanted.setTo(1, map.mask == 0);
  const cv::Mat v_eye = eye_directions(model, capture.camera, capture.screen, camera_size, wanted);

  CalibrationReport report;
  std::vector<Warp> warps;
  std::vector<std::vector<NodeOrigin>> node_origins;
  report_step("fitting warps", 0, projectors);
  for (std::size_t p = 0; p < capture.projectors.size(); ++p) {
    throw_if_interrupted(stopped);
    const CaptureProjector& projector = capture.projectors[p];
    const std::vector<FitSample> samples = fit_samples(decoded[p], v_eye);
    WarpFit fit;
    try {
      fit = fit_warp(samples, projector.size, options.fit, capture_json);
    } catch (const InputError& e) {
      throw InputError(capture_json,
                       "projectors[" + std::to_string(p) + "] ('" + projector.name + "')",
                       e.expected());
    }
    ProjectorReport item;
    item.name = projector.name;
    item.size = projector.size;
    item.decoded_pixels = std::size_t(cv::countNonZero(decoded[p].mask == 0));
    item.fit = fit.report;
    if (capture.truth) {
      const fs::path truth_file = capture.resolve(*capture.truth) / (projector.name + ".warp.exr");
      std::error_code error;
      if (fs::exists(truth_file, error)) {
        item.accuracy =
            compare_warps(read_warp(truth_file.string()), fit.warp, options.truth_border_px);
      }
    }
    fit.warp.eye = glm::dvec3(0.0);
    warps.push_back(std::move(fit.warp));
    node_origins.push_back(std::move(fit.node_origin));
    report.projectors.push_back(std::move(item));
    report_step("fitting warps", p + 1, projectors);
  }
  decoded.clear();

  throw_if_interrupted(stopped);
  report_step("blending", 0, 1);
  const BlendResult blend = compute_blend(warps, options.blend);
  report_step("blending", 1, 1);
  for (std::size_t p = 0; p < warps.size(); ++p) {
    std::size_t mapped = 0;
    for (const float a : blend.alpha[p].values) mapped += a > 0 ? 1 : 0;
    ProjectorReport& item = report.projectors[p];
    item.coverage = double(mapped) / double(blend.alpha[p].values.size());
    item.unlit_inside = unlit_inside(blend.alpha[p].values, blend.alpha[p].size);
    item.verdict = judge(item);
  }
  const BlendCheck check = check_blend(warps, blend.alpha);
  report.blend_sum_max_err = check.sum_max_err;
  report.blend_overlap_directions = check.overlap_directions;
  report.blend_single_directions = check.single_directions;
  report.blend_single_dim_directions = check.single_dim_directions;
  report.blend_single_min = check.single_min_sum;
  if (check.sum_max_err > 0) {
    report.blend_worst = capture.projectors[check.worst_projector].name + " at (" +
                         std::to_string(check.worst_q.x) + ", " + std::to_string(check.worst_q.y) +
                         ")";
  }

  projection_io::DisplayConfig display = written_display(capture, base_display, options);
  for (projection_io::DisplayProjector& item : display.projectors) {
    item.warp = item.name + ".warp.exr";
    item.blend = item.name + ".blend.exr";
    item.black.reset();
    if (!blend.black.empty()) item.black = item.name + ".black.exr";
  }

  write_folder_atomically(
      out,
      [&](const fs::path& temporary) {
        for (std::size_t p = 0; p < warps.size(); ++p) {
          const std::string& name = capture.projectors[p].name;
          write_warp((temporary / (name + ".warp.exr")).string(), warps[p]);
          projection_io::write_blend_map((temporary / (name + ".blend.exr")).string(),
                                         blend.alpha[p]);
          if (!blend.black.empty()) {
            projection_io::write_blend_map((temporary / (name + ".black.exr")).string(),
                                           blend.black[p]);
          }
        }
        projection_io::write_display_config(display, temporary / "display.json");
        const fs::path pictures = temporary / "report";
        fs::create_directories(pictures);
        for (std::size_t p = 0; p < warps.size(); ++p) {
          throw_if_interrupted(stopped);
          const std::string& name = capture.projectors[p].name;
          write_rgb_image(pictures / (name + ".residual.png"),
                          residual_image(report.projectors[p].fit, warps[p].output_size));
          write_rgb_image(pictures / (name + ".coverage.png"),
                          coverage_image(warps[p], node_origins[p], blend.alpha[p]));
        }
        throw_if_interrupted(stopped);
        const EyeViews views = eye_views(warps, blend.alpha, report);
        write_rgb_image(pictures / "composite.png", views.composite);
        write_rgb_image(pictures / "preview.png", views.residual);
        throw_if_interrupted(stopped);
      },
      out_rules);
  report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

}  // namespace facet::calibration
