#include "facet/driver/capture.hpp"

#include <chrono>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "facet/calibration/fake_camera.hpp"
#include "facet/calibration/video_camera.hpp"
#include "facet/driver/pattern_presenter.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/rig.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/rig_file.hpp"

namespace facet::driver {
namespace {

namespace fs = std::filesystem;
using calibration::CaptureProjector;

constexpr std::string_view kFakeScheme = "fake:";

// The calibration side's view of the presenter: pattern values in [0,1] go out as 8-bit levels.
class PresenterOutputs : public calibration::PatternOutputs {
 public:
  explicit PresenterOutputs(PatternPresenter& presenter) : presenter_(presenter) {}
  void show(std::size_t projector, const cv::Mat& values) override {
    cv::Mat levels;
    values.convertTo(levels, CV_8U, 255.0);  // rounds to the nearest level
    FACET_ASSERT(levels.isContinuous());
    presenter_.show(projector, {levels.data, levels.total()});
  }
  void blank() override { presenter_.blank(); }

 private:
  PatternPresenter& presenter_;
};

// The checks of the options that need neither the display nor the rig, made before anything is
// read beyond the display.
void check_options(const CaptureOptions& options, bool fake) {
  if (options.presenter == CapturePresenter::headless && !fake) {
    throw InputError(OptionName{"presenter"},
                     "a fake camera (fake:RIG.json): a real camera must see the patterns on the "
                     "projectors");
  }
  if (options.camera_size && fake) {
    throw InputError(OptionName{"camera_size"},
                     "a real camera: a fake camera's size comes from its rig (camera.size)");
  }
  if (options.projector_gamma &&
      !(*options.projector_gamma > 0 && *options.projector_gamma <= kMaxGamma)) {
    throw InputError(OptionName{"projector_gamma"}, "a gamma in (0, 10]");
  }
  if (!(options.camera_gamma > 0 && options.camera_gamma <= kMaxGamma)) {
    throw InputError(OptionName{"camera_gamma"}, "a gamma in (0, 10]");
  }
  // Checked up front whatever the camera (a fake one ignores some): a minute's settling, a
  // thousand dropped or averaged frames per pattern are more than any camera needs.
  if (options.settle_ms < 0 || options.settle_ms > 60'000) {
    throw InputError(OptionName{"settle_ms"}, "milliseconds from 0 to 60000");
  }
  if (options.discard < 0 || options.discard > 1000) {
    throw InputError(OptionName{"discard"}, "a number of frames from 0 to 1000");
  }
  if (options.average < 1 || options.average > 1000) {
    throw InputError(OptionName{"average"}, "a number of exposures from 1 to 1000");
  }
}

// The rig of a fake camera (fake:RIG), or nullopt for a real camera, which needs its lens model.
std::optional<Rig> load_camera_rig(const CaptureOptions& options, bool fake) {
  if (!fake) {
    if (options.camera_model.empty()) {
      throw InputError(OptionName{"camera_model"},
                       "the camera's mrcal .cameramodel (a real camera needs its lens model)");
    }
    return std::nullopt;
  }
  const std::string rig_name = options.camera.substr(kFakeScheme.size());
  if (rig_name.empty()) {
    throw InputError(OptionName{"camera"}, "fake:RIG, RIG a rig file or builtin:NAME; got 'fake:'");
  }
  std::optional<Rig> rig;
  try {
    rig = load_rig(rig_name);
  } catch (const InputError& error) {
    // The rig's errors name the option that gave it: its name alone may be the mistake.
    throw InputError(OptionName{"camera"}, error.what());
  }
  if (!options.camera_model.empty() || !options.camera_pose.empty()) {
    throw InputError(OptionName{options.camera_model.empty() ? "camera_pose" : "camera_model"},
                     "no camera model or camera pose with a fake camera: the rig gives both");
  }
  return rig;
}

// The pattern set: 16 px phase in 4 steps, the rig's for a fake camera, then the options'.
calibration::PatternSetOptions pattern_set(const CaptureOptions& options,
                                           const std::optional<Rig>& rig) {
  calibration::PatternSetOptions patterns;
  patterns.phase_period = 16;
  if (rig) {
    patterns.phase_period =
        rig->simulation.phase ? std::optional<double>(rig->simulation.phase_period) : std::nullopt;
    patterns.phase_steps = rig->simulation.phase_steps;
  }
  if (options.phase_period) patterns.phase_period = *options.phase_period;
  if (options.phase_steps) patterns.phase_steps = *options.phase_steps;
  if (!options.phase) patterns.phase_period.reset();
  if (patterns.phase_period &&
      !(*patterns.phase_period >= kMinPhasePeriod && *patterns.phase_period <= kMaxPhasePeriod)) {
    throw InputError(OptionName{"phase_period"}, "a period from 2 to 65536 projector pixels");
  }
  if (patterns.phase_steps < 3 || patterns.phase_steps > 64) {
    throw InputError(OptionName{"phase_steps"}, "3 to 64 steps");
  }
  return patterns;
}

// The display's projectors with their gammas and standard frames, and the display itself.
calibration::LiveCaptureSetup capture_setup(const CaptureOptions& options,
                                            const projection_io::DisplayConfig& display,
                                            const calibration::PatternSetOptions& patterns) {
  calibration::LiveCaptureSetup setup;
  for (const projection_io::DisplayProjector& p : display.projectors) {
    CaptureProjector projector;
    projector.name = p.name;
    projector.size = p.size;
    // display.json's gamma is the output encoding, value = linear^(1/gamma): the same response.
    projector.gamma = options.projector_gamma ? *options.projector_gamma : p.gamma.value_or(2.2);
    projector.frames = calibration::standard_frames(p.name, p.size, patterns);
    setup.projectors.push_back(std::move(projector));
  }
  setup.identity = {{"display", display.name}};
  setup.display = display;
  return setup;
}

// The fake camera of `rig`, seeing what `presenter` shows (set before the first grab); fills the
// setup's camera model, pose, screen and truth writer.
std::unique_ptr<calibration::LiveCamera> make_fake_camera(
    const CaptureOptions& options, const Rig& rig, calibration::LiveCaptureSetup& setup,
    const std::unique_ptr<PatternPresenter>& presenter) {
  auto shown = [&presenter](std::size_t projector) {
    const std::vector<std::uint8_t>& bytes = presenter->shown(projector);
    const glm::ivec2 size = presenter->output_size(projector);
    cv::Mat values;
    cv::Mat(size.y, size.x, CV_8U, const_cast<std::uint8_t*>(bytes.data()))
        .convertTo(values, CV_32F, 1.0 / 255.0);
    return values;
  };
  auto camera = std::make_unique<calibration::FakeCamera>(
      rig, setup.projectors, shown, options.camera.substr(kFakeScheme.size()));
  calibration::FakeCamera* fake_camera = camera.get();
  setup.model = fake_camera->model();
  setup.camera.R_eye_camera = rig.camera.R_eye_camera;
  setup.camera.t_eye_camera = rig.camera.t_eye_camera;
  setup.screen = rig.screen;
  setup.finish = [fake_camera](const fs::path& folder) -> std::optional<fs::path> {
    return fake_camera->write_truth(folder);
  };
  return camera;
}

// The V4L2 camera of options.camera; fills the setup's camera model, pose and screen.
std::unique_ptr<calibration::LiveCamera> open_real_camera(
    const CaptureOptions& options, const projection_io::DisplayConfig& display,
    calibration::LiveCaptureSetup& setup) {
  setup.model = calibration::CameraModel::read(options.camera_model);
  if (!options.camera_pose.empty())
    calibration::read_camera_pose(options.camera_pose, setup.camera);
  setup.screen = display.screen;
  calibration::VideoCameraOptions video;
  video.size = options.camera_size;
  video.discard = options.discard;
  const std::string device =
      calibration::find_video_node(options.camera, calibration::list_video_devices());
  return calibration::open_video_camera(device, options.camera, video);
}

}  // namespace

calibration::LiveCaptureReport run_capture(const CaptureOptions& options, const LogSink& log) {
  const projection_io::DisplayConfig display =
      projection_io::read_display_template(options.display);
  const bool fake = options.camera.starts_with(kFakeScheme);
  check_options(options, fake);
  const std::optional<Rig> rig = load_camera_rig(options, fake);
  const calibration::PatternSetOptions patterns = pattern_set(options, rig);

  // Checked before the camera and the projectors start.
  calibration::LiveCaptureOptions capture;
  capture.out = options.out;
  capture.average = options.average;
  capture.bits = options.bits ? *options.bits : rig ? rig->simulation.bits : 16;
  capture.camera_gamma = options.camera_gamma;
  capture.max_clipped_fraction = options.max_clipped_fraction;
  capture.allow_clipping = options.allow_clipping;
  capture.stop_after = options.stop_after;
  calibration::check_live_capture_options(capture);

  calibration::LiveCaptureSetup setup = capture_setup(options, display, patterns);
  std::unique_ptr<PatternPresenter> presenter;
  const std::unique_ptr<calibration::LiveCamera> camera =
      rig ? make_fake_camera(options, *rig, setup, presenter)
          : open_real_camera(options, display, setup);
  const auto settle = std::chrono::milliseconds(options.settle_ms);
  if (fake && options.presenter != CapturePresenter::windowed) {
    std::vector<glm::ivec2> sizes;
    for (const auto& p : display.projectors) sizes.push_back(p.size);
    presenter = create_headless_presenter(sizes, settle);
  } else {
    presenter = create_windowed_presenter(display, options.display, settle);
  }
  PresenterOutputs outputs(*presenter);

  PatternPresenter* watched = presenter.get();
  capture.interrupted = [&options, watched] {
    return (options.interrupted && options.interrupted()) || watched->closed();
  };
  if (log) capture.log = [&log](const std::string& line) { log(LogLevel::info, line); };
  return calibration::run_live_capture(outputs, *camera, setup, capture);
}

}  // namespace facet::driver
