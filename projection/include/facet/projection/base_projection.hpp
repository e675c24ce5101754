#pragma once
// Base projections of FORMATS.md §2: maps between normalised base-image coordinates st = (s, t)
// in [0,1]² (t grows downwards) and directions b in the base frame (x right, y up, looking down
// -z).
#include <array>
#include <glm/glm.hpp>
#include <limits>
#include <optional>
#include <string>

namespace facet {

enum class BaseKind { perspective, fisheye, cylindrical, equirectangular };

std::string to_string(BaseKind kind);
// Throws InputError(source, field, ...) for an unknown name.
BaseKind base_kind_from_string(const std::string& name, const std::string& source = {},
                               const std::string& field = "base");

// The largest tangent a perspective's or a cylinder's edge may have (89.99994°): beyond it the
// facet builders chase a map that no output pixel can resolve (tan 1e9 at 160x120 built facets
// until it ran out of memory).
inline constexpr double kMaxTangent = 1e6;

struct BaseProjection {
  BaseKind kind = BaseKind::perspective;
  // perspective: tangents [left, right, top, bottom] of the image edges.
  std::array<double, 4> tan_extent{-1.0, 1.0, 1.0, -1.0};
  // fisheye (azimuthal equidistant): full angle across the inscribed circle, degrees, in (0, 360].
  double fov_deg = 180.0;
  // cylindrical and equirectangular: azimuth of s = 0 and s = 1, degrees; 0 looks down -z and
  // positive turns towards +x. |a1 - a0| <= 360.
  std::array<double, 2> azimuth_deg{-180.0, 180.0};
  // cylindrical: tan(elevation) at t = 0 (top) and t = 1 (bottom).
  std::array<double, 2> tan_elevation{1.0, -1.0};
  // equirectangular: elevation at t = 0 (top) and t = 1 (bottom), degrees, within [-90, 90].
  std::array<double, 2> elevation_deg{90.0, -90.0};

  static BaseProjection perspective(double left, double right, double top, double bottom);
  // Symmetric perspective from full fields of view in degrees; InputError unless both are in
  // (0, 180).
  static BaseProjection perspective_fov(double fov_x_deg, double fov_y_deg);
  static BaseProjection fisheye(double fov_deg);
  static BaseProjection cylindrical(double a0_deg, double a1_deg, double tan_top,
                                    double tan_bottom);
  static BaseProjection equirectangular(double a0_deg, double a1_deg, double top_deg,
                                        double bottom_deg);

  // Throws InputError naming `source` and the field when a parameter is non-finite or out of its
  // domain (for example a perspective field of view of 180° or more, or a tangent beyond
  // kMaxTangent).
  void validate(const std::string& source = {}) const;

  // True when s = 0 and s = 1 are the same direction (a full 360° azimuth).
  bool wraps_horizontally() const;

  // A point on the base's natural surface for st, in the base frame (not normalised):
  // the plane z = -1 for perspective, the unit cylinder for cylindrical, the unit sphere otherwise.
  // Facet corners are taken here so that the seed's cylinder strips and a perspective base are
  // exactly planar.
  glm::dvec3 surface_point(glm::dvec2 st) const;
  // The unit direction for st. Defined for every st, also outside [0,1]².
  glm::dvec3 direction(glm::dvec2 st) const;

  // Inverse map: base-frame direction (any length > 0) to st. The result may lie outside [0,1]²;
  // nullopt where the base has no value (behind a perspective image plane, on a cylinder's axis,
  // beyond a fisheye's reach, non-finite input). For bases that wrap in azimuth, the branch is
  // chosen nearest to s_hint when given, else inside [0,1] when possible.
  std::optional<glm::dvec2> st_from_direction(
      glm::dvec3 b, double s_hint = std::numeric_limits<double>::quiet_NaN()) const;
};

}  // namespace facet
