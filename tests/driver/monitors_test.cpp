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

// Spanning: one borderless window over the outputs' bounding rectangle, each output's viewport at
// its place in it with GL's rows (y up from the bottom). Otherwise a window per output where its
// placement says, with the whole framebuffer as its viewport.
TEST(OutputWindows, OneSpanningWindowOrOneWindowPerOutput) {
  std::vector<OutputPlacement> placements(3);
  placements[0].rect = {100, 50, 1024, 768};
  placements[1].rect = {1124, 50, 1024, 768};
  placements[2].rect = {100, 818, 1024, 768};
  placements[2].kind = OutputPlacement::Kind::fullscreen;
  placements[2].monitor = 2;

  const std::vector<OutputWindow> spanning = output_windows(placements, true);
  ASSERT_EQ(spanning.size(), 1u);
  const OutputWindow& all = spanning[0];
  EXPECT_EQ(all.options.position, glm::ivec2(100, 50));
  EXPECT_EQ(all.options.width, 2048);
  EXPECT_EQ(all.options.height, 1536);
  EXPECT_FALSE(all.options.decorated);
  EXPECT_EQ(all.options.monitor, -1);
  EXPECT_EQ(all.outputs, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(all.viewports, (std::vector<glm::ivec4>{
                               {0, 768, 1024, 768}, {1024, 768, 1024, 768}, {0, 0, 1024, 768}}));

  const std::vector<OutputWindow> each = output_windows(placements, false);
  ASSERT_EQ(each.size(), 3u);
  for (std::size_t i = 0; i < each.size(); ++i) {
    EXPECT_EQ(each[i].outputs, std::vector<std::size_t>{i});
    EXPECT_EQ(each[i].viewports, std::vector<glm::ivec4>{glm::ivec4(0)});
  }
  EXPECT_EQ(each[1].options.position, glm::ivec2(1124, 50));
  EXPECT_EQ(each[1].options.width, 1024);
  EXPECT_EQ(each[1].options.monitor, -1);
  EXPECT_EQ(each[2].options.monitor, 2);
  EXPECT_TRUE(output_windows({}, true).empty());
}

}  // namespace
}  // namespace facet::driver
