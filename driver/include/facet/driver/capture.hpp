#pragma once
// Live structured-light capture as one call (`facet capture`): reads the display, checks the
// options, makes the camera (a V4L2/UVC camera, or the fake camera that sees a virtual rig), shows
// the patterns on the projectors (windows on their monitors, or headless framebuffers for a fake
// camera) and runs calibration::run_live_capture, which writes or resumes the capture folder.
//
// Target facet::capture (driver/src/capture/): above facet::driver (the pattern presenter) and
// facet::calibration (the capture itself), built when both are.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <glm/vec2.hpp>
#include <optional>
#include <string>

#include "facet/calibration/live_capture.hpp"
#include "facet/driver/log.hpp"

namespace facet::driver {

// Where the patterns appear.
enum class CapturePresenter {
  automatic,  // headless for a fake camera, windows for a real one
  headless,   // one framebuffer per projector on an EGL context (a fake camera only)
  windowed,   // a window per projector, placed as `facet run` places it
};

// Every field is an option of run_capture; an InputError names a refused one by its field name.
struct CaptureOptions {
  // display.json (or its folder) naming the projectors, their sizes, gammas and outputs; warps
  // may be absent (projection_io::read_display_template).
  std::string display;
  // A V4L2 camera: /dev/videoN, a device index, a USB id usb:VVVV:PPPP[:SERIAL|@BUS-PATH]; or
  // fake:RIG, the camera of a virtual rig (a rig file or builtin:NAME).
  std::string camera;
  std::filesystem::path out;  // the capture folder: new, empty, or an interrupted capture's
  // A real camera's mrcal .cameramodel (required), its pose file (R_eye_camera, t_eye_camera;
  // empty: at the eye, looking down -z) and the frame size (W, H) to ask it for. A fake camera
  // takes all three from its rig.
  std::filesystem::path camera_model, camera_pose;
  std::optional<glm::ivec2> camera_size;
  double camera_gamma = 1;  // a grabbed value e is light e^camera_gamma, in (0, 10]
  // Every projector's response, in (0, 10]; unset: display.json's gamma, 2.2 for "srgb".
  std::optional<double> projector_gamma;
  int average = 1;          // exposures averaged per pattern, 1 to 1000
  int settle_ms = 100;      // wait after each pattern is on screen, 0 to 60000 ms
  int discard = 2;          // real camera: frames dropped before each grab, 0 to 1000
  std::optional<int> bits;  // PNG bits per sample, 8 or 16; unset: 16, a fake camera's rig's
  // Phase-shift period in projector pixels, in [2, 65536], and steps per axis, 3 to 64; unset:
  // 16 and 4, a fake camera's rig's. phase = false: Gray code only.
  std::optional<double> phase_period;
  std::optional<int> phase_steps;
  bool phase = true;
  double max_clipped_fraction = 0.001;  // as calibration::LiveCaptureOptions
  bool allow_clipping = false;
  // Stop (leaving the capture resumable) after this many frames captured in this run.
  std::optional<std::size_t> stop_after;
  CapturePresenter presenter = CapturePresenter::automatic;
  // Polled between frames; true stops the capture as stop_after does. A closed pattern window
  // stops it too.
  std::function<bool()> interrupted;
};

// Runs or resumes the capture of `options` (calibration/live_capture.hpp gives the folder and
// the journal); `log` (may be empty) gets a line per event as info: frames captured, frames kept
// from an earlier run, clipping. Every option is checked before the camera and the projectors
// start. Throws InputError, naming the option (OptionName), for a bad option or combination (a
// headless presenter or camera_size with a real camera, a camera_model or camera_pose with a
// fake one, a real camera without camera_model), and whatever the display, the rig, the camera,
// the presenter and run_live_capture throw. An incomplete report (complete false) is a stopped
// capture that the same call resumes.
calibration::LiveCaptureReport run_capture(const CaptureOptions& options, const LogSink& log);

}  // namespace facet::driver
