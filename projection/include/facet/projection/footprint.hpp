#pragma once
// Choosing a base projection that covers a set of view directions: the footprint of a projector
// seen from the eye. Used for the ground-truth warps of the virtual rig and for calibrated warps,
// so that every projector's offset map spends its nodes where the projector shines.
#include <glm/glm.hpp>
#include <optional>
#include <span>

#include "facet/projection/base_projection.hpp"

namespace facet {

struct CoverOptions {
  // Extra angle added on every side of the footprint, radians. It keeps the warp defined a little
  // beyond the projector's edge, so that coverage can fall off between nodes there.
  double margin_rad = 0.035;  // about 2°
  // A footprint whose directions all lie within this angle of their mean direction (margin
  // included) gets a perspective base; perspective keeps straight lines straight and is exact
  // with two facets. Wider footprints get a fisheye, cylindrical or equirectangular base.
  double max_perspective_half_angle_rad = 1.05;  // about 60°
  // Cylindrical bases are used while every direction's elevation above the eye's horizontal
  // plane (the plane y = 0) stays within this angle, margin included; tan(elevation) grows
  // without bound towards the poles.
  double max_cylindrical_elevation_rad = 1.22;  // about 70°
  // The eye-frame direction that should appear as "up" (towards t = 0) in the base image, for
  // example a projector's up vector, so that the offsets stay small. Any direction not parallel
  // to the footprint's centre works; without it the eye's +y is used (or −z when the centre is
  // nearly vertical). Only the perspective and fisheye bases use it: cylindrical and
  // equirectangular bases keep the eye's vertical axis.
  std::optional<glm::dvec3> up_eye;
};

struct BaseCover {
  BaseProjection base;
  glm::dmat3 R_eye_base{1.0};  // base-frame directions into the eye frame
};

// A base projection and its rotation whose image [0,1]² contains every direction of v_eye (any
// length > 0; zero or non-finite vectors are ignored) plus the margin. The rule, in order:
//   - perspective, centred on the mean direction, when the footprint fits within
//     max_perspective_half_angle_rad of it;
//   - cylindrical about the eye's y axis when every elevation stays within
//     max_cylindrical_elevation_rad; the azimuth range is the smallest arc that holds every
//     direction (the full 360°, seam at the widest gap, when the arc plus margins reaches it);
//   - fisheye centred on the mean direction when its field of view stays at most 340°;
//   - equirectangular otherwise (with the elevation range clamped to [-90°, 90°]).
// The rule looks only at the directions given, so pass a dense enough sampling of the footprint's
// outline (for example every projector pixel along the image border) and its interior when the
// footprint may be concave. Asserts that at least one valid direction is given.
BaseCover cover_directions(std::span<const glm::dvec3> v_eye, const CoverOptions& options = {});

}  // namespace facet
