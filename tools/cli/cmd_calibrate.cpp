// facet calibrate: a recorded capture → display.json, <p>.warp.exr, <p>.blend.exr and report/,
// with a verdict per projector.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "command.hpp"
#include "facet/calibration/calibrate.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "facet/projection/progress.hpp"
#include "facet/projection_io/display_config.hpp"
#include "option_flags.hpp"

namespace {

struct CalibrateArgs {
  std::string capture;
  std::string out;
  bool json = false;
  std::string grid;
  std::optional<double> node_spacing_px;
  std::optional<double> black_level;
  double feather_deg = 20;
  std::string name;
  std::string display;
};

glm::ivec2 parse_grid(const std::string& text) {
  int width = 0, height = 0;
  char separator = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &separator, &height, &extra) != 3 ||
      (separator != 'x' && separator != 'X') || width < 2 || height < 2 || width > 4096 ||
      height > 4096) {
    throw facet::InputError("--grid", "",
                            "GWxGH nodes, each in 2..4096, e.g. 65x49, got '" + text + "'");
  }
  return {width, height};
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const facet::cli::OptionFlags option_flags{"calibrate", {{"out", "--out"}}};

const facet::cli::Registration registration{
    40, [](CLI::App& app) {
      auto args = std::make_shared<CalibrateArgs>();
      auto* cmd = app.add_subcommand(
          "calibrate",
          "Fit every projector's warp and blend from a recorded capture (capture.json and its "
          "images) and write display.json, <p>.warp.exr and <p>.blend.exr, and report/ with "
          "<p>.residual.png, <p>.coverage.png, and composite.png and preview.png (the display "
          "from the eye, as facet preview draws it, by projector and by residual); ends with a "
          "verdict per projector");
      cmd->add_option("capture", args->capture, "capture folder, or its capture.json")->required();
      cmd->add_option("--out", args->out, "output folder (must not exist, or be empty)")
          ->required();
      cmd->add_flag("--json", args->json,
                    "print the report as JSON: per projector coverage, decoded pixels, grid, "
                    "fit residual (rms, p50, p99), filled and holes (nodes extrapolated and kept, "
                    "or left uncovered), holes_filled (enclosed, interpolated), folds_refilled "
                    "and folds (cut), unlit_inside, worst_region_px and its rms, verdict and "
                    "reasons, and with truth/ rms_px, p99_px, max_px, max_at_px and "
                    "uncovered_fraction; blend_sum_max_err and where (blend_worst); the overall "
                    "verdict; seconds. Without --json: a table per projector (coverage, holes "
                    "filled, folds cut, residual p50/p99, worst 32x32 region, verdict) and the "
                    "reasons");
      cmd->add_option("--grid", args->grid,
                      "offset-map nodes GWxGH for every projector (default: one node about "
                      "every 16 output pixels, refined once where the map curves)");
      cmd->add_option("--node-spacing", args->node_spacing_px,
                      "node spacing in output pixels when --grid is not given");
      cmd->add_option("--black-level", args->black_level,
                      "also write <p>.black.exr for projectors whose black emits this fraction "
                      "of their white");
      cmd->add_option("--feather", args->feather_deg,
                      "blend feather: degrees from a projector's edge to its full weight");
      cmd->add_option("--display", args->display,
                      "display.json (or its folder) to write back with its warps and blends filled "
                      "in, keeping its name, outputs, gammas and render settings (default: the "
                      "display the capture ran with, if it kept one)");
      cmd->add_option("--name", args->name,
                      "display name (default: the display's, else the capture folder's name)");
      cmd->callback([args, cmd] {
        facet::calibration::CalibrateOptions options;
        if (!args->grid.empty()) options.fit.grid = parse_grid(args->grid);
        if (args->node_spacing_px) {
          if (!(*args->node_spacing_px >= 2 && *args->node_spacing_px <= 1024)) {
            throw facet::InputError("--node-spacing", "", "a number of output pixels in 2..1024");
          }
          options.fit.node_spacing_px = *args->node_spacing_px;
        }
        if (args->black_level) {
          if (!(*args->black_level >= 0 && *args->black_level < 1)) {
            throw facet::InputError("--black-level", "", "a fraction of white in [0, 1)");
          }
          options.blend.black_level = args->black_level;
        }
        if (!(args->feather_deg > 0 && args->feather_deg <= 180)) {
          throw facet::InputError("--feather", "", "an angle in degrees in (0, 180]");
        }
        options.blend.feather_rad = args->feather_deg * M_PI / 180;
        if (cmd->count("--name") > 0) facet::cli::check_name(args->name, "--name");
        options.display_name = args->name;
        if (!args->display.empty())
          options.display = facet::projection_io::read_display_template(args->display);
        // From here on SIGINT and SIGTERM stop the calibration cleanly (exit 128 + signal).
        facet::watch_interrupts();
        facet::TerminalProgress progress(stderr, "facet calibrate");
        options.progress = progress.sink();
        const auto report = facet::calibration::calibrate(args->capture, args->out, options);
        progress.finish();
        if (args->json) {
          std::cout << report.to_json().dump(2) << "\n";
          return;
        }
        // One row per projector, then the reasons for any verdict other than good.
        std::printf("%-12s %8s %7s %7s %7s %7s %19s %9s  %s\n", "projector", "coverage", "holes",
                    "folds", "p50 px", "p99 px", "worst region", "rms px", "verdict");
        for (const auto& p : report.projectors) {
          char worst[32];
          std::snprintf(worst, sizeof worst, "(%.0f, %.0f)", p.fit.worst_region_px.x,
                        p.fit.worst_region_px.y);
          std::printf("%-12s %7.1f%% %7zu %7zu %7.3f %7.3f %19s %9.3f  %s\n", p.name.c_str(),
                      100 * p.coverage, p.fit.holes_filled, p.fit.folds, p.fit.residual_p50_px,
                      p.fit.residual_p99_px, worst, p.fit.worst_region_rms_px,
                      facet::calibration::to_string(p.verdict.verdict));
        }
        for (const auto& p : report.projectors) {
          for (const std::string& reason : p.verdict.reasons) {
            std::printf("  %s: %s\n", p.name.c_str(), reason.c_str());
          }
          if (p.accuracy) {
            std::printf("  %s against truth: rms %.3f px, p99 %.3f px, max %.3f px\n",
                        p.name.c_str(), p.accuracy->rms_px, p.accuracy->p99_px, p.accuracy->max_px);
          }
        }
        std::printf("verdict: %s (thresholds: calibration/README.md)\n",
                    facet::calibration::to_string(report.verdict()));
        std::printf("blend sum max error %.5f; %.1f s\n", report.blend_sum_max_err, report.seconds);
      });
    }};

}  // namespace
