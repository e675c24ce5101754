#include "facet/calibration/capture.hpp"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "facet/calibration/image_io.hpp"
#include "facet/projection/errors.hpp"
#include "support/files.hpp"

namespace fc = facet::calibration;

namespace {

const std::filesystem::path kProcamBoard =
    std::filesystem::path(FACET_SHARED_DATA_DIR) / "captures/procam-board";

// A small valid capture folder with a camera model file and two tiny images.
fc::Capture small_capture(const std::filesystem::path& folder) {
  std::filesystem::copy_file(kProcamBoard / "camera.cameramodel", folder / "camera.cameramodel");
  fc::Capture capture;
  capture.folder = folder;
  capture.camera.model = "camera.cameramodel";
  fc::CaptureProjector projector;
  projector.name = "p0";
  projector.size = {4, 2};
  projector.gamma = 2.2;
  for (const auto& pattern : fc::standard_patterns(projector.size)) {
    projector.frames.push_back({fc::default_file_name(pattern), pattern});
    fc::write_grey_image(folder / fc::default_file_name(pattern), cv::Mat(3, 5, CV_32F, 0.25f));
  }
  capture.projectors.push_back(projector);
  return capture;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Rewrites one field of the capture's JSON and expects read_capture to name it.
void expect_rejected(const std::filesystem::path& folder, const nlohmann::json& json,
                     const std::string& field) {
  write_text(folder / "capture.json", json.dump());
  try {
    fc::read_capture(folder / "capture.json");
    ADD_FAILURE() << "accepted a capture with a bad " << field;
  } catch (const facet::InputError& error) {
    EXPECT_EQ(error.field(), field) << error.what();
    EXPECT_EQ(error.source(), (folder / "capture.json").string());
  }
}

}  // namespace

TEST(Capture, ReadsTheRealProcamBoardCapture) {
  const fc::Capture capture = fc::read_capture(kProcamBoard);
  EXPECT_EQ(capture.camera.model, "camera.cameramodel");
  EXPECT_EQ(capture.camera.R_eye_camera[1][1], -1.0);
  EXPECT_FALSE(capture.screen.has_value());
  ASSERT_EQ(capture.projectors.size(), 1u);
  const auto& projector = capture.projectors[0];
  EXPECT_EQ(projector.size, glm::ivec2(1024, 768));
  EXPECT_EQ(projector.frames.size(), 42u);
  EXPECT_EQ(projector.frames[1].pattern, fc::Pattern::gray(fc::Axis::x, 9, true));
  EXPECT_EQ(projector.frames[41].pattern, fc::Pattern::black());
  EXPECT_EQ(fc::check_capture_images(capture, 0), glm::ivec2(1280, 1024));
  const cv::Mat white = fc::load_frame(capture, projector.frames[40]);
  EXPECT_EQ(white.type(), CV_32F);
  double low = 0, high = 0;
  cv::minMaxLoc(white, &low, &high);
  EXPECT_GE(low, 0.0);
  EXPECT_LE(high, 1.0);
  EXPECT_GT(high, 0.5);
}

TEST(Capture, WriteThenReadGivesTheSameCapture) {
  const facet::test::TempFolder temp;
  fc::Capture capture = small_capture(temp.path());
  capture.camera.t_eye_camera = {0.1, -0.2, 0.3};
  capture.camera.gamma = 1.8;
  fc::Screen screen;
  screen.type = fc::Screen::Type::cylinder;
  screen.center = {0, 1, 0};
  screen.axis = {0, 1, 0};
  screen.radius = 3.5;
  capture.screen = screen;
  capture.truth = "truth";
  capture.projectors[0].frames.push_back({"px1.png", fc::Pattern::phase(fc::Axis::x, 2.5, 1, 3)});
  fc::write_capture(capture, temp.path() / "capture.json");
  const fc::Capture read = fc::read_capture(temp.path());
  EXPECT_EQ(read, capture);
}

TEST(Capture, DefaultsApply) {
  const facet::test::TempFolder temp;
  small_capture(temp.path());
  write_text(temp.path() / "capture.json", R"({"format": "facet-capture/1",
    "camera": {"model": "camera.cameramodel"}, "x-extra": 1,
    "projectors": [{"name": "p", "size": [4, 2], "frames": [{"file": "white.png",
                    "pattern": {"type": "white"}}]}]})");
  const fc::Capture capture = fc::read_capture(temp.path() / "capture.json");
  EXPECT_EQ(capture.camera.R_eye_camera, fc::CaptureCamera{}.R_eye_camera);
  EXPECT_EQ(capture.camera.R_eye_camera[2][2], -1.0);
  EXPECT_EQ(capture.camera.t_eye_camera, glm::dvec3(0.0));
  EXPECT_EQ(capture.camera.gamma, 1.0);
  EXPECT_EQ(capture.projectors[0].gamma, 1.0);
  EXPECT_FALSE(capture.truth.has_value());
}

