// facet capture: live structured-light capture. Shows every pattern on every projector output,
// grabs camera frames (a V4L2/UVC camera, or the fake camera that sees the virtual rig) and writes
// the recorded capture folder frame by frame, resuming an interrupted capture.
#if __has_include("facet/calibration/live_capture.hpp")
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "command.hpp"
#include "console_log.hpp"
#include "display_flags.hpp"
#include "facet/driver/capture.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "option_flags.hpp"

namespace facet::cli {
namespace {

// The flags: most set the library's options directly; the rest are parsed or combined here.
struct CaptureArgs {
  driver::CaptureOptions options;
  std::string out, camera_model, camera_pose, camera_size;
  bool no_phase = false, windowed = false, headless = false, json = false, quiet = false;
};

// The library's options from the flags; the flags' own syntax is checked here.
driver::CaptureOptions capture_options(const CaptureArgs& args) {
  if (args.windowed && args.headless) {
    throw InputError("--headless", "", "either --headless or --windowed, not both");
  }
  driver::CaptureOptions options = args.options;
  options.out = args.out;
  options.camera_model = args.camera_model;
  options.camera_pose = args.camera_pose;
  if (!args.camera_size.empty())
    options.camera_size = parse_size(args.camera_size, "--camera-size");
  options.phase = !args.no_phase;
  options.presenter = args.windowed   ? driver::CapturePresenter::windowed
                      : args.headless ? driver::CapturePresenter::headless
                                      : driver::CapturePresenter::automatic;
  // SIGINT and SIGTERM stop the capture after the frame in hand, leaving it resumable (exit 3).
  options.interrupted = [] { return interrupt_signal() != 0; };
  return options;
}

int run_capture(const CaptureArgs& args) {
  const driver::CaptureOptions options = capture_options(args);
  watch_interrupts();
  const calibration::LiveCaptureReport report =
      driver::run_capture(options, args.quiet || args.json ? driver::LogSink() : console_log(""));

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
                                {"out", "--out"},
                                {"camera", "--camera"},
                                {"camera_model", "--camera-model"},
                                {"camera_pose", "--camera-pose"},
                                {"camera_size", "--camera-size"},
                                {"projector_gamma", "--projector-gamma"},
                                {"settle_ms", "--settle-ms"},
                                {"phase_period", "--phase-period"},
                                {"phase_steps", "--phase-steps"},
                                {"presenter", "--headless"}}};

const Registration registration{
    28, [](CLI::App& app) {
      auto args = std::make_shared<CaptureArgs>();
      auto* cmd = app.add_subcommand(
          "capture",
          "Live structured-light capture: show every pattern on every projector, grab camera "
          "frames, and write the capture folder (resumes an interrupted capture; exit 3 when "
          "stopped before the end)");
      cmd->add_option("display,--display", args->options.display,
                      "display.json (or its folder) naming the projectors, their sizes and "
                      "outputs; warps may be absent")
          ->required();
      cmd->add_option(
             "--camera", args->options.camera,
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
      cmd->add_option("--camera-gamma", args->options.camera_gamma,
                      "camera response: a grabbed value e is light e^gamma (frames are written "
                      "linear)");
      cmd->add_option("--projector-gamma", args->options.projector_gamma,
                      "projector response for every projector (default: display.json's gamma, "
                      "2.2 for \"srgb\")");
      cmd->add_option("--average", args->options.average,
                      "exposures averaged per pattern (default 1)");
      cmd->add_option("--settle-ms", args->options.settle_ms,
                      "wait after each pattern is on screen, milliseconds (default 100)");
      cmd->add_option("--discard", args->options.discard,
                      "real camera: frames dropped before each grab (default 2)");
      cmd->add_option(
          "--bits", args->options.bits,
          "PNG bits per sample of the frames, 8 or 16 (16; the rig's for a fake camera)");
      cmd->add_option("--phase-period", args->options.phase_period,
                      "phase-shift period in projector pixels (default 16; the rig's for a fake "
                      "camera)");
      cmd->add_option("--phase-steps", args->options.phase_steps,
                      "phase shifts per axis (default 4)");
      cmd->add_flag("--no-phase", args->no_phase, "Gray code only");
      cmd->add_option("--max-clipped", args->options.max_clipped_fraction,
                      "largest share of camera pixels at full scale on a white frame (0.001)");
      cmd->add_flag("--allow-clipping", args->options.allow_clipping,
                    "report clipping on white frames but go on");
      cmd->add_option("--stop-after", args->options.stop_after,
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
