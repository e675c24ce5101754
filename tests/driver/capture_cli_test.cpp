// `facet capture` end to end with the fake camera: patterns drawn headless through EGL into one
// framebuffer per projector, read back, and seen through the virtual rig of the calibration
// replay tests. A capture stopped (--stop-after) or killed (SIGKILL) and then resumed must write
// the same frames, byte for byte, as one that ran through, and calibrate to the replay targets.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "../calibration/capture_rig.hpp"
#include "capture_rig_files.hpp"
#include "facet/calibration/calibrate.hpp"
#include "facet/calibration/capture.hpp"
#include "facet/calibration/live_capture.hpp"
#include "facet/calibration/simulate.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "support/facet_cli.hpp"

namespace facet::calibration {
namespace {

namespace fs = std::filesystem;

using test::RigFiles;

// Every frame file of the finished capture `a` exists in `b` with the same bytes, and both
// capture.json files list the same frames.
void expect_same_frames(const fs::path& a, const fs::path& b) {
  const Capture first = read_capture(a), second = read_capture(b);
  EXPECT_EQ(capture_to_json(first), capture_to_json(second));
  std::size_t compared = 0;
  for (const CaptureProjector& projector : first.projectors) {
    for (const CaptureFrame& frame : projector.frames) {
      EXPECT_EQ(test::slurp(first.resolve(frame.file)), test::slurp(second.resolve(frame.file)))
          << frame.file;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 2u * 38);
}

std::size_t journal_frames(const fs::path& out) {
  std::ifstream stream(out / kCaptureJournalFile);
  std::size_t done = 0;
  std::string line;
  while (std::getline(stream, line)) done += line.find("\"done\"") != std::string::npos;
  return done;
}

TEST(CaptureCli, AStoppedCaptureResumesToTheSameFrames) {
  const RigFiles setup;
  const fs::path whole = setup.temp.path() / "whole";
  ASSERT_EQ(test::run_facet(setup.command(whole)), 0);

  // A deterministic stop: exit 3, nothing finished, then a resume that captures the rest.
  const fs::path stopped = setup.temp.path() / "stopped";
  std::string output;
  ASSERT_EQ(test::run_facet(setup.command(stopped, "--stop-after 25"), &output), 3) << output;
  EXPECT_FALSE(fs::exists(stopped / "capture.json"));
  EXPECT_EQ(journal_frames(stopped), 25u);
  ASSERT_EQ(test::run_facet(setup.command(stopped, "--json"), &output), 0) << output;
  const nlohmann::json report = nlohmann::json::parse(output.substr(output.find('{')));
  EXPECT_EQ(report["kept"], 25);
  EXPECT_EQ(report["captured"], 2 * 38 - 25);
  EXPECT_TRUE(report["complete"].get<bool>());
  expect_same_frames(whole, stopped);
}

TEST(CaptureCli, AKilledCaptureResumesToTheSameFrames) {
  const RigFiles setup;
  const fs::path whole = setup.temp.path() / "whole";
  ASSERT_EQ(test::run_facet(setup.command(whole)), 0);
  std::string output;
  // A real interruption: SIGKILL once some frames exist.
  const fs::path killed = setup.temp.path() / "killed";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::freopen("/dev/null", "w", stdout);
    const std::string display = setup.display.string(), camera = "fake:" + setup.rig.string(),
                      out = killed.string();
    ::execl(FACET_CLI, "facet", "capture", "--display", display.c_str(), "--camera", camera.c_str(),
            "--out", out.c_str(), "--settle-ms", "20", "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (journal_frames(killed) < 10 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the capture ended before it was killed";
  EXPECT_FALSE(fs::exists(killed / "capture.json"));
  const std::size_t before = journal_frames(killed);
  EXPECT_GE(before, 10u);
  ASSERT_EQ(test::run_facet(setup.command(killed, "--json"), &output), 0) << output;
  const nlohmann::json resumed = nlohmann::json::parse(output.substr(output.find('{')));
  // At most one frame was renamed into place after its predecessor's journal line.
  EXPECT_GE(resumed["kept"].get<std::size_t>(), before);
  EXPECT_LE(resumed["kept"].get<std::size_t>(), before + 1);
  EXPECT_EQ(resumed["kept"].get<std::size_t>() + resumed["captured"].get<std::size_t>(), 76u);
  expect_same_frames(whole, killed);
  // No temporary file survives the resume.
  for (const auto& entry : fs::recursive_directory_iterator(killed)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

TEST(CaptureCli, SigintStopsBetweenFramesAndLeavesTheCaptureResumable) {
  const RigFiles files;
  const fs::path out = files.temp.path() / "interrupted";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::freopen("/dev/null", "w", stdout);
    const std::string display = files.display.string(), camera = "fake:" + files.rig.string(),
                      folder = out.string();
    ::execl(FACET_CLI, "facet", "capture", "--display", display.c_str(), "--camera", camera.c_str(),
            "--out", folder.c_str(), "--settle-ms", "20", "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (journal_frames(out) < 5 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(child, SIGINT);
  int status = 0;
  ::waitpid(child, &status, 0);
  // Stopped after the frame in hand: the incomplete capture's exit status, every frame journaled.
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping";
  EXPECT_EQ(WEXITSTATUS(status), 3);
  EXPECT_FALSE(fs::exists(out / "capture.json"));
  const std::size_t journaled = journal_frames(out);
  std::size_t images = 0;
  for (const auto& entry : fs::recursive_directory_iterator(out)) {
    images += entry.path().extension() == ".png";
  }
  EXPECT_EQ(images, journaled);
  EXPECT_LT(journaled, 76u);
  std::string output;
  ASSERT_EQ(test::run_facet(files.command(out, "--json"), &output), 0) << output;
  const nlohmann::json report = nlohmann::json::parse(output.substr(output.find('{')));
  EXPECT_EQ(report["kept"].get<std::size_t>(), journaled);
  EXPECT_EQ(report["kept"].get<std::size_t>() + report["captured"].get<std::size_t>(), 76u);
}

TEST(CaptureCli, AResumedCaptureCalibratesLikeTheSimulatedOne) {
  const RigFiles setup;
  const fs::path live = setup.temp.path() / "live";
  ASSERT_EQ(test::run_facet(setup.command(live, "--stop-after 40")), 3);
  ASSERT_EQ(test::run_facet(setup.command(live)), 0);
  const CalibrationReport live_report = calibrate(live, setup.temp.path() / "live-display");
  // The display the capture ran with comes back whole, its warps and blends filled in: name,
  // eye, outputs, gammas, render settings and missing_monitor as in the file given to capture.
  EXPECT_EQ(read_capture(live).display, fs::path("display.json"));
  projection_io::DisplayConfig expected = projection_io::read_display_template(setup.display);
  for (projection_io::DisplayProjector& projector : expected.projectors) {
    projector.warp = projector.name + ".warp.exr";
    projector.blend = projector.name + ".blend.exr";
  }
  projection_io::DisplayConfig written =
      projection_io::read_display_config(setup.temp.path() / "live-display");
  expected.folder = written.folder;
  expected.screen = written.screen;  // the rig's screen, recorded by the capture
  EXPECT_EQ(projection_io::format_display_config(written),
            projection_io::format_display_config(expected));
  EXPECT_EQ(written.name, "capture-test");
  EXPECT_EQ(written.render.method, "naive");
  // A display whose projectors are not the capture's is refused before any work, naming it.
  CalibrateOptions renamed;
  renamed.display = expected;
  renamed.display->projectors[0].name = "elsewhere";
  const fs::path refused = setup.temp.path() / "refused";
  try {
    calibrate(live, refused, renamed);
    ADD_FAILURE() << "a display without the capture's projector was accepted";
  } catch (const facet::InputError& error) {
    EXPECT_EQ(error.field(), "projectors");
    EXPECT_NE(std::string(error.what()).find(live_report.projectors[0].name), std::string::npos)
        << error.what();
  }
  EXPECT_FALSE(fs::exists(refused));
  const fs::path simulated = setup.temp.path() / "simulated";
  simulate_capture(test::capture_test_rig(), simulated);
  const CalibrationReport simulated_report =
      calibrate(simulated, setup.temp.path() / "simulated-display");
  ASSERT_EQ(live_report.projectors.size(), 2u);
  for (std::size_t p = 0; p < 2; ++p) {
    const ProjectorReport& a = live_report.projectors[p];
    const ProjectorReport& b = simulated_report.projectors[p];
    ASSERT_TRUE(a.accuracy && b.accuracy) << a.name;
    std::printf(
        "%s: live rms %.4f p99 %.4f max %.4f px, holes %zu, folds %zu; simulate rms %.4f p99 "
        "%.4f max %.4f px, holes %zu, folds %zu\n",
        a.name.c_str(), a.accuracy->rms_px, a.accuracy->p99_px, a.accuracy->max_px, a.fit.holes,
        a.fit.folds, b.accuracy->rms_px, b.accuracy->p99_px, b.accuracy->max_px, b.fit.holes,
        b.fit.folds);
    // The replay test's targets (FORMATS.md §5, 8 px border), in output pixels.
    EXPECT_LE(a.accuracy->rms_px, 0.1) << a.name;
    EXPECT_LE(a.accuracy->p99_px, 0.3) << a.name;
    EXPECT_LE(a.accuracy->max_px, 1.0) << a.name;
    EXPECT_LE(a.accuracy->uncovered_fraction, 0.001) << a.name;
    EXPECT_EQ(a.fit.folds, 0u) << a.name;
    EXPECT_EQ(a.fit.holes, 0u) << a.name;
    // Only the phase frames differ (8-bit output levels): the results must agree closely.
    EXPECT_LE(std::abs(a.accuracy->rms_px - b.accuracy->rms_px), 0.01) << a.name;
    EXPECT_LE(std::abs(a.accuracy->p99_px - b.accuracy->p99_px), 0.05) << a.name;
  }
  EXPECT_LE(live_report.blend_sum_max_err, 0.005);
}

TEST(CaptureCli, BadInputExitsTwoAndFinishesNothing) {
  Rig bright = test::capture_test_rig();
  bright.simulation.peak = 1;  // with ambient light, past full scale
  bright.simulation.ambient = 0.3;
  const RigFiles setup;
  std::string output;
  // An unknown camera device: nothing is created.
  const fs::path none = setup.temp.path() / "none";
  EXPECT_EQ(
      test::run_facet("capture --display " + setup.display.string() +
                          " --camera /dev/video-none-here --camera-model x.cameramodel --out " +
                          none.string(),
                      &output),
      2)
      << output;
  EXPECT_FALSE(fs::exists(none));
  // A real camera needs its lens model.
  EXPECT_EQ(test::run_facet("capture --display " + setup.display.string() +
                                " --camera /dev/video0 --out " + none.string(),
                            &output),
            2);
  EXPECT_NE(output.find("--camera-model"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(none));
  // A resume with other settings than the interrupted capture.
  const fs::path out = setup.temp.path() / "capture";
  ASSERT_EQ(test::run_facet(setup.command(out, "--stop-after 3")), 3);
  EXPECT_EQ(test::run_facet(setup.command(out, "--average 2"), &output), 2) << output;
  EXPECT_NE(output.find("settings.average"), std::string::npos) << output;
  EXPECT_EQ(test::run_facet(setup.command(out, "--bits 8"), &output), 2) << output;
  EXPECT_NE(output.find("settings.bits"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out / "capture.json"));
  // Clipping on the white frame: exit 2 naming the projector, no capture.json.
  const RigFiles clipped(bright);
  const fs::path clipped_out = clipped.temp.path() / "capture";
  EXPECT_EQ(test::run_facet(clipped.command(clipped_out), &output), 2) << output;
  EXPECT_NE(output.find("projector 'left': field '--max-clipped'"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(clipped_out / "capture.json"));
  // ... unless accepted.
  EXPECT_EQ(
      test::run_facet(clipped.command(clipped_out, "--allow-clipping --stop-after 2"), &output), 3)
      << output;
}

}  // namespace
}  // namespace facet::calibration
