#include "facet/projection/content_projection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "facet/projection/errors.hpp"

namespace facet {

namespace {
constexpr double kPi = std::numbers::pi;
// A perspective frustum holds directions up to this angle from its axis.
constexpr double kMaxFrustumHalfAngle_deg = 80;
}  // namespace

const std::array<CubeFaceAxes, 6> kCubeFaces = {{
    {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}},
    {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}},
    {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},
    {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},
    {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}},
}};

int cube_face_of(glm::dvec3 v) {
  const glm::dvec3 a = glm::abs(v);
  if (a.x >= a.y && a.x >= a.z) return v.x >= 0 ? 0 : 1;
  if (a.y >= a.z) return v.y >= 0 ? 2 : 3;
  return v.z >= 0 ? 4 : 5;
}

std::string to_string(ContentFormat format) {
  switch (format) {
    case ContentFormat::fisheye:
      return "fisheye";
    case ContentFormat::equirect:
      return "equirect";
    case ContentFormat::cubemap:
      return "cubemap";
    case ContentFormat::perspective:
      return "perspective";
  }
  return "?";
}

ContentFormat content_format_from_string(const std::string& name, const std::string& source,
                                         const std::string& field) {
  if (name == "fisheye") return ContentFormat::fisheye;
  if (name == "equirect" || name == "equirectangular") return ContentFormat::equirect;
  if (name == "cubemap") return ContentFormat::cubemap;
  if (name == "perspective") return ContentFormat::perspective;
  throw InputError(source, field,
                   "expected fisheye, equirect, cubemap or perspective; got '" + name + "'");
}

void ContentProjection::validate(const std::string& source) const {
  if (format == ContentFormat::fisheye && !(fov_deg > 0 && fov_deg <= 360)) {
    throw InputError(source, OptionName{"fov_deg"},
                     "expected the dome master's full field of view in degrees within (0, 360]; "
                     "got " +
                         detail::degrees_text(fov_deg));
  }
  if (format == ContentFormat::perspective) {
    const auto& e = tan_extent;
    const bool finite = std::all_of(e.begin(), e.end(), [](double x) { return std::isfinite(x); });
    if (!finite || !(e[0] < e[1]) || !(e[2] > e[3]))
      throw InputError(source, "tan_extent",
                       "expected finite tangents [left, right, top, bottom] with left < right and "
                       "top > bottom");
  }
}

std::optional<ContentPoint> ContentProjection::point_from_v_eye(glm::dvec3 v_eye) const {
  if (!(std::isfinite(v_eye.x) && std::isfinite(v_eye.y) && std::isfinite(v_eye.z)))
    return std::nullopt;
  const double length = glm::length(v_eye);
  if (!(length > 0)) return std::nullopt;
  const glm::dvec3 b = glm::transpose(R_eye_content) * (v_eye / length);
  switch (format) {
    case ContentFormat::fisheye: {
      // The dome master's own frame: view axis the zenith.
      const glm::dvec3 f = glm::transpose(R_dome_fisheye(FisheyeZenith::centre)) * b;
      const double theta = std::atan2(std::hypot(f.x, f.y), -f.z);
      const double rho = theta / (fov_deg * kPi / 360);
      if (rho > 1) return std::nullopt;
      const double phi = std::atan2(f.y, f.x);
      return ContentPoint{0, {(1 + rho * std::cos(phi)) / 2, (1 - rho * std::sin(phi)) / 2}};
    }
    case ContentFormat::equirect: {
      const double azimuth = std::atan2(b.x, -b.z);  // 0 ahead, +90° right
      const double elevation = std::atan2(b.y, std::hypot(b.x, b.z));
      double s = azimuth / (2 * kPi) + 0.5;
      if (s >= 1) s -= 1;
      return ContentPoint{0, {s, 0.5 - elevation / kPi}};
    }
    case ContentFormat::cubemap: {
      const int f = cube_face_of(b);
      const CubeFaceAxes& axes = kCubeFaces[std::size_t(f)];
      const double m = glm::dot(axes.a_m, b);
      return ContentPoint{
          f, {(glm::dot(axes.a_s, b) / m + 1) / 2, (glm::dot(axes.a_t, b) / m + 1) / 2}};
    }
    case ContentFormat::perspective: {
      if (!(b.z < 0)) return std::nullopt;
      const double x = b.x / -b.z, y = b.y / -b.z;
      const glm::dvec2 st{(x - tan_extent[0]) / (tan_extent[1] - tan_extent[0]),
                          (y - tan_extent[2]) / (tan_extent[3] - tan_extent[2])};
      if (st.x < 0 || st.x > 1 || st.y < 0 || st.y > 1) return std::nullopt;
      return ContentPoint{0, st};
    }
  }
  return std::nullopt;
}

