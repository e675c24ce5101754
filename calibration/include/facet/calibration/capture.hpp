#pragma once
// Recorded capture folders (FORMATS.md §1): capture.json and its images, as plain values.
#include <filesystem>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/calibration/patterns.hpp"
#include "facet/projection/screen.hpp"

namespace facet::calibration {

inline constexpr const char* kCaptureFormat = "facet-capture/1";

// The display surface in the eye frame, metres (facet/projection/screen.hpp).
using Screen = facet::Screen;

struct CaptureCamera {
  std::filesystem::path model;  // mrcal .cameramodel, relative to the capture folder
  // Camera-frame vectors into the eye frame; the default looks down the eye's −z.
  glm::dmat3 R_eye_camera{glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1)};
  glm::dvec3 t_eye_camera{0.0};  // camera position in the eye frame, metres
  // Camera response: an image value e means light proportional to e^gamma. 1 for linear images.
  double gamma = 1;

  bool operator==(const CaptureCamera&) const = default;
};

struct CaptureFrame {
  std::filesystem::path file;  // relative to the capture folder
  Pattern pattern;

  bool operator==(const CaptureFrame&) const = default;
};

struct CaptureProjector {
  std::string name;       // letters, digits, '_', '-', '.'; unique in the capture
  glm::ivec2 size{0, 0};  // W, H in projector pixels
  double gamma = 1;       // pattern value v emits light proportional to v^gamma
  std::vector<CaptureFrame> frames;

  bool operator==(const CaptureProjector&) const = default;
};

struct Capture {
  // The folder that relative paths resolve against (the folder of capture.json). Not stored in
  // the file.
  std::filesystem::path folder;
  CaptureCamera camera;
  std::optional<Screen> screen;
  std::vector<CaptureProjector> projectors;
  std::optional<std::filesystem::path> truth;  // relative folder of the ground truth (§5)
  // Relative path of the display.json the capture ran with (`facet capture --display` keeps a
  // copy): facet calibrate writes that display back, its warps and blends filled in.
  std::optional<std::filesystem::path> display;

  bool operator==(const Capture&) const = default;

  std::filesystem::path resolve(const std::filesystem::path& relative) const {
    return folder / relative;
  }
};

// Reads and validates capture.json (`path` may also be its folder). Checks every field of §1 and
// that the camera model file exists; it does not open images (see check_capture_images).
// Throws InputError(file, field, expected) on the first problem, unknown fields included (keys
// starting with "x-" are free for notes).
Capture read_capture(const std::filesystem::path& path);

// Reads a camera pose file (`facet capture --camera-pose`): a JSON object with an optional
// `R_eye_camera` (rows) and an optional `t_eye_camera` (metres), which replace those of `camera`.
// Unknown fields are refused as in read_capture; validate_capture checks the rotation.
void read_camera_pose(const std::filesystem::path& path, CaptureCamera& camera);

// Validates a Capture as read_capture would (source names the file in errors).
void validate_capture(const Capture& capture, const std::string& source);

nlohmann::json capture_to_json(const Capture& capture);
// Writes capture.json atomically; `capture.folder` is not used. Validates first (InputError).
void write_capture(const Capture& capture, const std::filesystem::path& capture_json);

// Opens every frame header of one projector: every image must be readable and all must have the
// same size, which is returned (width, height in camera pixels). Throws InputError naming the
// frame's file.
glm::ivec2 check_capture_images(const Capture& capture, std::size_t projector_index);

// Loads one frame as CV_32F linear light: read_luminance, then e^camera.gamma when the camera has
// a response curve.
cv::Mat load_frame(const Capture& capture, const CaptureFrame& frame);

}  // namespace facet::calibration
