// `facet capture --windowed` on a real X server: Xorg with the dummy video driver and two
// monitors, started here. Each projector's patterns go to a fullscreen window on its monitor
// (vsync, swap, read back of the presented buffer); the fake camera must then record the same
// frames, byte for byte, as the headless outputs, also across a stop and a resume. Skipped,
// saying why, only where Xorg cannot start here.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "../calibration/capture_rig.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "support/facet_cli.hpp"
#include "xorg_dummy.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;
using test::run_shell;

class CaptureWindows : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = fs::temp_directory_path() / ("facet_capture_xorg_" + std::to_string(::getpid()));
    fs::remove_all(folder_);
    fs::create_directories(folder_);
    // Another display number than the session tests' (:70–:169), which may run at the same time.
    skip_reason_ =
        server_.start(folder_, ":" + std::to_string(170 + ::getpid() % 100), 1280, 480, 64000);
    display_ = server_.display();
    if (!skip_reason_.empty()) return;
    // Two side-by-side 640×480 monitors DUMMY0 and DUMMY1, larger than the 128×96 projectors:
    // the patterns land 1:1 at each window's top-left corner.
    for (int i = 0; i < 2; ++i) {
      const std::string output = "DUMMY" + std::to_string(i);
      xrandr("--addmode " + output + " 640x480");
      xrandr("--output " + output + " --mode 640x480 --pos " + std::to_string(i * 640) + "x0");
    }
    xrandr("--listmonitors");
  }

  static void TearDownTestSuite() {
    server_.stop();
    std::error_code ignored;
    fs::remove_all(folder_, ignored);
  }

  void SetUp() override {
    if (!skip_reason_.empty()) GTEST_SKIP() << skip_reason_;
  }

  static int xrandr(const std::string& arguments) { return server_.xrandr(arguments); }

  static fs::path write_files(const std::string& name, const std::string& second_monitor) {
    const fs::path dir = folder_ / name;
    fs::create_directories(dir);
    write_rig(dir / "rig.json", test::capture_test_rig());
    nlohmann::json projectors = nlohmann::json::array();
    for (const auto& [projector, monitor] :
         {std::pair{"left", std::string("DUMMY0")}, std::pair{"right", second_monitor}}) {
      projectors.push_back({{"name", projector},
                            {"size", {128, 96}},
                            {"gamma", 2.2},
                            {"output", {{"monitor", monitor}}}});
    }
    std::ofstream(dir / "display.json") << nlohmann::json{{"format", "facet-display/1"},
                                                          {"name", name},
                                                          {"eye", {0, 0, 0}},
                                                          {"projectors", projectors}};
    return dir;
  }

  // Leak checking is off for windowed runs in the sanitizer build, as in the session tests: Mesa's
  // GLX driver is unloaded before LeakSanitizer runs.
  static std::string capture(const fs::path& dir, const std::string& out,
                             const std::string& extra) {
    return "ASAN_OPTIONS=detect_leaks=0 DISPLAY=" + display_ + " " + FACET_CLI +
           " capture --display " + (dir / "display.json").string() +
           " --camera fake:" + (dir / "rig.json").string() + " --out " + (dir / out).string() +
           " --settle-ms 0 --quiet " + extra;
  }

  static inline test::XorgDummyServer server_;
  static inline fs::path folder_;
  static inline std::string display_;
  static inline std::string skip_reason_;
};

TEST_F(CaptureWindows, WindowedFramesEqualHeadlessOnesAcrossAResume) {
  const fs::path dir = write_files("windows", "DUMMY1");
  std::string output;
  ASSERT_EQ(run_shell(capture(dir, "windowed", "--windowed --stop-after 30"), &output), 3)
      << output;
  EXPECT_FALSE(fs::exists(dir / "windowed" / "capture.json"));
  ASSERT_EQ(run_shell(capture(dir, "windowed", "--windowed"), &output), 0) << output;
  ASSERT_EQ(run_shell(capture(dir, "headless", "--headless"), &output), 0) << output;
  std::size_t compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir / "headless")) {
    if (entry.path().extension() != ".png") continue;
    const fs::path relative = fs::relative(entry.path(), dir / "headless");
    EXPECT_EQ(test::slurp(entry.path()), test::slurp(dir / "windowed" / relative)) << relative;
    ++compared;
  }
  EXPECT_EQ(compared, 2u * 38);
}

TEST_F(CaptureWindows, AMissingMonitorIsAClearError) {
  const fs::path dir = write_files("missing", "DP-9");
  std::string output;
  EXPECT_EQ(run_shell(capture(dir, "capture", "--windowed"), &output), 2) << output;
  EXPECT_NE(output.find("DP-9"), std::string::npos) << output;
  EXPECT_NE(output.find("projectors[1].output.monitor"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "capture"));
}

}  // namespace
}  // namespace facet
