#include "facet/calibration/camera_model.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <sstream>

extern "C" {
#include <mrcal/mrcal.h>
}

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"

namespace facet::calibration {

struct CameraModel::Impl {
  std::string name;
  mrcal_lensmodel_t lensmodel{};
  std::vector<double> intrinsics;
  glm::ivec2 imager_size{0, 0};
  std::array<double, 6> rt_cam_ref{};
};

namespace {

// The .cameramodel text is a Python literal. mrcal's C reader skips valid_intrinsics_region, so
// pick the polygon out of the text: drop comments, find the key, read [x, y] pairs up to the
// list's closing bracket.
std::vector<glm::dvec2> parse_valid_region(const std::string& text) {
  std::string code;
  code.reserve(text.size());
  char quote = 0;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char ch = text[k];
    if (quote == 0 && ch == '#') {
      while (k < text.size() && text[k] != '\n') ++k;
      code.push_back('\n');
      continue;
    }
    if (quote == 0 && (ch == '\'' || ch == '"')) {
      quote = ch;
    } else if (quote != 0 && ch == quote) {
      quote = 0;
    }
    code.push_back(ch);
  }
  const std::size_t key = code.find("valid_intrinsics_region");
  if (key == std::string::npos) return {};
  const std::size_t open = code.find('[', key);
  if (open == std::string::npos) return {};
  int depth = 0;
  std::size_t close = open;
  for (; close < code.size(); ++close) {
    if (code[close] == '[') ++depth;
    if (code[close] == ']' && --depth == 0) break;
  }
  const std::string list = code.substr(open + 1, close - open - 1);
  static const std::regex pair(R"(\[\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*,?\s*\])");
  std::vector<glm::dvec2> polygon;
  for (auto it = std::sregex_iterator(list.begin(), list.end(), pair); it != std::sregex_iterator();
       ++it) {
    polygon.emplace_back(std::strtod((*it)[1].str().c_str(), nullptr),
                         std::strtod((*it)[2].str().c_str(), nullptr));
  }
  return polygon.size() >= 3 ? polygon : std::vector<glm::dvec2>{};
}

bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool finite(const glm::dvec2& q) { return std::isfinite(q.x) && std::isfinite(q.y); }

}  // namespace

CameraModel::CameraModel(const std::string& lensmodel, std::vector<double> intrinsics,
                         glm::ivec2 imager_size, std::array<double, 6> rt_cam_ref,
                         const std::string& source) {
  auto impl = std::make_shared<Impl>();
  if (!mrcal_lensmodel_from_name(&impl->lensmodel, lensmodel.c_str()) ||
      !mrcal_lensmodel_type_is_valid(impl->lensmodel.type)) {
    throw InputError(
        source, "lensmodel",
        "a configured mrcal lens model name such as LENSMODEL_OPENCV8, not '" + lensmodel + "'");
  }
  const int count = mrcal_lensmodel_num_params(&impl->lensmodel);
  if (int(intrinsics.size()) != count) {
    throw InputError(source, "intrinsics",
                     std::to_string(count) + " values for " + lensmodel + ", not " +
                         std::to_string(intrinsics.size()));
  }
  for (double value : intrinsics) {
    if (!std::isfinite(value)) throw InputError(source, "intrinsics", "finite numbers");
  }
  // A zero or negative focal length would project nothing or mirror the image.
  if (mrcal_lensmodel_metadata(&impl->lensmodel).has_core &&
      !(intrinsics[0] > 0 && intrinsics[1] > 0)) {
    throw InputError(source, "intrinsics",
                     "positive focal lengths fx and fy (the first two values)");
  }
  for (double value : rt_cam_ref) {
    if (!std::isfinite(value)) throw InputError(source, "extrinsics", "finite numbers");
  }
  if (imager_size.x < 1 || imager_size.y < 1) {
    throw InputError(source, "imagersize", "a positive width and height");
  }
  char name[1024];
  if (!mrcal_lensmodel_name(name, sizeof name, &impl->lensmodel)) {
    throw InputError(source, "lensmodel", "a lens model name mrcal can print");
  }
  impl->name = name;
  impl->intrinsics = std::move(intrinsics);
  impl->imager_size = imager_size;
  impl->rt_cam_ref = rt_cam_ref;
  impl_ = std::move(impl);
}

