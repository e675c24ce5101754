// `facet calibrate` on bad captures: exit status 2 and no output folder.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_folder.hpp"

namespace fs = std::filesystem;

namespace {

int run(const std::string& arguments) {
  const std::string command = std::string(FACET_CLI) + " " + arguments + " 2>/dev/null";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The real procam-board capture, with its images referenced from the shared folder.
nlohmann::json board_capture(const fs::path& into) {
  const fs::path source = fs::path(FACET_SHARED_DATA_DIR) / "captures/procam-board";
  std::ifstream stream(source / "capture.json");
  nlohmann::json capture = nlohmann::json::parse(stream);
  fs::copy_file(source / "camera.cameramodel", into / "camera.cameramodel");
  for (auto& projector : capture["projectors"]) {
    for (auto& frame : projector["frames"]) {
      const fs::path file = source / frame["file"].get<std::string>();
      fs::create_symlink(file, into / file.filename());
      frame["file"] = file.filename().string();
    }
  }
  return capture;
}

void write(const fs::path& path, const nlohmann::json& value) { std::ofstream(path) << value; }

}  // namespace

TEST(CliCalibrate, BadCapturesExitWithStatusTwoAndWriteNothing) {
  const facet::test::TempFolder temp;
  const fs::path capture = temp.path() / "cap", out = temp.path() / "out";
  fs::create_directories(capture);
  const nlohmann::json good = board_capture(capture);

  EXPECT_EQ(run("calibrate " + (temp.path() / "none").string() + " --out " + out.string()), 2);

  nlohmann::json missing_frame = good;
  // The most significant column bit and its inverse.
  missing_frame["projectors"][0]["frames"].erase(1);
  missing_frame["projectors"][0]["frames"].erase(0);
  write(capture / "capture.json", missing_frame);
  EXPECT_EQ(run("calibrate " + capture.string() + " --out " + out.string()), 2);

  nlohmann::json missing_model = good;
  missing_model["camera"]["model"] = "nowhere.cameramodel";
  write(capture / "capture.json", missing_model);
  EXPECT_EQ(run("calibrate " + capture.string() + " --out " + out.string()), 2);

  nlohmann::json unreadable = good;
  std::ofstream(capture / "broken.png") << "not a png";
  unreadable["projectors"][0]["frames"][0]["file"] = "broken.png";
  write(capture / "capture.json", unreadable);
  EXPECT_EQ(run("calibrate " + capture.string() + " --out " + out.string()), 2);

  write(capture / "capture.json", good);
  EXPECT_EQ(run("calibrate " + capture.string() + " --out " + out.string() + " --grid 1x5"), 2);

  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(temp.path())) {
    EXPECT_TRUE(entry.path() == capture) << "left behind: " << entry.path();
  }
}
