// The windowed session on a real X server: Xorg with the dummy video driver and three monitors,
// started by the fixture. Each projector's window must land on its monitor and show exactly its
// output's pixels; unplugging a monitor mid-session must not crash it; a missing monitor is a
// clear error; SIGINT closes the windows with exit 130 and no report. Skipped, saying why, only
// where Xorg cannot start here.
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

#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "support/facet_cli.hpp"
#include "xorg_dummy.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;
using test::run_shell;

constexpr int kMonitors = 3;
constexpr int kWidth = 640, kHeight = 480;

class XorgDummy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = fs::temp_directory_path() / ("facet_xorg_" + std::to_string(::getpid()));
    fs::remove_all(folder_);
    fs::create_directories(folder_);
    skip_reason_ =
        server_.start(folder_, ":" + std::to_string(70 + ::getpid() % 100), 4096, 2048, 256000);
    display_ = server_.display();
  }

  static void TearDownTestSuite() { server_.stop(); }

  void SetUp() override {
    if (!skip_reason_.empty()) GTEST_SKIP() << skip_reason_;
    // Three side-by-side monitors DUMMY0..2, re-made for every test (one may have been unplugged).
    const std::string mode = std::to_string(kWidth) + "x" + std::to_string(kHeight);
    for (int i = 0; i < kMonitors; ++i) {
      const std::string output = "DUMMY" + std::to_string(i);
      xrandr("--addmode " + output + " " + mode);
      ASSERT_EQ(xrandr("--output " + output + " --mode " + mode + " --pos " +
                       std::to_string(i * kWidth) + "x0"),
                0)
          << "xrandr could not place " << output;
    }
    // GLFW reads the server's cached RandR state, which the dummy driver refreshes only when a
    // client asks for monitors; then wait until facet itself sees the layout.
    xrandr("--listmonitors");
    const std::string list = "DISPLAY=" + display_ + " " + FACET_CLI + " run --monitors";
    int seen = 0;
    for (int attempt = 0; attempt < 50 && seen != kMonitors; ++attempt) {
      seen = 0;
      if (FILE* monitors = ::popen(list.c_str(), "r")) {
        char line[256];
        while (std::fgets(line, sizeof line, monitors))
          seen += std::string(line).starts_with("DUMMY");
        ::pclose(monitors);
      }
      if (seen != kMonitors) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ASSERT_EQ(seen, kMonitors) << "facet run --monitors does not list the three monitors";
  }

  static int xrandr(const std::string& arguments) { return server_.xrandr(arguments); }

  // display.json with one projector per monitor, each a perspective view 60° apart.
  static fs::path write_display(const std::string& name, const std::string& missing_name = {}) {
    const fs::path dir = folder_ / name;
    fs::create_directories(dir);
    projection_io::DisplayConfig config;
    config.name = name;
    for (int i = 0; i < kMonitors; ++i) {
      const double yaw = glm::radians(60.0 * (i - 1));
      const glm::dmat3 R_eye_base(glm::dvec3(std::cos(yaw), 0, -std::sin(yaw)), glm::dvec3(0, 1, 0),
                                  glm::dvec3(std::sin(yaw), 0, std::cos(yaw)));
      const std::string projector_name = "p" + std::to_string(i);
      write_warp((dir / (projector_name + ".warp.exr")).string(),
                 Warp::analytic(BaseProjection::perspective(-0.58, 0.58, 0.43, -0.43),
                                {kWidth, kHeight}, {2, 2}, R_eye_base));
      projection_io::DisplayProjector projector;
      projector.name = projector_name;
      projector.size = {kWidth, kHeight};
      projector.warp = projector_name + ".warp.exr";
      projector.output.kind = projection_io::DisplayOutput::Kind::monitor;
      projector.output.monitor =
          (i == 2 && !missing_name.empty()) ? missing_name : "DUMMY" + std::to_string(i);
      config.projectors.push_back(projector);
    }
    config.render.tolerance_px = 0.5;
    const fs::path path = dir / "display.json";
    projection_io::write_display_config(config, path);
    return path;
  }

  // Leak checking is off for windowed runs in the sanitizer build: Mesa's GLX driver is unloaded
  // when GLFW closes the display, before LeakSanitizer runs, so the driver's own allocations
  // show as leaks from an unknown module that no suppression can name. The same session code is
  // leak-checked headless (driver_output_tests, RunCli).
  static std::string run_command(const fs::path& display, const std::string& extra) {
    return "ASAN_OPTIONS=detect_leaks=0 DISPLAY=" + display_ + " " + FACET_CLI + " run " +
           display.string() + " --no-path " + extra;
  }

  static inline test::XorgDummyServer server_;
  static inline fs::path folder_;
  static inline std::string display_;
  static inline std::string skip_reason_;
};

