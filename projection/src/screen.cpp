#include "facet/projection/screen.hpp"

#include <cmath>

namespace facet {
namespace {

bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Larger root of a t² + 2 b t + c = 0 when it is >= 0. The stable form avoids cancellation when
// the ray starts close to the surface.
std::optional<double> far_root(double a, double b, double c) {
  if (!(a > 0)) return std::nullopt;
  const double discriminant = b * b - a * c;
  if (!(discriminant >= 0)) return std::nullopt;
  const double root = std::sqrt(discriminant);
  double t;
  if (b <= 0) {
    t = (-b + root) / a;
  } else {
    // -b + root would cancel; -b - root is accurate, and the roots' product is c / a.
    const double near = (-b - root) / a;
    t = near != 0 ? c / (a * near) : 0.0;
  }
  if (!(t >= 0) || !std::isfinite(t)) return std::nullopt;
  return t;
}

}  // namespace

std::optional<double> intersect_screen(const Screen& screen, const glm::dvec3& p_origin,
                                       const glm::dvec3& v_dir) {
  if (!finite(p_origin) || !finite(v_dir) || !(glm::length(v_dir) > 0)) return std::nullopt;
  switch (screen.type) {
    case Screen::Type::sphere: {
      const glm::dvec3 o = p_origin - screen.center;
      return far_root(glm::dot(v_dir, v_dir), glm::dot(o, v_dir),
                      glm::dot(o, o) - screen.radius * screen.radius);
    }
    case Screen::Type::cylinder: {
      const glm::dvec3 axis = glm::normalize(screen.axis);
      const glm::dvec3 o = p_origin - screen.center;
      const glm::dvec3 o_perp = o - glm::dot(o, axis) * axis;
      const glm::dvec3 v_perp = v_dir - glm::dot(v_dir, axis) * axis;
      // Parallel to the axis (relative to the ray's length): no hit.
      if (!(glm::dot(v_perp, v_perp) > 1e-24 * glm::dot(v_dir, v_dir))) return std::nullopt;
      return far_root(glm::dot(v_perp, v_perp), glm::dot(o_perp, v_perp),
                      glm::dot(o_perp, o_perp) - screen.radius * screen.radius);
    }
    case Screen::Type::plane: {
      const double denominator = glm::dot(v_dir, screen.normal);
      if (denominator == 0) return std::nullopt;
      const double t = glm::dot(screen.point - p_origin, screen.normal) / denominator;
      if (!(t > 0) || !std::isfinite(t)) return std::nullopt;
      return t;
    }
  }
  return std::nullopt;
}

std::optional<glm::dvec3> screen_hit(const Screen& screen, const glm::dvec3& p_origin,
                                     const glm::dvec3& v_dir) {
  const auto t = intersect_screen(screen, p_origin, v_dir);
  if (!t) return std::nullopt;
  return p_origin + *t * v_dir;
}

glm::dvec3 screen_normal(const Screen& screen, const glm::dvec3& p_on_screen) {
  switch (screen.type) {
    case Screen::Type::sphere:
      return glm::normalize(screen.center - p_on_screen);
    case Screen::Type::cylinder: {
      const glm::dvec3 axis = glm::normalize(screen.axis);
      const glm::dvec3 o = p_on_screen - screen.center;
      return glm::normalize(-(o - glm::dot(o, axis) * axis));
    }
    case Screen::Type::plane:
      return glm::normalize(screen.normal);
  }
  return screen.normal;
}

}  // namespace facet