glm::dvec3 ContentProjection::v_eye_from_point(const ContentPoint& point) const {
  const glm::dvec2 st = point.st;
  glm::dvec3 b{0, 0, -1};
  switch (format) {
    case ContentFormat::fisheye: {
      const double u = 2 * st.x - 1, v = 1 - 2 * st.y;
      const double rho = std::hypot(u, v);
      const double theta = rho * fov_deg * kPi / 360;
      const double phi = std::atan2(v, u);
      const glm::dvec3 f{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                         -std::cos(theta)};
      b = R_dome_fisheye(FisheyeZenith::centre) * f;
      break;
    }
    case ContentFormat::equirect: {
      const double azimuth = (st.x - 0.5) * 2 * kPi;
      const double elevation = (0.5 - st.y) * kPi;
      b = {std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
           -std::cos(elevation) * std::cos(azimuth)};
      break;
    }
    case ContentFormat::cubemap: {
      const CubeFaceAxes& axes = kCubeFaces[std::size_t(std::clamp(point.face, 0, 5))];
      // a_s, a_t and a_m are orthonormal: the inverse is their sum.
      b = glm::normalize(axes.a_m + (2 * st.x - 1) * axes.a_s + (2 * st.y - 1) * axes.a_t);
      break;
    }
    case ContentFormat::perspective: {
      const double x = tan_extent[0] + st.x * (tan_extent[1] - tan_extent[0]);
      const double y = tan_extent[2] + st.y * (tan_extent[3] - tan_extent[2]);
      b = glm::normalize(glm::dvec3(x, y, -1));
      break;
    }
  }
  return R_eye_content * b;
}

ContentProjection fisheye_content(double fov_deg, const DomeOrientation& orientation) {
  ContentProjection content;
  content.format = ContentFormat::fisheye;
  content.fov_deg = fov_deg;
  content.R_eye_content = orientation.R_eye_dome();
  return content;
}

ContentProjection equirect_content(const DomeOrientation& orientation) {
  ContentProjection content;
  content.format = ContentFormat::equirect;
  content.R_eye_content = orientation.R_eye_dome();
  return content;
}

ContentProjection cubemap_content(const DomeOrientation& orientation) {
  ContentProjection content;
  content.format = ContentFormat::cubemap;
  content.R_eye_content = orientation.R_eye_dome();
  return content;
}

glm::dmat4 Frustum::gl_projection(double z_near, double z_far) const {
  FACET_ASSERT(z_near > 0 && z_far > z_near);
  const double l = tan_extent[0] * z_near, r = tan_extent[1] * z_near;
  const double t = tan_extent[2] * z_near, b = tan_extent[3] * z_near;
  glm::dmat4 m(0.0);  // column-major: m[column][row]
  m[0][0] = 2 * z_near / (r - l);
  m[1][1] = 2 * z_near / (t - b);
  m[2][0] = (r + l) / (r - l);
  m[2][1] = (t + b) / (t - b);
  m[2][2] = -(z_far + z_near) / (z_far - z_near);
  m[2][3] = -1;
  m[3][2] = -2 * z_far * z_near / (z_far - z_near);
  return m;
}

ContentProjection Frustum::content() const {
  ContentProjection content;
  content.format = ContentFormat::perspective;
  content.tan_extent = tan_extent;
  content.R_eye_content = R_eye_frustum;
  return content;
}

Frustum covering_frustum(const Warp& warp, const std::string& source, double margin) {
  constexpr int kSteps = 256;
  std::vector<glm::dvec3> directions;
  directions.reserve(std::size_t(kSteps + 1) * (kSteps + 1));
  glm::dvec3 sum{0.0};
  for (int j = 0; j <= kSteps; ++j) {
    for (int i = 0; i <= kSteps; ++i) {
      const glm::dvec2 st(double(i) / kSteps, double(j) / kSteps);
      if (!(warp.coverage_at(st) >= 0.5)) continue;
      const glm::dvec3 v = glm::normalize(warp.v_eye_from_st(st));
      directions.push_back(v);
      sum += v;
    }
  }
  if (directions.empty() || !(glm::length(sum) > 1e-9 * double(directions.size())))
    throw InputError(source, "warp",
                     "a projector whose covered directions lie within one hemisphere, for a "
                     "perspective frustum; this one covers none, or all around");
  const glm::dvec3 axis = glm::normalize(sum);
  glm::dvec3 up = glm::dvec3(0, 1, 0) - axis.y * axis;
  if (glm::length(up) < 1e-6) up = glm::dvec3(0, 0, -1) - axis.z * axis;
  up = glm::normalize(up);
  const glm::dvec3 right = glm::cross(axis, up);
  Frustum frustum;
  frustum.R_eye_frustum = glm::dmat3(right, up, -axis);
  const double min_cos = std::cos(kMaxFrustumHalfAngle_deg * kPi / 180);
  double left = 1e300, right_tan = -1e300, top = -1e300, bottom = 1e300;
  for (const glm::dvec3& v : directions) {
    const double depth = glm::dot(v, axis);
    if (!(depth >= min_cos)) {
      throw InputError(source, "warp",
                       "a projector whose directions lie within " +
                           detail::degrees_text(kMaxFrustumHalfAngle_deg) +
                           "° of one axis, for a perspective frustum; this one reaches " +
                           detail::degrees_text(
                               std::round(std::acos(std::clamp(depth, -1.0, 1.0)) * 180 / kPi)) +
                           "° from its mean direction: use a cube map or a fisheye instead");
    }
    const double x = glm::dot(v, right) / depth, y = glm::dot(v, up) / depth;
    left = std::min(left, x);
    right_tan = std::max(right_tan, x);
    bottom = std::min(bottom, y);
    top = std::max(top, y);
  }
  const double widen_x = margin * (right_tan - left), widen_y = margin * (top - bottom);
  frustum.tan_extent = {left - widen_x, right_tan + widen_x, top + widen_y, bottom - widen_y};
  return frustum;
}

}  // namespace facet
