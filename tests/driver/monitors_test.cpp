// Where each projector's output goes: by monitor name, then by recorded position and size, then
// the config's missing-monitor policy.
#include "facet/driver/monitors.hpp"

#include <gtest/gtest.h>

#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

using projection_io::DisplayOutput;
using projection_io::MissingMonitor;

const std::vector<MonitorInfo> kMonitors = {
    {0, "DUMMY0", {0, 0}, {1024, 768}, 60},
    {1, "DUMMY1", {1024, 0}, {1024, 768}, 60},
    {2, "HDMI-2", {2048, 0}, {1920, 1080}, 60},
};

DisplayOutput monitor_output(std::string name, std::optional<glm::ivec2> position = {},
                             std::optional<glm::ivec2> size = {}) {
  DisplayOutput output;
  output.kind = DisplayOutput::Kind::monitor;
  output.monitor = std::move(name);
  output.position = position;
  output.size = size;
  return output;
}

TEST(PlaceOutput, MatchesMonitorByName) {
  const OutputPlacement placement =
      place_output(monitor_output("HDMI-2", glm::ivec2(0, 0)), kMonitors, MissingMonitor::error,
                   {800, 600}, "d.json", "projectors[0].output");
  EXPECT_EQ(placement.kind, OutputPlacement::Kind::fullscreen);
  EXPECT_EQ(placement.monitor, 2);
  EXPECT_EQ(placement.rect, glm::ivec4(2048, 0, 1920, 1080));
  EXPECT_EQ(placement.how, "monitor name");
}

TEST(PlaceOutput, FallsBackToPositionAndSize) {
  // After a reboot the connector was renamed; the recorded geometry still finds it.
  const OutputPlacement placement =
      place_output(monitor_output("DP-3", glm::ivec2(1024, 0), glm::ivec2(1024, 768)), kMonitors,
                   MissingMonitor::error, {800, 600}, "d.json", "projectors[1].output");
  EXPECT_EQ(placement.monitor, 1);
  EXPECT_EQ(placement.how, "monitor position and size");
}

TEST(PlaceOutput, MissingMonitorIsAnErrorNamingTheConnectedOnes) {
  try {
    place_output(monitor_output("DP-9"), kMonitors, MissingMonitor::error, {800, 600}, "d.json",
                 "projectors[3].output.monitor");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("d.json"), std::string::npos) << message;
    EXPECT_NE(message.find("projectors[3].output.monitor"), std::string::npos) << message;
    EXPECT_NE(message.find("DP-9"), std::string::npos) << message;
    EXPECT_NE(message.find("DUMMY0, DUMMY1, HDMI-2"), std::string::npos) << message;
  }
}

TEST(PlaceOutput, MissingMonitorBecomesAWindowWhenAllowed) {
  const OutputPlacement recorded =
      place_output(monitor_output("DP-9", glm::ivec2(300, 200), glm::ivec2(640, 480)), kMonitors,
                   MissingMonitor::window, {800, 600}, "d.json", "projectors[0].output");
  EXPECT_EQ(recorded.kind, OutputPlacement::Kind::window);
  EXPECT_EQ(recorded.rect, glm::ivec4(300, 200, 640, 480));
  const OutputPlacement unrecorded =
      place_output(monitor_output("DP-9"), {}, MissingMonitor::window, {800, 600}, "d.json",
                   "projectors[0].output");
  EXPECT_EQ(unrecorded.rect, glm::ivec4(0, 0, 800, 600));
}

TEST(PlaceOutput, WindowOutputsKeepTheirRectangle) {
  DisplayOutput output;
  output.kind = DisplayOutput::Kind::window;
  output.window = {10, 20, 300, 200};
  const OutputPlacement placement =
      place_output(output, {}, MissingMonitor::error, {800, 600}, "d.json", "x");
  EXPECT_EQ(placement.kind, OutputPlacement::Kind::window);
  EXPECT_EQ(placement.rect, glm::ivec4(10, 20, 300, 200));
}

}  // namespace
}  // namespace facet::driver