TEST_F(XorgDummy, WindowsLandOnTheirMonitorsAndShowTheirOutputs) {
  const fs::path display = write_display("placed");
  const fs::path report_path = folder_ / "placed_report.json";
  ASSERT_EQ(run_shell(run_command(display, "--frames 3 --report " + report_path.string())), 0);
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(report_path));
  ASSERT_EQ(report["windows"].size(), std::size_t(kMonitors));
  for (int i = 0; i < kMonitors; ++i) {
    const nlohmann::json& window = report["windows"][i];
    SCOPED_TRACE("window " + std::to_string(i));
    EXPECT_EQ(window["position"][0], i * kWidth);
    EXPECT_EQ(window["position"][1], 0);
    EXPECT_EQ(window["framebuffer"][0], kWidth);
    EXPECT_EQ(window["framebuffer"][1], kHeight);
    const nlohmann::json& output = window["outputs"][0];
    EXPECT_EQ(output["monitor"], "DUMMY" + std::to_string(i));
    EXPECT_EQ(output["how"], "monitor name");
    EXPECT_EQ(output["mismatched_bytes"], 0) << "the window does not show its output exactly";
  }
  EXPECT_GT(report["last_frame"]["replicas"].get<double>(), 0.0);
}

// A depth image at @lod in a windowed run: the camera path moves the eye (a turn a minute about
// the point looked at, 6° in 60 frames, about 1.1 m here), and the session rebuilds the image's
// mesh where the levels change, as headless runs do. The report counts those frames.
TEST_F(XorgDummy, ADepthImageAtLodIsRebuiltAsThePathMovesTheEye) {
  const fs::path display = write_display("depth_lod");
  const fs::path image = folder_ / "depth_lod" / "city.exr";
  ASSERT_EQ(run_shell(std::string(FACET_CLI) + " depth-image --scene builtin:city --size 128x64 " +
                      "--out " + image.string() + " > /dev/null"),
            0);
  const fs::path report_path = folder_ / "depth_lod_report.json";
  const std::string command = "ASAN_OPTIONS=detect_leaks=0 DISPLAY=" + display_ + " " + FACET_CLI +
                              " run " + display.string() + " --scene depth:" + image.string() +
                              "@lod=0.3 --eye 0,4.7,-2 --look-at 0,1.7,-12 --frames 60 --report " +
                              report_path.string();
  ASSERT_EQ(run_shell(command), 0);
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(report_path));
  EXPECT_GE(report["scene_rebuilds"].get<int>(), 1) << report.dump();
  EXPECT_LT(report["scene_rebuilds"].get<int>(), 60) << report.dump();
  EXPECT_GT(report["last_frame"]["replicas"].get<double>(), 0.0);
}