namespace {

// InputError naming `source` and the line when a ' or " string of the text (outside '#' comments)
// is not closed before the end of the text.
void require_closed_quotes(std::string_view text, const std::string& source) {
  char open = 0;  // the quote of the string being read, or 0
  bool comment = false;
  int line = 1, opened_at = 0;
  for (const char c : text) {
    if (c == '\n') {
      ++line;
      comment = false;
      continue;
    }
    if (comment) continue;
    if (open) {
      if (c == open) open = 0;
    } else if (c == '#') {
      comment = true;
    } else if (c == '\'' || c == '"') {
      open = c;
      opened_at = line;
    }
  }
  if (open) {
    throw InputError(
        source, "",
        "an mrcal .cameramodel file whose strings are closed; the one opened on line " +
            std::to_string(opened_at) + " never is (a cut file?)");
  }
}

}  // namespace

CameraModel CameraModel::read(const std::filesystem::path& path) {
  const Activity activity("reading the camera model " + path.string());
  require_regular_file(path);
  std::ifstream stream(path);
  if (!stream) throw InputError(path.string(), "", "a readable mrcal .cameramodel file");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  const std::string text = buffer.str();
  // mrcal's reader looks for the end of a quoted string without checking for the end of the
  // text (a file cut inside 'lensmodel' was read past its end): every quote must be closed.
  require_closed_quotes(text, path.string());
  // It also skips a '#' comment up to its newline without checking for the end of the text, so a
  // file that ends inside a comment would be read past its end: end it with one.
  const std::string terminated = text + '\n';
  mrcal_cameramodel_t* model =
      mrcal_read_cameramodel_string(terminated.c_str(), int(terminated.size()));
  if (model == nullptr) {
    throw InputError(path.string(), "",
                     "an mrcal .cameramodel file that mrcal can parse (see its message above)");
  }
  char name[1024];
  const bool named = mrcal_lensmodel_name(name, sizeof name, &model->lensmodel);
  const int count = mrcal_lensmodel_num_params(&model->lensmodel);
  std::vector<double> intrinsics(model->intrinsics, model->intrinsics + count);
  const glm::ivec2 size(int(model->imagersize[0]), int(model->imagersize[1]));
  std::array<double, 6> rt{};
  std::copy(model->rt_cam_ref, model->rt_cam_ref + 6, rt.begin());
  mrcal_free_cameramodel(&model);
  if (!named) throw InputError(path.string(), "lensmodel", "a lens model mrcal can name");
  CameraModel camera(name, std::move(intrinsics), size, rt, path.string());
  camera.valid_region_ = parse_valid_region(text);
  return camera;
}

void CameraModel::write(const std::filesystem::path& path) const {
  // mrcal's own C writer prints with %f, which loses the precision of small distortion
  // coefficients; the format is a Python literal that is easy to write in full precision.
  auto number = [](double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", value);
    return std::string(text);
  };
  std::string text = "{\n  'lensmodel':  '" + impl_->name + "',\n";
  text += "  # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....\n  'intrinsics': [";
  for (double value : impl_->intrinsics) text += " " + number(value) + ",";
  text += " ],\n  # extrinsics are rt_fromref\n  'extrinsics': [";
  for (double value : impl_->rt_cam_ref) text += " " + number(value) + ",";
  text += " ],\n  'imagersize': [ " + std::to_string(impl_->imager_size.x) + ", " +
          std::to_string(impl_->imager_size.y) + " ],\n";
  if (!valid_region_.empty()) {
    text += "  'valid_intrinsics_region': [\n";
    for (const auto& q : valid_region_) {
      text += "    [ " + number(q.x) + ", " + number(q.y) + " ],\n";
    }
    text += "  ],\n";
  }
  text += "}\n";
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    std::ofstream stream(temporary);
    stream << text;
    stream.close();
    if (!stream) throw InputError(path.string(), "", "a writable .cameramodel file");
  });
}

