// facet preview: what the audience sees from the eye, every projector composited on a fisheye or
// equirectangular image, with the coverage and blend figures.
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/driver/output_images.hpp"
#include "facet/driver/session.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/display_preview.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/display_config.hpp"
#include "option_flags.hpp"

namespace facet::cli {
namespace {

struct PreviewCommandOptions {
  std::string display = "builtin:dome180";
  std::string size;
  DomeOrientationFlags orientation;  // the dome's: builtin:dome180 and the fisheye view
  std::string view;                  // fit | fisheye | equirect; empty: fit, or fisheye with --tilt
  std::optional<double> fov_deg;     // the fisheye's; 180 when not given
  std::string show = "projectors";
  int preview_size = 1024;
  std::string out;
  bool json = false;
};

double percent(double part, double whole) { return whole > 0 ? 100 * part / whole : 0; }

void preview(const PreviewCommandOptions& options) {
  if (options.out.empty()) throw InputError("command line", "--out", "a PNG file to write");
  check_output_file(options.out, "--out");  // before the preview is drawn
  const PreviewShow show = preview_show_from_string(options.show, "command line", "--show");
  if (show == PreviewShow::residual)
    throw InputError("command line", "--show",
                     "projectors, overlap, blend or uncovered: a display has no fit residual "
                     "(facet calibrate draws it in report/preview.png)");
  std::string view_name = options.view;
  if (view_name.empty())
    view_name = options.orientation.given() || options.fov_deg ? "fisheye" : "fit";
  if (options.fov_deg && !(*options.fov_deg > 0 && *options.fov_deg <= 360))
    throw InputError(
        "command line", "--fov",
        "a fisheye field of view in (0, 360] degrees, got " + std::to_string(*options.fov_deg));
  if (view_name != "fit" && view_name != "fisheye" && view_name != "equirect")
    throw InputError("command line", "--view", "fit, fisheye or equirect, got '" + view_name + "'");
  std::optional<glm::ivec2> size;
  if (!options.size.empty()) size = parse_size(options.size, "--size");
  // --tilt and --orientation say how the dome sits: a built-in dome is built so, and the fisheye
  // view follows the dome's zenith and front for any display.
  const DomeOrientation view_orientation =
      options.orientation.given() ? options.orientation.value() : DomeOrientation{};
  const bool builtin = options.display.rfind("builtin:", 0) == 0;
  const auto orientation =
      builtin ? builtin_dome_orientation(options.orientation, options.display) : std::nullopt;
  driver::SessionDisplay display = driver::load_session_display(options.display, size);
  for (auto& output : display.outputs)
    if (orientation) orient_warp(output.spec.warp, *orientation);

  std::vector<PreviewProjector> projectors;
  for (const driver::SessionOutput& output : display.outputs) {
    PreviewProjector projector;
    projector.name = output.spec.name;
    projector.warp = &output.spec.warp;
    if (!output.blend.alpha.empty()) {
      projector.alpha_size = output.blend.size;
      projector.alpha_channels = output.blend.channels;
      projector.alpha = output.blend.alpha;
    }
    projectors.push_back(projector);
  }
  PreviewOptions preview_options;
  if (view_name == "fit") {
    preview_options.view = fitted_preview_view(projectors);
    view_name = preview_options.view.format == ContentFormat::fisheye ? "fisheye" : "equirect";
  } else if (view_name == "fisheye") {
    preview_options.view = fisheye_content(options.fov_deg.value_or(180), view_orientation);
  } else {
    preview_options.view = equirect_content();
  }
  preview_options.height_px = options.preview_size;

  const DisplayPreview result = preview_display(projectors, preview_options, "command line");
  driver::write_png_rgba8(options.out, result.size,
                          render_preview(result, show, preview_options.view));

  const DisplayPreview::Figures& f = result.figures;
  if (options.json) {
    nlohmann::json json;
    json["display"] = options.display;
    json["view"] = view_name;
    if (view_name == "fisheye") json["fov_deg"] = preview_options.view.fov_deg;
    json["view_sr"] = f.view_sr;
    json["covered_sr"] = f.covered_sr;
    json["overlap_sr"] = f.overlap_sr;
    json["uncovered_sr"] = f.uncovered_sr;
    json["blend_sum_worst_error"] = f.blend_worst;
    json["blend_sum_p99_error"] = f.blend_p99;
    json["blend_sum_off_sr"] = f.blend_off_sr;
    for (std::size_t p = 0; p < result.names.size(); ++p)
      json["projectors"].push_back({{"name", result.names[p]}, {"covered_sr", f.projector_sr[p]}});
    json["image"] = options.out;
    std::cout << json.dump(2) << "\n";
    return;
  }
  std::cout << "facet preview: " << display.outputs.size() << " projector(s) of " << options.display
            << ", " << view_name
            << (view_name == "fisheye"
                    ? " " + std::to_string(int(std::lround(preview_options.view.fov_deg))) + "°"
                    : std::string(" 360°×180°"))
            << " view (" << f.view_sr << " sr)\n";
  std::cout << "  covered " << percent(f.covered_sr, f.view_sr) << "% of the view, by two or more "
            << percent(f.overlap_sr, f.view_sr) << "%, uncovered "
            << percent(f.uncovered_sr, f.view_sr) << "% (" << f.uncovered_sr << " sr)\n";
  std::cout << "  blend sum over covered directions: |sum - 1| worst " << f.blend_worst << ", p99 "
            << f.blend_p99 << "; above 0.005 on " << percent(f.blend_off_sr, f.covered_sr)
            << "% of the covered directions\n";
  for (std::size_t p = 0; p < result.names.size(); ++p)
    std::cout << "  " << result.names[p] << " covers " << percent(f.projector_sr[p], f.view_sr)
              << "% of the view\n";
  std::cout << "facet preview: wrote " << options.out << " (" << to_string(show) << ", "
            << result.size.x << "x" << result.size.y << ")\n";
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"preview",
                               {{"display", "--display"},
                                {"size", "--size"},
                                {"view", "--view"},
                                {"fov_deg", "--fov"},
                                {"height_px", "--preview-size"},
                                {"out", "--out"}}};

const Registration registration{
    45, [](CLI::App& app) {
      auto options = std::make_shared<PreviewCommandOptions>();
      auto* command = app.add_subcommand(
          "preview",
          "What the audience sees from the eye: every projector of a display composited, blended, "
          "on a fisheye (domes) or equirectangular image, coloured by projector, overlap count, "
          "blend sum or uncovered directions, with the coverage figures");
      command->add_option("display,--display", options->display,
                          "builtin:dome180 (default), builtin:cylinder360, builtin:wall2x2, a "
                          ".warp.exr or a display.json");
      command->add_option("--size", options->size, "Output size WxH of a built-in display");
      options->orientation.add_to(*command);
      command->add_option("--view", options->view,
                          "fit (default; fisheye with --tilt, --orientation or --fov), fisheye or "
                          "equirect: fit is a fisheye about the mean covered direction wide "
                          "enough for every covered one, or equirect beyond 270 degrees");
      command->add_option(
          "--fov", options->fov_deg,
          "Fisheye view: the full field of view in degrees, (0, 360] (default 180)");
      command->add_option("--show", options->show,
                          "projectors (default), overlap, blend or uncovered");
      command->add_option("--preview-size", options->preview_size,
                          "Preview height in pixels, 8 to 8192 (default 1024; equirect is twice "
                          "as wide)");
      command->add_option("--out", options->out, "The PNG to write")->required();
      command->add_flag("--json", options->json, "Print the figures as JSON");
      command->callback([options] { preview(*options); });
    }};

}  // namespace
}  // namespace facet::cli
