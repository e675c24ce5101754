#pragma once
// The files of the live-capture tests (capture_test.cpp, capture_cli_test.cpp): the capture rig
// (capture_rig.hpp) as a rig file and a display.json, in a temporary folder.
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "../calibration/capture_rig.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "support/files.hpp"

namespace facet::test {

// The rig as a file and a display.json naming its two projectors (no warps yet); `command` is the
// `facet capture` command line that captures them with the rig's fake camera into `out`.
struct RigFiles {
  TempFolder temp;
  std::filesystem::path rig = temp.path() / "rig.json";
  std::filesystem::path display = temp.path() / "display.json";

  explicit RigFiles(const Rig& value = capture_test_rig()) {
    write_rig(rig, value);
    nlohmann::json projectors = nlohmann::json::array();
    int x = 0;
    for (const ProjectorModel& p : value.projectors) {
      projectors.push_back({{"name", p.name},
                            {"size", {p.size.x, p.size.y}},
                            {"gamma", 2.2},
                            {"output", {{"window", {x, 0, p.size.x, p.size.y}}}}});
      x += p.size.x;
    }
    std::ofstream(display) << nlohmann::json{
        {"format", "facet-display/1"},
        {"name", "capture-test"},
        {"eye", {0, 0, 0}},
        {"render", {{"method", "naive"}, {"tolerance_px", 0.5}}},
        {"missing_monitor", "window"},
        {"projectors",
         projectors}}.dump(1);
  }

  std::string command(const std::filesystem::path& out, const std::string& extra = "") const {
    return "capture --display " + display.string() + " --camera fake:" + rig.string() + " --out " +
           out.string() + " --settle-ms 0 --quiet " + extra;
  }
};

}  // namespace facet::test