const std::string& CameraModel::lensmodel() const { return impl_->name; }
const std::vector<double>& CameraModel::intrinsics() const { return impl_->intrinsics; }
glm::ivec2 CameraModel::imager_size() const { return impl_->imager_size; }
const std::array<double, 6>& CameraModel::rt_cam_ref() const { return impl_->rt_cam_ref; }
const std::vector<glm::dvec2>& CameraModel::valid_intrinsics_region() const {
  return valid_region_;
}
void CameraModel::set_valid_intrinsics_region(std::vector<glm::dvec2> polygon) {
  valid_region_ = std::move(polygon);
}

bool CameraModel::is_valid_pixel(glm::dvec2 q_camera) const {
  const glm::dvec2 size(impl_->imager_size);
  if (!(q_camera.x >= -0.5 && q_camera.y >= -0.5 && q_camera.x <= size.x - 0.5 &&
        q_camera.y <= size.y - 0.5)) {
    return false;
  }
  if (valid_region_.empty()) return true;
  std::vector<cv::Point2f> contour;
  contour.reserve(valid_region_.size());
  for (const auto& q : valid_region_) contour.emplace_back(float(q.x), float(q.y));
  return cv::pointPolygonTest(contour, cv::Point2f(float(q_camera.x), float(q_camera.y)), false) >=
         0;
}

std::optional<glm::dvec3> CameraModel::unproject(glm::dvec2 q_camera) const {
  if (impl_->lensmodel.type == MRCAL_LENSMODEL_CAHVORE || !finite(q_camera)) return std::nullopt;
  mrcal_point2_t q;
  q.x = q_camera.x;
  q.y = q_camera.y;
  mrcal_point3_t v;
  if (!mrcal_unproject(&v, &q, 1, &impl_->lensmodel, impl_->intrinsics.data())) {
    return std::nullopt;
  }
  const glm::dvec3 v_camera(v.x, v.y, v.z);
  const double length = glm::length(v_camera);
  if (!finite(v_camera) || !(length > 0)) return std::nullopt;
  return v_camera / length;
}

std::optional<glm::dvec2> CameraModel::project(glm::dvec3 v_camera) const {
  if (!finite(v_camera) || v_camera == glm::dvec3(0.0)) return std::nullopt;
  mrcal_point3_t v;
  v.x = v_camera.x;
  v.y = v_camera.y;
  v.z = v_camera.z;
  mrcal_point2_t q;
  if (!mrcal_project(&q, nullptr, nullptr, &v, 1, &impl_->lensmodel, impl_->intrinsics.data())) {
    return std::nullopt;
  }
  const glm::dvec2 q_camera(q.x, q.y);
  if (!finite(q_camera)) return std::nullopt;
  return q_camera;
}

void CameraModel::unproject(std::span<const glm::dvec2> q_camera,
                            std::span<glm::dvec3> v_camera) const {
  FACET_ASSERT(q_camera.size() == v_camera.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < q_camera.size(); ++k) {
    v_camera[k] = unproject(q_camera[k]).value_or(glm::dvec3(nan));
  }
}

void CameraModel::project(std::span<const glm::dvec3> v_camera,
                          std::span<glm::dvec2> q_camera) const {
  FACET_ASSERT(q_camera.size() == v_camera.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < v_camera.size(); ++k) {
    q_camera[k] = project(v_camera[k]).value_or(glm::dvec2(nan));
  }
}

}  // namespace facet::calibration
