// Live capture orchestration (live_capture.hpp) with the fake camera (fake_camera.hpp) and an
// in-memory pattern output that quantises to 8 bits as a projector output does: frames against
// `facet simulate`'s, resume after a stop, the journal's identity check, clipping, and the sysfs
// lookup of video devices.
#include "facet/calibration/live_capture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "capture_rig.hpp"
#include "facet/calibration/fake_camera.hpp"
#include "facet/calibration/image_io.hpp"
#include "facet/calibration/simulate.hpp"
#include "facet/calibration/video_camera.hpp"
#include "facet/projection/errors.hpp"
#include "support/files.hpp"

namespace facet::calibration {
namespace {

namespace fs = std::filesystem;

// Pattern outputs in memory: each output holds the 8-bit levels it was last given, as values.
class MemoryOutputs : public PatternOutputs {
 public:
  explicit MemoryOutputs(const std::vector<CaptureProjector>& projectors) {
    for (const auto& p : projectors) shown.push_back(cv::Mat::zeros(p.size.y, p.size.x, CV_32F));
  }
  void show(std::size_t projector, const cv::Mat& values) override {
    for (auto& image : shown) image.setTo(0.0f);
    cv::Mat levels;
    values.convertTo(levels, CV_8U, 255.0);
    levels.convertTo(shown[projector], CV_32F, 1.0 / 255.0);
    ++shows;
  }
  void blank() override {
    for (auto& image : shown) image.setTo(0.0f);
  }
  std::vector<cv::Mat> shown;
  int shows = 0;
};

struct FakeRun {
  Rig rig = test::capture_test_rig();
  LiveCaptureSetup setup;
  std::optional<MemoryOutputs> outputs;
  std::optional<FakeCamera> camera;

  explicit FakeRun(bool phase = true, bool overexposed = false, double noise = 0.01) {
    rig.simulation.noise = noise;
    if (overexposed) {
      // The brightest white plus ambient light past full scale.
      rig.simulation.peak = 1;
      rig.simulation.ambient = 0.3;
    }
    rig.simulation.phase = phase;
    PatternSetOptions patterns;
    if (phase) patterns.phase_period = rig.simulation.phase_period;
    for (const ProjectorModel& p : rig.projectors) {
      CaptureProjector projector{p.name, p.size, 2.2, standard_frames(p.name, p.size, patterns)};
      setup.projectors.push_back(projector);
    }
    outputs.emplace(setup.projectors);
    camera.emplace(rig, setup.projectors, [this](std::size_t p) { return outputs->shown[p]; });
    setup.model = camera->model();
    setup.camera.R_eye_camera = rig.camera.R_eye_camera;
    setup.screen = rig.screen;
  }

