#pragma once
// Live structured-light capture (`facet capture`): shows every pattern of every projector, grabs
// camera frames, and writes the recorded capture folder of FORMATS.md §1, frame by frame, so that
// an interrupted capture resumes where it stopped.
//
// The folder while a capture runs:
//   capture.journal      what the capture is and which frames are done (JSON lines, below)
//   camera.cameramodel   the camera's lens model (written first)
//   <projector>/<file>   one image per frame, each written atomically (temporary name, rename)
//   capture.json         written last, atomically: its presence means the capture is complete
//                        (a later run that finds a frame missing removes it until it is whole)
//
// capture.journal: line 1 is {"format": "facet-capture-journal/1", "identity": {...}}, where the
// identity holds the display's projectors, the camera, the frames (file and pattern) and every
// setting that changes the images (averaging, bits, camera gamma); each further line is
// {"done": "<file>"} for a frame whose image is in place. A torn last line (a kill during the
// append) is ignored. A second run on the same folder checks that its identity is the journal's
// (InputError naming the first differing field otherwise), keeps every frame whose image reads
// back at the camera's size (also one renamed into place just before a kill, before its journal
// line), removes stale temporary files, and captures only the rest.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/calibration/camera_model.hpp"
#include "facet/calibration/capture.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::calibration {

inline constexpr const char* kCaptureJournalFormat = "facet-capture-journal/1";
inline constexpr const char* kCaptureJournalFile = "capture.journal";

// Where the patterns appear: one output per projector of the capture, in its order.
class PatternOutputs {
 public:
  virtual ~PatternOutputs() = default;
  // Shows `values` (CV_32F, the projector's size (W, H), pattern values in [0,1] before the
  // projector's gamma) on projector `projector`'s output and black on every other output; returns
  // once the image is on screen and the settle time has passed.
  virtual void show(std::size_t projector, const cv::Mat& values) = 0;
  // Black on every output.
  virtual void blank() = 0;
};

// Which exposure a grab is: the projector and frame index in the capture and the repeat (0 to
// average − 1). Real cameras ignore it; the fake camera seeds its noise with it.
struct GrabKey {
  std::size_t projector = 0, frame = 0, repeat = 0;
};

class LiveCamera {
 public:
  virtual ~LiveCamera() = default;
  // Image size (W, H) in camera pixels.
  virtual glm::ivec2 size() const = 0;
  // One exposure: CV_32F of size(), grey, in the camera's own encoding scaled so that full scale
  // (a clipped pixel) is exactly 1. Throws InputError when the camera stops delivering frames.
  virtual cv::Mat grab(const GrabKey& key) = 0;
  // What identifies the camera and its settings in the journal (a device id, a rig, ...).
  virtual nlohmann::json identity() const = 0;
};

// What to capture.
struct LiveCaptureSetup {
  // Names, sizes, gammas and frames (file relative to the folder, pattern) of every projector,
  // in the order of PatternOutputs.
  std::vector<CaptureProjector> projectors;
  // The pose for capture.json; `model` is set to "camera.cameramodel" and `gamma` to 1 (images
  // are written in linear light).
  CaptureCamera camera;
  std::optional<CameraModel> model;  // the camera's lens model; required
  std::optional<Screen> screen;
  // The display the capture runs with, kept as display.json in the capture folder (capture.json's
  // `display`) so that facet calibrate writes it back with its warps and blends filled in.
  std::optional<projection_io::DisplayConfig> display;
  // Added to the journal identity: what else the images depend on (the display, ...).
  nlohmann::json identity = nlohmann::json::object();
  // Called after the last frame and before capture.json is written, with the capture folder:
  // extra files (a fake camera's truth/). Returns the value of capture.json's `truth`, if any.
  std::function<std::optional<std::filesystem::path>(const std::filesystem::path&)> finish;
};

struct LiveCaptureOptions {
  std::filesystem::path out;  // the capture folder: new, empty, or an interrupted capture's
  int average = 1;            // exposures averaged per frame, >= 1
  int bits = 16;              // PNG bits per sample of the written frames, 8 or 16
  // Camera response: a grabbed value e is light proportional to e^camera_gamma. Grabs are
  // linearised before averaging, and the frames are written in linear light.
  double camera_gamma = 1;
  // Exposure check on each projector's white frame: the share of camera pixels at full scale in
  // any of its exposures must not exceed this (InputError naming the projector otherwise).
  double max_clipped_fraction = 0.001;
  bool allow_clipping = false;  // report clipping but go on
  // Stop (leaving the capture resumable) after this many frames captured in this run.
  std::optional<std::size_t> stop_after;
  // Polled between frames; true stops the capture as stop_after does (SIGINT).
  std::function<bool()> interrupted;
  // One line per event (frame captured, frames kept from an earlier run, clipping).
  std::function<void(const std::string&)> log;
};

struct LiveCaptureReport {
  std::size_t frames = 0;    // frames the capture has in all
  std::size_t kept = 0;      // frames found done from an earlier run
  std::size_t captured = 0;  // frames captured in this run
  bool complete = false;     // capture.json written (now or by an earlier run)
  struct Exposure {
    std::string projector;
    double clipped_fraction = 0;  // on its white frame, when captured in this run
    double white_max = 0;         // largest linear value of the averaged white frame
  };
  std::vector<Exposure> exposures;
  double seconds = 0;
};

// The checks run_live_capture makes of `options` before anything else, for a command to make
// before its camera and projectors start: InputError naming the flag for average < 1, bits not 8
// or 16, a camera gamma outside (0, 10], a clipped fraction outside [0, 1], and an --out that is
// neither new (and creatable) nor an empty folder nor an interrupted capture's folder (it holds
// capture.journal), or is the current folder or one of its parents.
void check_live_capture_options(const LiveCaptureOptions& options);

// Runs or resumes the capture described above. Throws InputError (nothing finished, the folder
// stays resumable) for: an output path that is a file or a folder holding something else, a
// journal whose identity differs, bad options (average < 1, bits not 8 or 16, camera gamma <= 0),
// a camera whose frames change size, and clipping on a white frame (unless allow_clipping).
LiveCaptureReport run_live_capture(PatternOutputs& outputs, LiveCamera& camera,
                                   const LiveCaptureSetup& setup,
                                   const LiveCaptureOptions& options);

// The standard frames of a projector as capture.json lists them: "<name>/<pattern>.png".
std::vector<CaptureFrame> standard_frames(const std::string& projector_name, glm::ivec2 size,
                                          const PatternSetOptions& options = {});

}  // namespace facet::calibration
