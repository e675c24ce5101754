#include "facet/projection/footprint.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;
double degrees(double radians) { return radians * 180.0 / kPi; }

// Rotation whose base −z is `forward` and whose base +y leans towards `up`.
glm::dmat3 look_rotation(const glm::dvec3& forward, const std::optional<glm::dvec3>& up_hint) {
  auto orthogonal_up = [&](glm::dvec3 up) -> std::optional<glm::dvec3> {
    if (!(glm::length(up) > 0)) return std::nullopt;
    up = glm::normalize(up);
    const glm::dvec3 rest = up - glm::dot(up, forward) * forward;
    // Too close to the centre to define a roll reliably.
    if (!(glm::length(rest) > 1e-3)) return std::nullopt;
    return glm::normalize(rest);
  };
  std::optional<glm::dvec3> y_base;
  if (up_hint) y_base = orthogonal_up(*up_hint);
  if (!y_base) y_base = orthogonal_up({0, 1, 0});
  if (!y_base) y_base = orthogonal_up({0, 0, -1});
  FACET_ASSERT(y_base.has_value());
  const glm::dvec3 z_base = -forward;
  const glm::dvec3 x_base = glm::cross(*y_base, z_base);
  return glm::dmat3(x_base, *y_base, z_base);
}

// Rotation about the eye's y axis by azimuth c (0 looks down −z, positive towards +x), so that
// base azimuth α becomes eye azimuth α + c.
glm::dmat3 azimuth_rotation(double c) {
  return glm::dmat3(glm::dvec3(std::cos(c), 0, std::sin(c)), glm::dvec3(0, 1, 0),
                    glm::dvec3(-std::sin(c), 0, std::cos(c)));
}

struct AzimuthRange {
  double center = 0;     // eye azimuth of the base's azimuth 0, radians
  double half_span = 0;  // radians, margin included, at most π
};

// The smallest arc of azimuths holding every direction, widened by the margin.
AzimuthRange azimuth_range(const std::vector<glm::dvec3>& v, double margin) {
  std::vector<double> alpha;
  alpha.reserve(v.size());
  for (const auto& d : v) {
    if (std::hypot(d.x, d.z) > 1e-12) alpha.push_back(std::atan2(d.x, -d.z));
  }
  if (alpha.empty()) return {0, kPi};
  std::sort(alpha.begin(), alpha.end());
  // The widest empty gap between neighbouring azimuths, the wrap-around gap included.
  double widest = alpha.front() + 2 * kPi - alpha.back();
  double gap_start = alpha.back();
  for (std::size_t k = 1; k < alpha.size(); ++k) {
    if (alpha[k] - alpha[k - 1] > widest) {
      widest = alpha[k] - alpha[k - 1];
      gap_start = alpha[k - 1];
    }
  }
  const double arc = 2 * kPi - widest;
  if (arc + 2 * margin >= 2 * kPi) {
    // The seam goes in the middle of the widest gap, opposite the centre.
    return {gap_start + widest / 2 + kPi, kPi};
  }
  const double arc_start = gap_start + widest;
  return {arc_start + arc / 2, arc / 2 + margin};
}

}  // namespace

BaseCover cover_directions(std::span<const glm::dvec3> v_eye, const CoverOptions& options) {
  std::vector<glm::dvec3> v;
  v.reserve(v_eye.size());
  for (const auto& d : v_eye) {
    const double length = glm::length(d);
    if (std::isfinite(length) && length > 0) v.push_back(d / length);
  }
  FACET_ASSERT(!v.empty());
  const double margin = options.margin_rad;

  glm::dvec3 sum(0.0);
  for (const auto& d : v) sum += d;
  const bool has_centre = glm::length(sum) > 1e-6 * double(v.size());
  double max_angle = kPi;
  glm::dvec3 centre(0, 0, -1);
  if (has_centre) {
    centre = glm::normalize(sum);
    double min_cos = 1;
    for (const auto& d : v) min_cos = std::min(min_cos, glm::dot(d, centre));
    max_angle = std::acos(std::clamp(min_cos, -1.0, 1.0));
  }

  BaseCover cover;
  if (has_centre && max_angle + margin <= options.max_perspective_half_angle_rad) {
    cover.R_eye_base = look_rotation(centre, options.up_eye);
    const glm::dmat3 R_base_eye = glm::transpose(cover.R_eye_base);
    double left = 1e300, right = -1e300, top = -1e300, bottom = 1e300;
    for (const auto& d : v) {
      const glm::dvec3 b = R_base_eye * d;
      const double x = std::atan2(b.x, -b.z), y = std::atan2(b.y, -b.z);
      left = std::min(left, x);
      right = std::max(right, x);
      top = std::max(top, y);
      bottom = std::min(bottom, y);
    }
    cover.base = BaseProjection::perspective(std::tan(left - margin), std::tan(right + margin),
                                             std::tan(top + margin), std::tan(bottom - margin));
    return cover;
  }

  double min_elevation = kPi, max_elevation = -kPi;
  for (const auto& d : v) {
    const double e = std::asin(std::clamp(d.y, -1.0, 1.0));
    min_elevation = std::min(min_elevation, e);
    max_elevation = std::max(max_elevation, e);
  }
  const double top = max_elevation + margin, bottom = min_elevation - margin;
  if (std::max(top, -bottom) <= options.max_cylindrical_elevation_rad) {
    const AzimuthRange range = azimuth_range(v, margin);
    cover.R_eye_base = azimuth_rotation(range.center);
    cover.base = BaseProjection::cylindrical(-degrees(range.half_span), degrees(range.half_span),
                                             std::tan(top), std::tan(bottom));
    return cover;
  }

  if (has_centre && max_angle + margin <= kPi * 170.0 / 180.0) {
    cover.R_eye_base = look_rotation(centre, options.up_eye);
    cover.base = BaseProjection::fisheye(2 * degrees(max_angle + margin));
    return cover;
  }

  const AzimuthRange range = azimuth_range(v, margin);
  cover.R_eye_base = azimuth_rotation(range.center);
  cover.base = BaseProjection::equirectangular(-degrees(range.half_span), degrees(range.half_span),
                                               std::min(90.0, degrees(top)),
                                               std::max(-90.0, degrees(bottom)));
  return cover;
}

}  // namespace facet
