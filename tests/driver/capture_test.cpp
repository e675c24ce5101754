// driver::run_capture, the library call behind `facet capture`, run directly: the fake camera of
// the calibration replay tests' small rig, patterns drawn headless through EGL. A run stopped by
// its `interrupted` callback resumes to a complete capture; bad options are refused by their
// library names before anything is written.
#include "facet/driver/capture.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "capture_rig_files.hpp"
#include "facet/calibration/capture.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

namespace fs = std::filesystem;

// Options that capture the files' rig with its fake camera into `out`, headless, no settling.
CaptureOptions fake_capture(const facet::test::RigFiles& files, const fs::path& out) {
  CaptureOptions options;
  options.display = files.display.string();
  options.camera = "fake:" + files.rig.string();
  options.out = out;
  options.settle_ms = 0;
  return options;
}

// Every line a sink got, with its level.
struct Lines {
  std::vector<std::pair<LogLevel, std::string>> got;
  LogSink sink() {
    return [this](LogLevel level, const std::string& line) { got.emplace_back(level, line); };
  }
};

constexpr std::size_t kFrames = 2 * 38;  // two projectors, 38 standard frames each

TEST(Capture, AnInterruptedRunResumesToACompleteCapture) {
  const facet::test::RigFiles files;
  const fs::path out = files.temp.path() / "capture";
  CaptureOptions options = fake_capture(files, out);
  std::size_t polls = 0;
  options.interrupted = [&polls] { return ++polls > 10; };
  Lines first;
  const calibration::LiveCaptureReport stopped = run_capture(options, first.sink());
  EXPECT_FALSE(stopped.complete);
  EXPECT_EQ(stopped.frames, kFrames);
  EXPECT_EQ(stopped.kept, 0u);
  EXPECT_EQ(stopped.captured, 10u);
  EXPECT_FALSE(fs::exists(out / "capture.json"));
  // A line per frame captured, and one for the first white frame's exposure; all info.
  EXPECT_EQ(first.got.size(), 11u);
  for (const auto& [level, line] : first.got) EXPECT_EQ(level, LogLevel::info) << line;

  options.interrupted = {};
  Lines second;
  const calibration::LiveCaptureReport resumed = run_capture(options, second.sink());
  EXPECT_TRUE(resumed.complete);
  EXPECT_EQ(resumed.frames, kFrames);
  EXPECT_EQ(resumed.kept, 10u);
  EXPECT_EQ(resumed.captured, kFrames - 10);
  ASSERT_FALSE(second.got.empty());
  EXPECT_EQ(second.got[0].second, "kept 10 of 76 frames from an earlier run");
  // The second projector's white frame is the only one captured in this run.
  ASSERT_EQ(resumed.exposures.size(), 1u);
  EXPECT_EQ(resumed.exposures[0].projector, "right");
  EXPECT_LE(resumed.exposures[0].clipped_fraction, options.max_clipped_fraction);

  const calibration::Capture capture = calibration::read_capture(out);
  ASSERT_EQ(capture.projectors.size(), 2u);
  std::size_t frames = 0;
  for (const calibration::CaptureProjector& projector : capture.projectors) {
    for (const calibration::CaptureFrame& frame : projector.frames) {
      EXPECT_TRUE(fs::is_regular_file(capture.resolve(frame.file))) << frame.file;
      ++frames;
    }
  }
  EXPECT_EQ(frames, kFrames);
  EXPECT_EQ(capture.display, fs::path("display.json"));
  // A run on the finished capture captures nothing and says it is complete.
  const calibration::LiveCaptureReport again = run_capture(options, {});
  EXPECT_TRUE(again.complete);
  EXPECT_EQ(again.captured, 0u);
}

// The option an InputError of run_capture names, and that its message names no flag.
std::string refused_option(const CaptureOptions& options) {
  try {
    run_capture(options, {});
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).find("--"), std::string::npos) << error.what();
    return error.option();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

TEST(Capture, BadOptionsAreRefusedByTheirLibraryNamesBeforeAnyWork) {
  const facet::test::RigFiles files;
  const fs::path out = files.temp.path() / "capture";
  CaptureOptions headless_real = fake_capture(files, out);
  headless_real.camera = "/dev/video-none-here";
  headless_real.camera_model = files.temp.path() / "camera.cameramodel";
  headless_real.presenter = CapturePresenter::headless;
  EXPECT_EQ(refused_option(headless_real), "presenter");
  CaptureOptions sized_fake = fake_capture(files, out);
  sized_fake.camera_size = glm::ivec2(640, 480);
  EXPECT_EQ(refused_option(sized_fake), "camera_size");
  CaptureOptions no_model = fake_capture(files, out);
  no_model.camera = "/dev/video-none-here";
  EXPECT_EQ(refused_option(no_model), "camera_model");
  CaptureOptions no_rig = fake_capture(files, out);
  no_rig.camera = "fake:";
  EXPECT_EQ(refused_option(no_rig), "camera");
  CaptureOptions missing_rig = fake_capture(files, out);
  missing_rig.camera = "fake:" + (files.temp.path() / "missing.json").string();
  EXPECT_EQ(refused_option(missing_rig), "camera");
  CaptureOptions fake_with_pose = fake_capture(files, out);
  fake_with_pose.camera_pose = files.temp.path() / "pose.json";
  EXPECT_EQ(refused_option(fake_with_pose), "camera_pose");
  fake_with_pose.camera_model = files.temp.path() / "camera.cameramodel";
  EXPECT_EQ(refused_option(fake_with_pose), "camera_model");
  CaptureOptions settle = fake_capture(files, out);
  settle.settle_ms = -1;
  EXPECT_EQ(refused_option(settle), "settle_ms");
  CaptureOptions steps = fake_capture(files, out);
  steps.phase_steps = 2;
  EXPECT_EQ(refused_option(steps), "phase_steps");
  CaptureOptions gamma = fake_capture(files, out);
  gamma.projector_gamma = 11;
  EXPECT_EQ(refused_option(gamma), "projector_gamma");
  CaptureOptions bits = fake_capture(files, out);
  bits.bits = 12;
  EXPECT_EQ(refused_option(bits), "bits");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace facet::driver
