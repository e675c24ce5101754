#include "facet/projection/base_projection.hpp"

#include <cmath>
#include <numbers>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;
double radians(double degrees) { return degrees * kPi / 180.0; }

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

// Azimuth of a base-frame direction: 0 down -z, positive towards +x.
double azimuth(glm::dvec3 b) { return std::atan2(b.x, -b.z); }

// s of azimuth alpha on the branch chosen by FORMATS.md's wrap rule.
double s_from_azimuth(double alpha, double a0, double a1, double s_hint) {
  const double span = a1 - a0;
  double s = (alpha - a0) / span;
  const double period = 2 * kPi / std::abs(span);  // one full turn, in units of s
  if (std::isfinite(s_hint)) {
    s += period * std::round((s_hint - s) / period);
  } else {
    // Prefer a branch inside [0,1]; otherwise the one nearest to it.
    s -= period * std::floor(s / period);  // s in [0, period)
    if (s > 1 && (period - s) < (s - 1)) s -= period;
  }
  return s;
}

}  // namespace

std::string to_string(BaseKind kind) {
  switch (kind) {
    case BaseKind::perspective:
      return "perspective";
    case BaseKind::fisheye:
      return "fisheye";
    case BaseKind::cylindrical:
      return "cylindrical";
    case BaseKind::equirectangular:
      return "equirectangular";
  }
  return "unknown";
}

BaseKind base_kind_from_string(const std::string& name, const std::string& source,
                               const std::string& field) {
  for (BaseKind kind : {BaseKind::perspective, BaseKind::fisheye, BaseKind::cylindrical,
                        BaseKind::equirectangular}) {
    if (name == to_string(kind)) return kind;
  }
  throw InputError(
      source, field,
      "expected one of perspective, fisheye, cylindrical, equirectangular; got '" + name + "'");
}

BaseProjection BaseProjection::perspective(double left, double right, double top, double bottom) {
  BaseProjection base;
  base.kind = BaseKind::perspective;
  base.tan_extent = {left, right, top, bottom};
  return base;
}

BaseProjection BaseProjection::perspective_fov(double fov_x_deg, double fov_y_deg) {
  for (auto [fov, field] : {std::pair{fov_x_deg, "fov_x"}, std::pair{fov_y_deg, "fov_y"}}) {
    if (!(fov > 0 && fov < 180)) {
      throw InputError(
          {}, field,
          "a perspective field of view must lie in (0°, 180°); got " + number(fov) + "°");
    }
  }
  const double x = std::tan(radians(fov_x_deg) / 2), y = std::tan(radians(fov_y_deg) / 2);
  return perspective(-x, x, y, -y);
}

BaseProjection BaseProjection::fisheye(double fov_deg) {
  BaseProjection base;
  base.kind = BaseKind::fisheye;
  base.fov_deg = fov_deg;
  return base;
}

BaseProjection BaseProjection::cylindrical(double a0_deg, double a1_deg, double tan_top,
                                           double tan_bottom) {
  BaseProjection base;
  base.kind = BaseKind::cylindrical;
  base.azimuth_deg = {a0_deg, a1_deg};
  base.tan_elevation = {tan_top, tan_bottom};
  return base;
}

BaseProjection BaseProjection::equirectangular(double a0_deg, double a1_deg, double top_deg,
                                               double bottom_deg) {
  BaseProjection base;
  base.kind = BaseKind::equirectangular;
  base.azimuth_deg = {a0_deg, a1_deg};
  base.elevation_deg = {top_deg, bottom_deg};
  return base;
}

void BaseProjection::validate(const std::string& source) const {
  auto require = [&](bool ok, const char* field, const std::string& expected) {
    if (!ok) throw InputError(source, field, expected);
  };
  auto check_azimuth = [&] {
    const auto [a0, a1] = azimuth_deg;
    require(std::isfinite(a0) && std::isfinite(a1), "azimuth", "expected finite degrees");
    require(a0 != a1 && std::abs(a1 - a0) <= 360.0 + 1e-9, "azimuth",
            "expected two different azimuths at most 360° apart; got [" + number(a0) + ", " +
                number(a1) + "]");
  };
  switch (kind) {
    case BaseKind::perspective: {
      const auto [l, r, t, b] = tan_extent;
      require(std::isfinite(l) && std::isfinite(r) && std::isfinite(t) && std::isfinite(b),
              "tan_extent",
              "expected finite tangents [left, right, top, bottom]; a perspective field of view "
              "of 180° or more cannot be represented");
      require(std::abs(l) <= kMaxTangent && std::abs(r) <= kMaxTangent &&
                  std::abs(t) <= kMaxTangent && std::abs(b) <= kMaxTangent,
              "tan_extent", "expected tangents within ±1e6");
      require(l < r && b < t, "tan_extent",
              "expected left < right and bottom < top; got [" + number(l) + ", " + number(r) +
                  ", " + number(t) + ", " + number(b) + "]");
      break;
    }
    case BaseKind::fisheye:
      require(std::isfinite(fov_deg) && fov_deg > 0 && fov_deg <= 360, "fov",
              "expected a fisheye field of view in (0°, 360°]; got " + number(fov_deg) + "°");
      break;
    case BaseKind::cylindrical: {
      check_azimuth();
      const auto [top, bottom] = tan_elevation;
      require(std::isfinite(top) && std::isfinite(bottom) && top != bottom, "tan_elevation",
              "expected two different finite tangents [top, bottom]");
      require(std::abs(top) <= kMaxTangent && std::abs(bottom) <= kMaxTangent, "tan_elevation",
              "expected tangents within ±1e6");
      break;
    }
    case BaseKind::equirectangular: {
      check_azimuth();
      const auto [top, bottom] = elevation_deg;
      require(std::isfinite(top) && std::isfinite(bottom) && top != bottom && std::abs(top) <= 90 &&
                  std::abs(bottom) <= 90,
              "elevation", "expected two different elevations within [-90°, 90°]");
      break;
    }
  }
}