  LiveCaptureReport run(const fs::path& out, std::optional<std::size_t> stop_after = {},
                        int average = 1) {
    LiveCaptureOptions options;
    options.log = [this](const std::string& line) { log.push_back(line); };
    options.out = out;
    options.average = average;
    options.stop_after = stop_after;
    return run_live_capture(*outputs, *camera, setup, options);
  }
  std::vector<std::string> log;  // every line the runs logged
};

std::string file_bytes(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

TEST(LiveCapture, FakeFramesAreSimulatesWhereTheOutputShowsThePatternExactly) {
  const test::TempFolder temp;
  FakeRun run;
  const LiveCaptureReport report = run.run(temp.path() / "live");
  ASSERT_TRUE(report.complete);
  EXPECT_EQ(report.captured, report.frames);
  simulate_capture(run.rig, temp.path() / "simulated");
  const Capture live = read_capture(temp.path() / "live");
  const Capture simulated = read_capture(temp.path() / "simulated");
  ASSERT_EQ(live.projectors.size(), simulated.projectors.size());
  std::size_t identical = 0, phase_frames = 0;
  double phase_max_difference = 0;
  for (std::size_t p = 0; p < live.projectors.size(); ++p) {
    ASSERT_EQ(live.projectors[p].frames, simulated.projectors[p].frames);
    for (const CaptureFrame& frame : live.projectors[p].frames) {
      const fs::path a = live.resolve(frame.file), b = simulated.resolve(frame.file);
      if (frame.pattern.type != PatternType::phase) {
        // 0 and 1 survive the output's 8 bits exactly: bit for bit simulate's frame.
        EXPECT_EQ(file_bytes(a), file_bytes(b)) << frame.file;
        ++identical;
      } else {
        // Phase values go out as 8-bit levels (±0.5/255 before gamma 2.2): the light differs by
        // at most peak · 2.2 · 0.5/255 ≈ 0.004 of full scale plus one 16-bit level.
        double difference = 0;
        cv::minMaxLoc(cv::abs(read_luminance(a) - read_luminance(b)), nullptr, &difference);
        phase_max_difference = std::max(phase_max_difference, difference);
        ++phase_frames;
      }
    }
  }
  std::printf("identical frames %zu, phase frames %zu with max |live - simulate| %.5f\n", identical,
              phase_frames, phase_max_difference);
  EXPECT_EQ(identical, 2u * (2 + 2 * 7 + 2 * 7));
  EXPECT_EQ(phase_frames, 2u * 8);
  EXPECT_LE(phase_max_difference, 0.005);
  EXPECT_GT(phase_max_difference, 0.0);  // the outputs really quantise
}

TEST(LiveCapture, AStoppedCaptureResumesToTheSameFrames) {
  const test::TempFolder temp;
  FakeRun whole(false), parts(false);
  ASSERT_TRUE(whole.run(temp.path() / "whole").complete);
  const fs::path out = temp.path() / "parts";
  const LiveCaptureReport first = parts.run(out, 7);
  EXPECT_FALSE(first.complete);
  EXPECT_EQ(first.captured, 7u);
  EXPECT_FALSE(fs::exists(out / "capture.json"));
  const LiveCaptureReport second = parts.run(out, 20);
  EXPECT_FALSE(second.complete);
  EXPECT_EQ(second.kept, 7u);
  EXPECT_EQ(second.captured, 20u);
  const int shows_before = parts.outputs->shows;
  const LiveCaptureReport third = parts.run(out);
  EXPECT_TRUE(third.complete);
  EXPECT_EQ(third.kept, 27u);
  EXPECT_EQ(third.kept + third.captured, third.frames);
  // Each captured frame's line counts the frames done of all, an earlier run's included.
  std::vector<std::string> captured;
  for (const std::string& line : parts.log)
    if (line.starts_with("captured ")) captured.push_back(line);
  ASSERT_EQ(captured.size(), third.frames);
  EXPECT_NE(captured[0].find(": frames 1/" + std::to_string(third.frames) + ", "),
            std::string::npos)
      << captured[0];
  EXPECT_NE(captured[6].find(": frames 7/"), std::string::npos) << captured[6];
  EXPECT_NE(captured[7].find(": frames 8/"), std::string::npos) << captured[7];
  EXPECT_NE(captured.back().find(": frames " + std::to_string(third.frames) + "/" +
                                 std::to_string(third.frames) + ", "),
            std::string::npos)
      << captured.back();
  EXPECT_NE(captured[10].find(" left"), std::string::npos) << captured[10];
  // Only the missing frames were shown again.
  EXPECT_EQ(parts.outputs->shows - shows_before, int(third.captured));
  const Capture a = read_capture(temp.path() / "whole"), b = read_capture(out);
  EXPECT_EQ(capture_to_json(a), capture_to_json(b));
  for (const CaptureProjector& projector : a.projectors) {
    for (const CaptureFrame& frame : projector.frames) {
      EXPECT_EQ(file_bytes(a.resolve(frame.file)), file_bytes(b.resolve(frame.file))) << frame.file;
    }
  }
  // A finished capture: a further run changes nothing.
  const LiveCaptureReport again = parts.run(out);
  EXPECT_TRUE(again.complete);
  EXPECT_EQ(again.captured, 0u);
  // A frame lost since: capture.json no longer claims a whole capture until it is captured again.
  const fs::path lost = out / a.projectors[1].frames[5].file;
  fs::remove(lost);
  EXPECT_FALSE(parts.run(out, 0).complete);
  EXPECT_FALSE(fs::exists(out / "capture.json"));
  const LiveCaptureReport repaired = parts.run(out);
  EXPECT_TRUE(repaired.complete);
  EXPECT_EQ(repaired.captured, 1u);
  EXPECT_EQ(file_bytes(lost), file_bytes(a.resolve(a.projectors[1].frames[5].file)));
}

TEST(LiveCapture, ResumeAdoptsAFrameRenamedBeforeItsJournalLineAndToleratesATornLine) {
  const test::TempFolder temp;
  FakeRun run(false);
  const fs::path out = temp.path() / "capture";
  ASSERT_FALSE(run.run(out, 5).complete);
  // A kill between the frame's rename and its journal line, in the middle of the next line, and
  // while the next frame's temporary file was being written.
  const fs::path journal = out / kCaptureJournalFile;
  std::string text = file_bytes(journal);
  const std::size_t last = text.rfind("{\"done\"");
  ASSERT_NE(last, std::string::npos);
  text = text.substr(0, last) + "{\"do";
  std::ofstream(journal, std::ios::binary | std::ios::trunc) << text;
  std::ofstream(out / "left" / ".gx5.tmp999-0.png") << "partial";
  const LiveCaptureReport resumed = run.run(out);
  EXPECT_TRUE(resumed.complete);
  EXPECT_EQ(resumed.kept, 5u);
  EXPECT_EQ(resumed.kept + resumed.captured, resumed.frames);
  EXPECT_FALSE(fs::exists(out / "left" / ".gx5.tmp999-0.png"));
  EXPECT_NO_THROW(read_capture(out));
}

TEST(LiveCapture, ADifferentCaptureInTheFolderIsAnInputError) {
  const test::TempFolder temp;
  FakeRun run(false);
  const fs::path out = temp.path() / "capture";
  ASSERT_FALSE(run.run(out, 3).complete);
  try {
    run.run(out, std::nullopt, 2);
    ADD_FAILURE() << "no InputError for a different --average";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("settings.average"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(kCaptureJournalFile), std::string::npos) << e.what();
  }
  FakeRun other(false);
  other.rig.simulation.seed = 7;
  other.camera.emplace(other.rig, other.setup.projectors,
                       [&other](std::size_t p) { return other.outputs->shown[p]; });
  try {
    other.run(out);
    ADD_FAILURE() << "no InputError for another rig";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("identity.camera.fake"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out / "capture.json"));
  // A folder that holds something else is not taken over.
  const fs::path busy = temp.path() / "busy";
  fs::create_directories(busy);
  std::ofstream(busy / "notes.txt") << "mine";
  EXPECT_THROW(run.run(busy), InputError);
  EXPECT_FALSE(fs::exists(busy / kCaptureJournalFile));
}

TEST(LiveCapture, ClippingOnTheWhiteFrameIsAnInputErrorNamingTheProjector) {
  const test::TempFolder temp;
  FakeRun run(false, true);
  const fs::path out = temp.path() / "capture";
  try {
    run.run(out);
    ADD_FAILURE() << "no InputError for a clipped white frame";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("projector 'left'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("exposure"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out / "capture.json"));
  EXPECT_FALSE(fs::exists(out / "left" / "white.png"));
}

TEST(LiveCapture, AveragingExposuresLowersTheNoise) {
  const test::TempFolder temp;
  // The white frame only (the first), with and without noise, 1 and 4 exposures.
  FakeRun clean(false, false, 0.0), single(false), averaged(false);
  clean.run(temp.path() / "clean", 1);
  single.run(temp.path() / "single", 1);
  averaged.run(temp.path() / "averaged", 1, 4);
  const cv::Mat truth = read_luminance(temp.path() / "clean/left/white.png");
  auto rms = [&](const char* name) {
    const cv::Mat difference = read_luminance(temp.path() / name / "left/white.png") - truth;
    return std::sqrt(cv::mean(difference.mul(difference))[0]);
  };
  const double one = rms("single"), four = rms("averaged");
  std::printf("white frame noise RMS: 1 exposure %.5f, 4 exposures %.5f\n", one, four);
  // σ = 1% of full scale per exposure; the mean of 4 independent exposures has half of it.
  EXPECT_NEAR(one, 0.01, 0.001);
  EXPECT_NEAR(four / one, 0.5, 0.05);
}

// A camera with a response curve: every pixel at 0.5 of full scale.
class ConstantCamera : public LiveCamera {
 public:
  glm::ivec2 size() const override { return {320, 256}; }
  cv::Mat grab(const GrabKey&) override { return cv::Mat(256, 320, CV_32F, cv::Scalar(0.5)); }
  nlohmann::json identity() const override { return "constant"; }
};

TEST(LiveCapture, FramesAreWrittenInLinearLight) {
  const test::TempFolder temp;
  FakeRun run(false);
  ConstantCamera camera;
  LiveCaptureOptions options;
  options.out = temp.path() / "capture";
  options.camera_gamma = 2;
  options.stop_after = 1;
  run_live_capture(*run.outputs, camera, run.setup, options);
  const cv::Mat white = read_luminance(options.out / "left/white.png");
  double low = 0, high = 0;
  cv::minMaxLoc(white, &low, &high);
  EXPECT_NEAR(low, 0.25, 1.0 / 65535);  // 0.5^2
  EXPECT_NEAR(high, 0.25, 1.0 / 65535);
}

TEST(VideoDevices, SysfsNodesCarryTheirUsbIdentity) {
  const test::TempFolder temp;
  const fs::path sys = temp.path() / "sys";
  // The layout of sysfs: class/video4linux/videoN links into the USB interface's folder, whose
  // parent is the USB device with idVendor, idProduct, serial, busnum and devpath.
  const fs::path usb_device = sys / "devices/pci0000:00/0000:00:14.0/usb3/3-1/3-1.4";
  const fs::path interface = usb_device / "3-1.4:1.0";
  for (const char* node : {"video0", "video1"}) {
    fs::create_directories(interface / "video4linux" / node);
    std::ofstream(interface / "video4linux" / node / "name") << "USB Camera\n";
    std::ofstream(interface / "video4linux" / node / "index")
        << (std::string(node) == "video0" ? "0\n" : "1\n");
  }
  fs::create_directory_symlink(interface, interface / "video4linux/video0/device");
  fs::create_directory_symlink(interface, interface / "video4linux/video1/device");
  std::ofstream(usb_device / "idVendor") << "046d\n";
  std::ofstream(usb_device / "idProduct") << "085c\n";
  std::ofstream(usb_device / "serial") << "C0FFEE\n";
  std::ofstream(usb_device / "busnum") << "3\n";
  std::ofstream(usb_device / "devpath") << "1.4\n";
  fs::create_directories(sys / "class/video4linux");
  fs::create_directory_symlink(interface / "video4linux/video1", sys / "class/video4linux/video1");
  fs::create_directory_symlink(interface / "video4linux/video0", sys / "class/video4linux/video0");
  // A non-USB node (a PCI capture card).
  fs::create_directories(sys / "class/video4linux/video2");
  std::ofstream(sys / "class/video4linux/video2/name") << "PCI grabber\n";

  const std::vector<VideoDevice> devices = list_video_devices(sys, "/dev");
  ASSERT_EQ(devices.size(), 3u);
  EXPECT_EQ(devices[0].node, fs::path("/dev/video0"));
  ASSERT_TRUE(devices[0].usb);
  EXPECT_EQ(devices[0].index, 0);
  EXPECT_EQ(devices[0].usb->vendor_id, 0x046d);
  EXPECT_EQ(devices[0].usb->product_id, 0x085c);
  EXPECT_EQ(devices[0].usb->serial, "C0FFEE");
  EXPECT_EQ(bus_path(*devices[0].usb), "3-1.4");
  EXPECT_EQ(stable_id(*devices[0].usb), "usb:046d:085c:C0FFEE");
  EXPECT_EQ(devices[0].name, "USB Camera");
  EXPECT_EQ(devices[1].index, 1);
  EXPECT_FALSE(devices[2].usb);
  EXPECT_TRUE(list_video_devices(temp.path() / "nothing").empty());
}

// A stable USB id finds the main capture node of the one camera it names; anything else is a node
// or an index and passes as it is.
TEST(VideoDevices, AStableIdFindsItsCamerasMainNode) {
  const auto camera = [](const char* node, int index, std::uint8_t port, const char* serial) {
    VideoDevice device;
    device.node = node;
    device.index = index;
    device.usb = UsbIdentity{0x046d, 0x085c, 3, {1, port}, serial};
    return device;
  };
  VideoDevice grabber;
  grabber.node = "/dev/video9";
  const std::vector<VideoDevice> devices = {camera("/dev/video0", 0, 4, "A1"),
                                            camera("/dev/video1", 1, 4, "A1"),
                                            camera("/dev/video2", 0, 5, ""), grabber};
  EXPECT_EQ(find_video_node("usb:046d:085c:A1", devices), "/dev/video0");
  EXPECT_EQ(find_video_node("usb:046D:085C@3-1.5", devices), "/dev/video2");
  EXPECT_EQ(find_video_node("/dev/video7", devices), "/dev/video7");
  EXPECT_EQ(find_video_node("2", devices), "2");
  const auto error_of = [&](const std::string& id) {
    try {
      find_video_node(id, devices);
    } catch (const InputError& e) {
      EXPECT_EQ(e.option(), "device") << id;
      return std::string(e.what());
    }
    return std::string("no InputError");
  };
  EXPECT_NE(error_of("usb:046d:085c").find("names /dev/video0, /dev/video2"), std::string::npos);
  EXPECT_NE(error_of("usb:046d:085c:B2")
                .find("(video devices: /dev/video0 = usb:046d:085c:A1, "
                      "/dev/video2 = usb:046d:085c@3-1.5)"),
            std::string::npos);
  EXPECT_NE(error_of("usb:46d:85c").find("expected usb:VVVV:PPPP"), std::string::npos);
  try {
    find_video_node("usb:046d:085c:A1", {});
    ADD_FAILURE() << "no InputError without devices";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("(video devices: none)"), std::string::npos) << e.what();
  }
}

TEST(VideoDevices, AMissingDeviceIsAnInputError) {
  try {
    open_video_camera("/dev/video-none-here", "/dev/video-none-here");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/video-none-here"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace facet::calibration
