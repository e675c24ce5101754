#pragma once
// How a dome sits around the viewer, and how a fisheye master's image lies on it.
//
// The eye frame is x right, y up, −z ahead (the viewer's front). A dome's own frame is the same
// for an untilted dome facing the viewer's front: its zenith is +y, its front −z. A display is
// placed by rotating its warps' directions about the eye: R_eye_base ← R_eye_dome · R_eye_base.
#include <cmath>
#include <glm/glm.hpp>
#include <numbers>
#include <sstream>
#include <string>

#include "facet/projection/errors.hpp"

namespace facet {

namespace detail {
inline std::string degrees_text(double degrees) {
  std::ostringstream text;
  text << degrees;
  return text.str();
}
}  // namespace detail

struct DomeOrientation {
  // The dome tilted forward about eye +x: its zenith moves from +y toward the front (−z) by this
  // angle, its front edge goes down. Planetarium domes are often tilted 15–30°. In [−90°, 90°].
  double tilt_deg = 0;
  // The dome then turned about the vertical (eye +y): its front turns from −z toward the right
  // (+x) by this angle, as a compass heading (SGCT's and MPCDI's heading). In [−360°, 360°].
  double orientation_deg = 0;

  // Ry(−orientation)·Rx(−tilt): the zenith +y goes to (sin o·sin t, cos t, −cos o·sin t).
  glm::dmat3 R_eye_dome() const {
    const double t = tilt_deg * std::numbers::pi / 180,
                 o = orientation_deg * std::numbers::pi / 180;
    // glm matrices are column-major: each dvec3 is a column.
    const glm::dmat3 R_tilt(glm::dvec3(1, 0, 0), glm::dvec3(0, std::cos(t), -std::sin(t)),
                            glm::dvec3(0, std::sin(t), std::cos(t)));
    const glm::dmat3 R_turn(glm::dvec3(std::cos(o), 0, std::sin(o)), glm::dvec3(0, 1, 0),
                            glm::dvec3(-std::sin(o), 0, std::cos(o)));
    return R_turn * R_tilt;
  }

  // InputError(source, OptionName "tilt_deg" or "orientation_deg", ...) for a value out of range
  // or not finite.
  void validate(const std::string& source) const {
    if (!(std::isfinite(tilt_deg) && std::abs(tilt_deg) <= 90)) {
      throw InputError(source, OptionName{"tilt_deg"},
                       "expected the dome's forward tilt in degrees within [−90, 90]; got " +
                           detail::degrees_text(tilt_deg));
    }
    if (!(std::isfinite(orientation_deg) && std::abs(orientation_deg) <= 360)) {
      throw InputError(source, OptionName{"orientation_deg"},
                       "expected the dome's azimuth turn in degrees within [−360, 360]; got " +
                           detail::degrees_text(orientation_deg));
    }
  }
};

// Where a fisheye master's image centre points on the dome.
enum class FisheyeZenith {
  centre,  // the image centre is the zenith (+y), its bottom edge the front (−z), its top edge
           // behind (+z), its right edge +x: the usual dome master layout
  front,   // the image centre is straight ahead (−z), its top edge up (+y), its right edge +x
};

// The rotation of a fisheye base frame (view axis −z, image up +y) into the dome frame.
inline glm::dmat3 R_dome_fisheye(FisheyeZenith zenith) {
  if (zenith == FisheyeZenith::front) return glm::dmat3(1.0);
  // Columns: base x → +x, base y (image up) → +z (behind), base z → −y (so the view axis −z → +y).
  return glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0));
}

// "centre" (or "center") or "front"; InputError(source, field, ...) otherwise.
inline FisheyeZenith fisheye_zenith_from_string(const std::string& text, const std::string& source,
                                                const std::string& field) {
  if (text == "centre" || text == "center") return FisheyeZenith::centre;
  if (text == "front") return FisheyeZenith::front;
  throw InputError(source, field,
                   "expected centre (the fisheye's centre is overhead) or front (straight "
                   "ahead); got '" +
                       text + "'");
}

}  // namespace facet
