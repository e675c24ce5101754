#pragma once
// The display surface and where rays meet it. Points and directions are in the eye frame
// (x right, y up, looking down −z), metres.
#include <glm/glm.hpp>
#include <optional>

namespace facet {

struct Screen {
  enum class Type { sphere, cylinder, plane };
  Type type = Type::sphere;
  glm::dvec3 center{0.0};            // sphere, cylinder: a point on the axis
  glm::dvec3 axis{0.0, 1.0, 0.0};    // cylinder: unit direction of the axis
  double radius = 0;                 // sphere, cylinder: > 0
  glm::dvec3 point{0.0};             // plane: a point on it
  glm::dvec3 normal{0.0, 0.0, 1.0};  // plane: unit normal

  bool operator==(const Screen&) const = default;
};

// Distance t >= 0 along the ray p_origin + t·v_dir (v_dir of any length > 0; t is in units of
// |v_dir|) at which the ray meets the screen, or nullopt.
//   - sphere, cylinder (infinitely long): the larger root of the quadratic when it is positive.
//     From inside, that is the one hit; from outside, it is the far wall seen from within, which
//     is the side a display viewed from inside shows. A ray that only grazes the surface (a double
//     root) counts as a hit. A ray parallel to a cylinder's axis misses.
//   - plane: the one hit when it lies ahead (t > 0); a ray parallel to the plane, or starting on
//     it, misses. Both sides of the plane count.
// Non-finite input misses.
std::optional<double> intersect_screen(const Screen& screen, const glm::dvec3& p_origin,
                                       const glm::dvec3& v_dir);

// The hit point itself, or nullopt.
std::optional<glm::dvec3> screen_hit(const Screen& screen, const glm::dvec3& p_origin,
                                     const glm::dvec3& v_dir);

// Unit normal of the screen at a point on it (the point is not checked): towards the axis or
// centre for spheres and cylinders (the inside, where the audience sits), `normal` for a plane.
glm::dvec3 screen_normal(const Screen& screen, const glm::dvec3& p_on_screen);

}  // namespace facet
