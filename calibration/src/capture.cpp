#include "facet/calibration/capture.hpp"

#include <cmath>
#include <fstream>
#include <set>

#include "facet/calibration/image_io.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "json_fields.hpp"

namespace facet::calibration {
namespace {

using json_fields::FieldPath;
using json_fields::Fields;
using json_fields::Json;

bool valid_name(const std::string& name) {
  if (name.empty() || name.front() == '.' || name.size() > 128) return false;
  for (char ch : name) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '_' || ch == '-' || ch == '.';
    if (!ok) return false;
  }
  return true;
}

void check_relative_path(const std::filesystem::path& path, const FieldPath& at) {
  if (path.empty() || path.is_absolute()) at.fail("a file path relative to the capture folder");
}

void check_rotation(const glm::dmat3& R, const FieldPath& at) {
  const glm::dmat3 error = glm::transpose(R) * R - glm::dmat3(1.0);
  double worst = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) worst = std::max(worst, std::abs(error[i][j]));
  }
  if (worst > 1e-6 || glm::determinant(R) <= 0) {
    at.fail("a rotation matrix (orthonormal within 1e-6, determinant +1)");
  }
}

CaptureProjector projector_from_json(const Json& object, const FieldPath& at) {
  using namespace json_fields;
  Fields fields(object, at);
  CaptureProjector projector;
  projector.name = to_string(fields.required("name", "a name"), at["name"]);
  const std::string expected_size = "[width, height] in projector pixels";
  projector.size = to_ivec2(fields.required("size", expected_size), at["size"], expected_size);
  if (const Json* gamma = fields.present("gamma")) projector.gamma = to_number(*gamma, at["gamma"]);
  const Json& frames = fields.required("frames", "a list of frames");
  if (!frames.is_array()) at["frames"].fail("a list of frames", frames);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const FieldPath frame_at = at["frames"][k];
    Fields frame_fields(frames[k], frame_at);
    CaptureFrame frame;
    frame.file = to_string(frame_fields.required("file", "an image file name"), frame_at["file"]);
    frame.pattern = pattern_from_json(frame_fields.required("pattern", "a pattern object"),
                                      at.source(), frame_at["pattern"].field());
    frame_fields.finish();
    projector.frames.push_back(std::move(frame));
  }
  fields.finish();
  return projector;
}

}  // namespace