bool BaseProjection::wraps_horizontally() const {
  return (kind == BaseKind::cylindrical || kind == BaseKind::equirectangular) &&
         std::abs(std::abs(azimuth_deg[1] - azimuth_deg[0]) - 360.0) < 1e-9;
}

glm::dvec3 BaseProjection::surface_point(glm::dvec2 st) const {
  const double s = st.x, t = st.y;
  switch (kind) {
    case BaseKind::perspective:
      return {tan_extent[0] + s * (tan_extent[1] - tan_extent[0]),
              tan_extent[2] + t * (tan_extent[3] - tan_extent[2]), -1.0};
    case BaseKind::fisheye: {
      const double u = 2 * s - 1, v = 1 - 2 * t;
      const double rho = std::hypot(u, v);
      const double theta = rho * radians(fov_deg) / 2;
      const double phi = std::atan2(v, u);
      return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), -std::cos(theta)};
    }
    case BaseKind::cylindrical: {
      const double alpha = radians(azimuth_deg[0] + s * (azimuth_deg[1] - azimuth_deg[0]));
      const double y = tan_elevation[0] + t * (tan_elevation[1] - tan_elevation[0]);
      return {std::sin(alpha), y, -std::cos(alpha)};
    }
    case BaseKind::equirectangular: {
      const double alpha = radians(azimuth_deg[0] + s * (azimuth_deg[1] - azimuth_deg[0]));
      const double e = radians(elevation_deg[0] + t * (elevation_deg[1] - elevation_deg[0]));
      return {std::cos(e) * std::sin(alpha), std::sin(e), -std::cos(e) * std::cos(alpha)};
    }
  }
  return glm::dvec3(0.0);
}

glm::dvec3 BaseProjection::direction(glm::dvec2 st) const {
  return glm::normalize(surface_point(st));
}

std::optional<glm::dvec2> BaseProjection::st_from_direction(glm::dvec3 b, double s_hint) const {
  if (!std::isfinite(b.x) || !std::isfinite(b.y) || !std::isfinite(b.z)) return std::nullopt;
  const double length = glm::length(b);
  if (!(length > 0)) return std::nullopt;
  b /= length;
  switch (kind) {
    case BaseKind::perspective: {
      if (!(b.z < 0)) return std::nullopt;
      const double x = b.x / -b.z, y = b.y / -b.z;
      return glm::dvec2{(x - tan_extent[0]) / (tan_extent[1] - tan_extent[0]),
                        (y - tan_extent[2]) / (tan_extent[3] - tan_extent[2])};
    }
    case BaseKind::fisheye: {
      const double theta = std::atan2(std::hypot(b.x, b.y), -b.z);
      const double rho = theta / (radians(fov_deg) / 2);
      const double phi = std::atan2(b.y, b.x);
      const double u = rho * std::cos(phi), v = rho * std::sin(phi);
      return glm::dvec2{(u + 1) / 2, (1 - v) / 2};
    }
    case BaseKind::cylindrical: {
      const double horizontal = std::hypot(b.x, b.z);
      if (!(horizontal > 0)) return std::nullopt;
      const double s =
          s_from_azimuth(azimuth(b), radians(azimuth_deg[0]), radians(azimuth_deg[1]), s_hint);
      const double y = b.y / horizontal;
      return glm::dvec2{s, (y - tan_elevation[0]) / (tan_elevation[1] - tan_elevation[0])};
    }
    case BaseKind::equirectangular: {
      const double horizontal = std::hypot(b.x, b.z);
      const double e = std::atan2(b.y, horizontal);
      // At the poles every azimuth is right; take the hint's, or the middle.
      const double s = horizontal > 0 ? s_from_azimuth(azimuth(b), radians(azimuth_deg[0]),
                                                       radians(azimuth_deg[1]), s_hint)
                                      : (std::isfinite(s_hint) ? s_hint : 0.5);
      return glm::dvec2{s, (e - radians(elevation_deg[0])) /
                               (radians(elevation_deg[1]) - radians(elevation_deg[0]))};
    }
  }
  return std::nullopt;
}

}  // namespace facet