TEST(Capture, BadFieldsAreNamed) {
  const facet::test::TempFolder temp;
  const nlohmann::json good = fc::capture_to_json(small_capture(temp.path()));
  auto with = [&](const nlohmann::json::json_pointer& pointer, const nlohmann::json& value) {
    nlohmann::json json = good;
    json[pointer] = value;
    return json;
  };
  using ptr = nlohmann::json::json_pointer;
  expect_rejected(temp.path(), with(ptr("/format"), "facet-capture/2"), "format");
  expect_rejected(temp.path(), with(ptr("/camera/model"), "missing.cameramodel"), "camera.model");
  expect_rejected(temp.path(), with(ptr("/camera/R_eye_camera/0/0"), 2.0), "camera.R_eye_camera");
  expect_rejected(temp.path(), with(ptr("/camera/t_eye_camera"), nlohmann::json{0, 0, 1}),
                  "screen");
  expect_rejected(temp.path(), with(ptr("/screen"), {{"type", "sphere"}, {"center", {0, 0, 0}}}),
                  "screen.radius");
  expect_rejected(temp.path(), with(ptr("/screen"), {{"type", "torus"}}), "screen.type");
  expect_rejected(temp.path(), with(ptr("/projectors/0/gamma"), -2.2), "projectors[0].gamma");
  expect_rejected(temp.path(), with(ptr("/projectors/0/size"), {4}), "projectors[0].size");
  expect_rejected(temp.path(), with(ptr("/projectors/0/name"), "a/b"), "projectors[0].name");
  expect_rejected(temp.path(), with(ptr("/projectors/0/frames/3/pattern/bit"), 2),
                  "projectors[0].frames[3].pattern.bit");
  expect_rejected(temp.path(), with(ptr("/projectors/0/frames/3/pattern/inverted"), false),
                  "projectors[0].frames[3].pattern");  // the same pattern as frames[2]
  expect_rejected(temp.path(), with(ptr("/projectors/0/frames/0/file"), "/abs/white.png"),
                  "projectors[0].frames[0].file");
  expect_rejected(temp.path(), with(ptr("/projectors"), nlohmann::json::array()), "projectors");
  nlohmann::json two = good;
  two["projectors"].push_back(two["projectors"][0]);
  expect_rejected(temp.path(), two, "projectors[1].name");

  // Unknown keys, by their path, with the nearest known key; "x-" keys are free.
  expect_rejected(temp.path(), with(ptr("/extra"), 1), "extra");
  expect_rejected(temp.path(), with(ptr("/camera/gama"), 1.0), "camera.gama");
  expect_rejected(temp.path(), with(ptr("/projectors/0/frames/2/pattern/invert"), true),
                  "projectors[0].frames[2].pattern.invert");
  write_text(temp.path() / "capture.json",
             with(ptr("/projectors/0/frames/2/pattern/invert"), true).dump());
  try {
    fc::read_capture(temp.path());
  } catch (const facet::InputError& error) {
    EXPECT_NE(std::string(error.what()).find("unknown field 'invert'; did you mean 'inverted'?"),
              std::string::npos)
        << error.what();
  }
  nlohmann::json notes = good;
  notes["x-operator"] = "kim";
  notes["camera"]["x-lens"] = "8 mm";
  notes["projectors"][0]["frames"][1]["pattern"]["x-note"] = "dim";
  write_text(temp.path() / "capture.json", notes.dump());
  EXPECT_NO_THROW(fc::read_capture(temp.path()));

  write_text(temp.path() / "capture.json", "{\"format\": ");
  EXPECT_THROW(fc::read_capture(temp.path()), facet::InputError);
  EXPECT_THROW(fc::read_capture(temp.path() / "nothing.json"), facet::InputError);
}

