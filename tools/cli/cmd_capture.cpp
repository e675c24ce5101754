// facet capture: live structured-light capture. Shows every pattern on every projector output,
// grabs camera frames (a V4L2/UVC camera, or the fake camera that sees the virtual rig) and writes
// the recorded capture folder frame by frame, resuming an interrupted capture.
#if __has_include("facet/calibration/live_capture.hpp")
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/calibration/fake_camera.hpp"
#include "facet/calibration/live_capture.hpp"
#include "facet/calibration/video_camera.hpp"
#include "facet/driver/pattern_presenter.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "option_flags.hpp"

namespace facet::cli {
namespace {

namespace fs = std::filesystem;
using calibration::CaptureProjector;

struct CaptureArgs {
  std::string display, camera, out;
  std::string camera_model, camera_pose, camera_size;
  double camera_gamma = 1;
  std::optional<double> projector_gamma;
  int average = 1;
  int settle_ms = 100;
  std::optional<int> bits;
  int discard = 2;
  std::optional<double> phase_period;
  std::optional<int> phase_steps;
  bool no_phase = false;
  double max_clipped = 0.001;
  bool allow_clipping = false;
  std::optional<std::size_t> stop_after;
  bool windowed = false, headless = false, json = false, quiet = false;
};

// The calibration side's view of the presenter: pattern values in [0,1] go out as 8-bit levels.
class PresenterOutputs : public calibration::PatternOutputs {
 public:
  explicit PresenterOutputs(driver::PatternPresenter& presenter) : presenter_(presenter) {}
  void show(std::size_t projector, const cv::Mat& values) override {
    cv::Mat levels;
    values.convertTo(levels, CV_8U, 255.0);  // rounds to the nearest level
    FACET_ASSERT(levels.isContinuous());
    presenter_.show(projector, {levels.data, levels.total()});
  }
  void blank() override { presenter_.blank(); }