// --span: one borderless window over all three monitors, each output read back from its own
// viewport byte for byte.
TEST_F(XorgDummy, OneSpanningWindowShowsEveryOutputInItsPlace) {
  const fs::path display = write_display("spanned");
  const fs::path report_path = folder_ / "spanned_report.json";
  ASSERT_EQ(run_shell(run_command(display, "--span --frames 3 --report " + report_path.string())),
            0);
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(report_path));
  ASSERT_EQ(report["windows"].size(), 1u);
  const nlohmann::json& window = report["windows"][0];
  EXPECT_EQ(window["position"][0], 0);
  EXPECT_EQ(window["position"][1], 0);
  EXPECT_EQ(window["framebuffer"][0], kMonitors * kWidth);
  EXPECT_EQ(window["framebuffer"][1], kHeight);
  ASSERT_EQ(window["outputs"].size(), std::size_t(kMonitors));
  for (int i = 0; i < kMonitors; ++i) {
    const nlohmann::json& output = window["outputs"][i];
    SCOPED_TRACE("output " + std::to_string(i));
    EXPECT_EQ(output["monitor"], "DUMMY" + std::to_string(i));
    EXPECT_EQ(output["mismatched_bytes"], 0) << "the viewport does not show its output exactly";
  }
}

TEST_F(XorgDummy, SurvivesAMonitorUnpluggedDuringTheSession) {
  const fs::path display = write_display("unplug");
  const fs::path report_path = folder_ / "unplug_report.json";
  FILE* session = ::popen(
      (run_command(display, "--frames 20 --report " + report_path.string()) + " 2>&1").c_str(),
      "r");
  ASSERT_NE(session, nullptr);
  // Unplug once the windows are open (the runner says so on its output).
  std::string output;
  char line[512];
  bool unplugged = false;
  while (std::fgets(line, sizeof line, session)) {
    output += line;
    if (!unplugged && output.find("windows open") != std::string::npos) {
      EXPECT_EQ(xrandr("--output DUMMY2 --off"), 0);
      unplugged = true;
    }
  }
  const int status = ::pclose(session);
  EXPECT_TRUE(unplugged) << output;
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(report_path));
  EXPECT_NE(report["monitor_events"].dump().find("DUMMY2 disconnected"), std::string::npos)
      << report["monitor_events"].dump() << "\n"
      << output;
  // And the operator was told, through the CLI's log sink.
  EXPECT_NE(output.find("facet run: monitor DUMMY2 disconnected"), std::string::npos) << output;
}

TEST_F(XorgDummy, AMissingMonitorIsAClearError) {
  const fs::path display = write_display("missing", "DP-9");
  const std::string log = (folder_ / "missing.log").string();
  EXPECT_EQ(run_shell(run_command(display, "--frames 1") + " > " + log + " 2>&1"), 2);
  std::ifstream in(log);
  const std::string message((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(message.find("DP-9"), std::string::npos) << message;
  EXPECT_NE(message.find("projectors[2].output.monitor"), std::string::npos) << message;
}

TEST_F(XorgDummy, SigintClosesTheWindowsWithoutAReport) {
  const fs::path display = write_display("sigint");
  const fs::path report_path = folder_ / "sigint_report.json";
  // The shell prints its process id, then becomes facet (exec): that id is facet's.
  FILE* session =
      ::popen(("echo $$; exec env " +
               run_command(display, "--frames 1000000 --report " + report_path.string()) + " 2>&1")
                  .c_str(),
              "r");
  ASSERT_NE(session, nullptr);
  std::string output;
  char line[512];
  pid_t facet = 0;
  bool interrupted = false;
  while (std::fgets(line, sizeof line, session)) {
    if (facet == 0) {
      facet = pid_t(std::atol(line));
      continue;
    }
    output += line;
    if (!interrupted && output.find("windows open") != std::string::npos) {
      ::kill(facet, SIGINT);
      interrupted = true;
    }
  }
  const int status = ::pclose(session);
  EXPECT_TRUE(interrupted) << output;
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 130) << output;
  EXPECT_NE(output.find("facet run: interrupted by SIGINT: stopped after "), std::string::npos)
      << output;
  EXPECT_NE(output.find("no report written to " + report_path.string()), std::string::npos)
      << output;
  EXPECT_FALSE(fs::exists(report_path));
}

}  // namespace
}  // namespace facet