void validate_capture(const Capture& capture, const std::string& source) {
  const FieldPath root(source);
  check_relative_path(capture.camera.model, root["camera"]["model"]);
  check_rotation(capture.camera.R_eye_camera, root["camera"]["R_eye_camera"]);
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(capture.camera.t_eye_camera[i])) {
      root["camera"]["t_eye_camera"].fail("a list of 3 finite numbers");
    }
  }
  if (!(capture.camera.gamma > 0) || !std::isfinite(capture.camera.gamma)) {
    root["camera"]["gamma"].fail("a positive number");
  }
  if (capture.camera.t_eye_camera != glm::dvec3(0.0) && !capture.screen) {
    root["screen"].fail(
        "a screen description: the camera is not at the eye point (t_eye_camera is not 0), so "
        "directions from the eye need the surface");
  }
  if (capture.screen) json_fields::check_screen(*capture.screen, root["screen"]);
  if (capture.projectors.empty()) root["projectors"].fail("a non-empty list of projectors");
  std::set<std::string> names;
  for (std::size_t p = 0; p < capture.projectors.size(); ++p) {
    const CaptureProjector& projector = capture.projectors[p];
    const FieldPath at = root["projectors"][p];
    if (!valid_name(projector.name)) {
      at["name"].fail(
          "a name of letters, digits, '_', '-' and '.' that does not start with '.' (it names "
          "files)");
    }
    if (!names.insert(projector.name).second) {
      at["name"].fail("a name no other projector has, but '" + projector.name + "' repeats");
    }
    if (projector.size.x < 1 || projector.size.y < 1 || projector.size.x > 65536 ||
        projector.size.y > 65536) {
      at["size"].fail("[width, height], each from 1 to 65536");
    }
    if (!(projector.gamma > 0) || !std::isfinite(projector.gamma)) {
      at["gamma"].fail("a positive number");
    }
    if (projector.frames.empty()) at["frames"].fail("a non-empty list of frames");
    std::set<std::string> seen;
    for (std::size_t k = 0; k < projector.frames.size(); ++k) {
      const CaptureFrame& frame = projector.frames[k];
      const FieldPath frame_at = at["frames"][k];
      check_relative_path(frame.file, frame_at["file"]);
      const Pattern& pattern = frame.pattern;
      if (pattern.type == PatternType::gray) {
        const int axis_size = pattern.axis == Axis::x ? projector.size.x : projector.size.y;
        const int bits = gray_bits(axis_size);
        if (pattern.bit < 0 || pattern.bit >= bits) {
          frame_at["pattern"]["bit"].fail("a bit from 0 to " + std::to_string(bits - 1) +
                                          " (ceil(log2(" + std::to_string(axis_size) +
                                          ")) bits identify every pixel of this axis)");
        }
      }
      if (pattern.type == PatternType::phase &&
          (!(pattern.period > 0) || pattern.steps < 3 || pattern.step < 0 ||
           pattern.step >= pattern.steps)) {
        frame_at["pattern"].fail("a phase pattern with period > 0, steps >= 3, 0 <= step < steps");
      }
      if (!seen.insert(pattern_to_json(pattern).dump()).second) {
        frame_at["pattern"].fail("a pattern that no other frame of this projector shows");
      }
    }
  }
  if (capture.truth) check_relative_path(*capture.truth, root["truth"]);
  if (capture.display) check_relative_path(*capture.display, root["display"]);
}

Capture read_capture(const std::filesystem::path& path) {
  const Activity activity("reading the capture " + path.string());
  using namespace json_fields;
  std::error_code error;
  const std::filesystem::path file =
      std::filesystem::is_directory(path, error) ? path / "capture.json" : path;
  const std::string source = file.string();
  const Json root = parse_file(file);
  const FieldPath at(source);
  Fields fields(root, at);
  const std::string expected_format = std::string("\"") + kCaptureFormat + "\"";
  const Json& format = fields.required("format", expected_format);
  if (!format.is_string() || format.get<std::string>() != kCaptureFormat) {
    at["format"].fail(expected_format, format);
  }

  Capture capture;
  capture.folder = file.parent_path();
  const FieldPath camera_at = at["camera"];
  Fields camera(fields.required("camera", "a camera object"), camera_at);
  capture.camera.model =
      to_string(camera.required("model", "an mrcal .cameramodel file"), camera_at["model"]);
  if (const Json* R = camera.present("R_eye_camera")) {
    capture.camera.R_eye_camera = to_dmat3(*R, camera_at["R_eye_camera"]);
  }
  if (const Json* t = camera.present("t_eye_camera")) {
    capture.camera.t_eye_camera = to_dvec3(*t, camera_at["t_eye_camera"]);
  }
  if (const Json* gamma = camera.present("gamma")) {
    capture.camera.gamma = to_number(*gamma, camera_at["gamma"]);
  }
  camera.finish();
  if (const Json* screen = fields.optional("screen")) {
    capture.screen = json_fields::to_screen(*screen, at["screen"]);
  }
  const Json& projectors = fields.required("projectors", "a list of projectors");
  if (!projectors.is_array()) at["projectors"].fail("a list of projectors", projectors);
  for (std::size_t p = 0; p < projectors.size(); ++p) {
    capture.projectors.push_back(projector_from_json(projectors[p], at["projectors"][p]));
  }
  if (const Json* truth = fields.optional("truth")) {
    capture.truth = to_string(*truth, at["truth"]);
  }
  if (const Json* display = fields.optional("display")) {
    capture.display = to_string(*display, at["display"]);
  }
  fields.finish();
  validate_capture(capture, source);
  if (!std::filesystem::is_regular_file(capture.resolve(capture.camera.model), error)) {
    camera_at["model"].fail("an mrcal .cameramodel file, but '" +
                            capture.resolve(capture.camera.model).string() + "' does not exist");
  }
  return capture;
}