 private:
  driver::PatternPresenter& presenter_;
};

int run_capture(const CaptureArgs& args) {
  const projection_io::DisplayConfig display = projection_io::read_display_template(args.display);
  const bool fake = args.camera.starts_with("fake:");
  if (args.windowed && args.headless) {
    throw InputError("--headless", "", "either --headless or --windowed, not both");
  }
  if (args.headless && !fake) {
    throw InputError("--headless", "",
                     "a fake camera (fake:RIG.json): a real camera must see the patterns on the "
                     "projectors");
  }
  if (!args.camera_size.empty()) {
    parse_size(args.camera_size, "--camera-size");
    if (fake) {
      throw InputError("--camera-size", "",
                       "a real camera: a fake camera's size comes from its rig (camera.size)");
    }
  }
  if (args.projector_gamma && !(*args.projector_gamma > 0 && *args.projector_gamma <= kMaxGamma)) {
    throw InputError("--projector-gamma", "", "a gamma in (0, 10]");
  }
  if (!(args.camera_gamma > 0 && args.camera_gamma <= kMaxGamma)) {
    throw InputError("--camera-gamma", "", "a gamma in (0, 10]");
  }
  // Checked up front whatever the camera (a fake one ignores some): a minute's settling, a
  // thousand dropped or averaged frames per pattern are more than any camera needs.
  if (args.settle_ms < 0 || args.settle_ms > 60'000) {
    throw InputError("--settle-ms", "", "milliseconds from 0 to 60000");
  }
  if (args.discard < 0 || args.discard > 1000) {
    throw InputError("--discard", "", "a number of frames from 0 to 1000");
  }
  if (args.average < 1 || args.average > 1000) {
    throw InputError("--average", "", "a number of exposures from 1 to 1000");
  }

  std::optional<Rig> rig;
  if (fake) {
    // The rig's errors name the flag that gave it: its name alone may be the mistake.
    const std::string rig_name = args.camera.substr(5);
    if (rig_name.empty()) {
      throw InputError("--camera", "", "fake:RIG, RIG a rig file or builtin:NAME; got 'fake:'");
    }
    try {
      rig = load_rig(rig_name);
    } catch (const InputError& error) {
      throw InputError("--camera " + error.source(), error.field(), error.expected());
    }
    if (!args.camera_model.empty() || !args.camera_pose.empty()) {
      throw InputError("--camera-model", "",
                       "no --camera-model or --camera-pose with a fake camera: the rig gives both");
    }
  } else if (args.camera_model.empty()) {
    throw InputError("--camera-model", "",
                     "the camera's mrcal .cameramodel (a real camera needs its lens model)");
  }

  calibration::PatternSetOptions patterns;
  patterns.phase_period = 16;
  if (rig) {
    patterns.phase_period =
        rig->simulation.phase ? std::optional<double>(rig->simulation.phase_period) : std::nullopt;
    patterns.phase_steps = rig->simulation.phase_steps;
  }
  if (args.phase_period) patterns.phase_period = *args.phase_period;
  if (args.phase_steps) patterns.phase_steps = *args.phase_steps;
  if (args.no_phase) patterns.phase_period.reset();
  if (patterns.phase_period &&
      !(*patterns.phase_period >= kMinPhasePeriod && *patterns.phase_period <= kMaxPhasePeriod)) {
    throw InputError("--phase-period", "", "a period from 2 to 65536 projector pixels");
  }
  if (patterns.phase_steps < 3 || patterns.phase_steps > 64) {
    throw InputError("--phase-steps", "", "3 to 64 steps");
  }

  // Checked before the camera and the projectors start.
  calibration::LiveCaptureOptions options;
  options.out = args.out;
  options.average = args.average;
  options.bits = args.bits ? *args.bits : rig ? rig->simulation.bits : 16;
  options.camera_gamma = args.camera_gamma;
  options.max_clipped_fraction = args.max_clipped;
  options.allow_clipping = args.allow_clipping;
  options.stop_after = args.stop_after;
  calibration::check_live_capture_options(options);

  calibration::LiveCaptureSetup setup;
  for (const projection_io::DisplayProjector& p : display.projectors) {
    CaptureProjector projector;
    projector.name = p.name;
    projector.size = p.size;
    // display.json's gamma is the output encoding, value = linear^(1/gamma): the same response.
    projector.gamma = args.projector_gamma ? *args.projector_gamma : p.gamma.value_or(2.2);
    projector.frames = calibration::standard_frames(p.name, p.size, patterns);
    setup.projectors.push_back(std::move(projector));
  }
  setup.identity = {{"display", display.name}};
  setup.display = display;

  std::vector<glm::ivec2> sizes;
  for (const auto& p : display.projectors) sizes.push_back(p.size);
  const auto settle = std::chrono::milliseconds(args.settle_ms);
  std::unique_ptr<driver::PatternPresenter> presenter;
  std::unique_ptr<calibration::LiveCamera> camera;
  calibration::FakeCamera* fake_camera = nullptr;
  if (fake) {
    auto shown = [&presenter](std::size_t projector) {
      const std::vector<std::uint8_t>& bytes = presenter->shown(projector);
      const glm::ivec2 size = presenter->output_size(projector);
      cv::Mat values;
      cv::Mat(size.y, size.x, CV_8U, const_cast<std::uint8_t*>(bytes.data()))
          .convertTo(values, CV_32F, 1.0 / 255.0);
      return values;
    };
    auto owned = std::make_unique<calibration::FakeCamera>(*rig, setup.projectors, shown,
                                                           args.camera.substr(5));
    fake_camera = owned.get();
    setup.model = fake_camera->model();
    setup.camera.R_eye_camera = rig->camera.R_eye_camera;
    setup.camera.t_eye_camera = rig->camera.t_eye_camera;
    setup.screen = rig->screen;
    setup.finish = [fake_camera](const fs::path& folder) -> std::optional<fs::path> {
      return fake_camera->write_truth(folder);
    };
    camera = std::move(owned);
  } else {
    setup.model = calibration::CameraModel::read(args.camera_model);
    if (!args.camera_pose.empty()) calibration::read_camera_pose(args.camera_pose, setup.camera);
    setup.screen = display.screen;
    calibration::VideoCameraOptions video;
    if (!args.camera_size.empty()) video.size = parse_size(args.camera_size, "--camera-size");
    video.discard = args.discard;
    const std::string device =
        calibration::find_video_node(args.camera, calibration::list_video_devices());
    camera = calibration::open_video_camera(device, args.camera, video);
  }
  presenter = fake && !args.windowed
                  ? driver::create_headless_presenter(sizes, settle)
                  : driver::create_windowed_presenter(display, args.display, settle);
  PresenterOutputs outputs(*presenter);

  driver::PatternPresenter* watched = presenter.get();
  // SIGINT and SIGTERM stop the capture after the frame in hand, leaving it resumable (exit 3).
  options.interrupted = [watched] { return interrupt_signal() != 0 || watched->closed(); };
  if (!args.quiet && !args.json) {
    options.log = [](const std::string& line) {
      std::printf("%s\n", line.c_str());
      std::fflush(stdout);
    };
  }
  watch_interrupts();
  const calibration::LiveCaptureReport report =
      calibration::run_live_capture(outputs, *camera, setup, options);

  if (args.json) {
    nlohmann::json exposures = nlohmann::json::array();
    for (const auto& e : report.exposures) {
      exposures.push_back({{"projector", e.projector},
                           {"clipped_fraction", e.clipped_fraction},
                           {"white_max", e.white_max}});
    }
    std::cout << nlohmann::json{{"out", args.out},
                                {"frames", report.frames},
                                {"kept", report.kept},
                                {"captured", report.captured},
                                {"complete", report.complete},
                                {"exposures", exposures},
                                {"seconds", report.seconds}}
                     .dump(2)
              << "\n";
  } else if (report.complete) {
    std::printf(
        "%s: capture complete, %zu frames (%zu kept from an earlier run, %zu captured) in "
        "%.1f s\n",
        args.out.c_str(), report.frames, report.kept, report.captured, report.seconds);
  } else {
    const std::string why =
        interrupt_signal() ? "interrupted by " + signal_name(interrupt_signal()) + ": " : "";
    std::printf("%s: %sstopped after %zu of %zu frames; run the same command again to resume\n",
                args.out.c_str(), why.c_str(), report.kept + report.captured, report.frames);
  }
  std::fflush(stdout);
  return report.complete ? 0 : 3;
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"capture",
                               {{"device", "--camera"},
                                {"size", "--camera-size"},
                                {"discard", "--discard"},
                                {"average", "--average"},
                                {"bits", "--bits"},
                                {"camera_gamma", "--camera-gamma"},
                                {"max_clipped_fraction", "--max-clipped"},
                                {"out", "--out"}}};

const Registration registration{
    28, [](CLI::App& app) {
      auto args = std::make_shared<CaptureArgs>();
      auto* cmd = app.add_subcommand(
          "capture",
          "Live structured-light capture: show every pattern on every projector, grab camera "
          "frames, and write the capture folder (resumes an interrupted capture; exit 3 when "
          "stopped before the end)");
      cmd->add_option("display,--display", args->display,
                      "display.json (or its folder) naming the projectors, their sizes and "
                      "outputs; warps may be absent")
          ->required();
      cmd->add_option(
             "--camera", args->camera,
             "/dev/videoN, a device index, a USB stable id usb:VVVV:PPPP[:SERIAL|@BUS-PATH] "
             "(facet devices), or fake:RIG (the camera of a virtual rig: a rig file or "
             "builtin:NAME)")
          ->required();
      cmd->add_option("--out", args->out,
                      "capture folder: new, empty, or an interrupted capture to resume")
          ->required();
      cmd->add_option("--camera-model", args->camera_model,
                      "mrcal .cameramodel of a real camera (the fake camera's comes from the rig)");
      cmd->add_option("--camera-pose", args->camera_pose,
                      "JSON with R_eye_camera (list of rows) and t_eye_camera (metres) of a real "
                      "camera; default: at the eye, looking down -z");
      cmd->add_option("--camera-size", args->camera_size, "ask a real camera for WxH frames");
      cmd->add_option("--camera-gamma", args->camera_gamma,
                      "camera response: a grabbed value e is light e^gamma (frames are written "
                      "linear)");
      cmd->add_option("--projector-gamma", args->projector_gamma,
                      "projector response for every projector (default: display.json's gamma, "
                      "2.2 for \"srgb\")");
      cmd->add_option("--average", args->average, "exposures averaged per pattern (default 1)");
      cmd->add_option("--settle-ms", args->settle_ms,
                      "wait after each pattern is on screen, milliseconds (default 100)");
      cmd->add_option("--discard", args->discard,
                      "real camera: frames dropped before each grab (default 2)");
      cmd->add_option(
          "--bits", args->bits,
          "PNG bits per sample of the frames, 8 or 16 (16; the rig's for a fake camera)");
      cmd->add_option("--phase-period", args->phase_period,
                      "phase-shift period in projector pixels (default 16; the rig's for a fake "
                      "camera)");
      cmd->add_option("--phase-steps", args->phase_steps, "phase shifts per axis (default 4)");
      cmd->add_flag("--no-phase", args->no_phase, "Gray code only");
      cmd->add_option("--max-clipped", args->max_clipped,
                      "largest share of camera pixels at full scale on a white frame (0.001)");
      cmd->add_flag("--allow-clipping", args->allow_clipping,
                    "report clipping on white frames but go on");
      cmd->add_option("--stop-after", args->stop_after,
                      "stop after capturing this many frames (a deterministic interruption)")
          ->check(unsigned_only());
      cmd->add_flag("--windowed", args->windowed,
                    "fake camera: show the patterns in windows as for a real camera");
      cmd->add_flag("--headless", args->headless,
                    "fake camera: offscreen outputs through EGL (the default for a fake camera)");
      cmd->add_flag("--json", args->json, "print the report as JSON");
      cmd->add_flag("--quiet", args->quiet, "no progress lines");
      cmd->callback([args] {
        const int status = run_capture(*args);
        // Everything is released by now; an incomplete capture is its own exit status.
        if (status != 0) std::exit(status);
      });
    }};

}  // namespace
}  // namespace facet::cli
#endif