TEST(Capture, CameraPoseFilesReadLikeCaptureJson) {
  const facet::test::TempFolder temp;
  const std::filesystem::path pose = temp.path() / "pose.json";
  write_text(pose, R"({"R_eye_camera": [[1, 0, 0], [0, -1, 0], [0, 0, -1]],
                       "t_eye_camera": [0.5, 0, 0], "x-measured": "2026-11-30"})");
  fc::CaptureCamera camera;
  camera.R_eye_camera = glm::dmat3(1.0);
  fc::read_camera_pose(pose, camera);
  EXPECT_EQ(camera.R_eye_camera[1][1], -1.0);
  EXPECT_EQ(camera.t_eye_camera, glm::dvec3(0.5, 0, 0));

  auto field_of = [&](const std::string& text) -> std::string {
    write_text(pose, text);
    try {
      fc::read_camera_pose(pose, camera);
    } catch (const facet::InputError& error) {
      EXPECT_EQ(error.source(), pose.string());
      return error.field();
    }
    return "accepted";
  };
  EXPECT_EQ(field_of(R"({"t_eye_camra": [0, 0, 0]})"), "t_eye_camra");
  EXPECT_EQ(field_of(R"({"R_eye_camera": [[1, 0, 0], [0, 1, "0"], [0, 0, 1]]})"),
            "R_eye_camera[1][2]");
  EXPECT_EQ(field_of(R"({"t_eye_camera": [0, 0]})"), "t_eye_camera");
  EXPECT_EQ(field_of("[]"), "");
}

TEST(Capture, UnreadableOrMismatchedImagesAreNamed) {
  const facet::test::TempFolder temp;
  fc::Capture capture = small_capture(temp.path());
  EXPECT_EQ(fc::check_capture_images(capture, 0), glm::ivec2(5, 3));

  fc::write_grey_image(temp.path() / "gx1.png", cv::Mat(3, 6, CV_32F, 0.5f));
  try {
    fc::check_capture_images(capture, 0);
    ADD_FAILURE() << "accepted images of two sizes";
  } catch (const facet::InputError& error) {
    EXPECT_EQ(error.source(), (temp.path() / "gx1.png").string());
    EXPECT_NE(std::string(error.what()).find("5x3"), std::string::npos) << error.what();
  }

  write_text(temp.path() / "gx1.png", "not a png");
  EXPECT_THROW(fc::check_capture_images(capture, 0), facet::InputError);
  std::filesystem::remove(temp.path() / "gx1.png");
  EXPECT_THROW(fc::check_capture_images(capture, 0), facet::InputError);
  EXPECT_THROW(fc::load_frame(capture, capture.projectors[0].frames[2]), facet::InputError);
}

TEST(Capture, ImagesAreReadAsLinearLuminance) {
  const facet::test::TempFolder temp;
  // 16-bit RGBA with a partly transparent alpha: the colour must come back unchanged, not
  // multiplied by alpha.
  const std::uint16_t rgba[4] = {65535, 32768, 0, 16384};
  OIIO::ImageSpec spec(1, 1, 4, OIIO::TypeDesc::UINT16);
  spec.attribute("oiio:UnassociatedAlpha", 1);
  const std::string rgba_path = (temp.path() / "rgba16.png").string();
  auto output = OIIO::ImageOutput::create(rgba_path);
  ASSERT_TRUE(output && output->open(rgba_path, spec));
  ASSERT_TRUE(output->write_image(OIIO::TypeDesc::UINT16, rgba));
  output->close();
  const float expected = float(0.2126 + 0.7152 * 32768.0 / 65535.0);
  EXPECT_NEAR(fc::read_luminance(rgba_path).at<float>(0, 0), expected, 1e-6f);

  cv::Mat grey(2, 3, CV_32F, 0.5f);
  fc::write_grey_image(temp.path() / "g16.png", grey, 16);
  fc::write_grey_image(temp.path() / "g.exr", grey);
  EXPECT_NEAR(fc::read_luminance(temp.path() / "g16.png").at<float>(1, 2), 0.5f, 0.5f / 65535);
  EXPECT_EQ(fc::read_luminance(temp.path() / "g.exr").at<float>(1, 2), 0.5f);
}