void read_camera_pose(const std::filesystem::path& path, CaptureCamera& camera) {
  using namespace json_fields;
  const Json root = parse_file(path);
  const FieldPath at(path.string());
  Fields fields(root, at);
  if (const Json* R = fields.present("R_eye_camera")) {
    camera.R_eye_camera = to_dmat3(*R, at["R_eye_camera"]);
  }
  if (const Json* t = fields.present("t_eye_camera")) {
    camera.t_eye_camera = to_dvec3(*t, at["t_eye_camera"]);
  }
  fields.finish();
}

nlohmann::json capture_to_json(const Capture& capture) {
  nlohmann::json camera{{"model", capture.camera.model.generic_string()},
                        {"R_eye_camera", json_fields::from_dmat3(capture.camera.R_eye_camera)},
                        {"t_eye_camera", json_fields::from_dvec3(capture.camera.t_eye_camera)}};
  if (capture.camera.gamma != 1.0) camera["gamma"] = capture.camera.gamma;
  nlohmann::json projectors = nlohmann::json::array();
  for (const CaptureProjector& projector : capture.projectors) {
    nlohmann::json frames = nlohmann::json::array();
    for (const CaptureFrame& frame : projector.frames) {
      frames.push_back(
          {{"file", frame.file.generic_string()}, {"pattern", pattern_to_json(frame.pattern)}});
    }
    projectors.push_back({{"name", projector.name},
                          {"size", {projector.size.x, projector.size.y}},
                          {"gamma", projector.gamma},
                          {"frames", frames}});
  }
  nlohmann::json root{{"format", kCaptureFormat}, {"camera", camera}, {"projectors", projectors}};
  if (capture.screen) root["screen"] = json_fields::from_screen(*capture.screen);
  if (capture.truth) root["truth"] = capture.truth->generic_string();
  if (capture.display) root["display"] = capture.display->generic_string();
  return root;
}

void write_capture(const Capture& capture, const std::filesystem::path& capture_json) {
  validate_capture(capture, capture_json.string());
  const std::string text = capture_to_json(capture).dump(1) + "\n";
  write_atomically(capture_json, [&](const std::filesystem::path& temporary) {
    std::ofstream stream(temporary);
    stream << text;
    stream.close();
    if (!stream) throw InputError(capture_json.string(), "", "a writable file");
  });
}

glm::ivec2 check_capture_images(const Capture& capture, std::size_t projector_index) {
  FACET_ASSERT(projector_index < capture.projectors.size());
  const CaptureProjector& projector = capture.projectors[projector_index];
  std::optional<glm::ivec2> size;
  std::filesystem::path first;
  for (const CaptureFrame& frame : projector.frames) {
    const std::filesystem::path path = capture.resolve(frame.file);
    const ImageInfo info = read_image_info(path);
    if (!size) {
      size = info.size;
      first = path;
    } else if (info.size != *size) {
      throw InputError(path.string(), "",
                       "an image of the same size as the other frames (" + std::to_string(size->x) +
                           "x" + std::to_string(size->y) + ", as " + first.filename().string() +
                           "), but it is " + std::to_string(info.size.x) + "x" +
                           std::to_string(info.size.y));
    }
  }
  FACET_ASSERT(size.has_value());
  return *size;
}

cv::Mat load_frame(const Capture& capture, const CaptureFrame& frame) {
  cv::Mat image = read_luminance(capture.resolve(frame.file));
  if (capture.camera.gamma != 1.0) {
    cv::max(image, 0.0, image);
    cv::pow(image, capture.camera.gamma, image);
  }
  return image;
}

}  // namespace facet::calibration
