#pragma once
// Content images in the eye's frame: how a fisheye dome master, an equirectangular panorama, a
// cube map or a per-projector perspective image maps eye directions to its pixels. The GL pass
// that resamples content through a display's exact warp (driver/content_pass.hpp) mirrors these
// maps in GLSL; tests compare the two.
//
// Image coordinates st are normalised, in [0,1]², s right and t down (row 0 of the image at the
// top), as for warps (FORMATS.md §2). The eye frame is x right, y up, −z ahead.
#include <array>
#include <glm/glm.hpp>
#include <optional>
#include <string>

#include "facet/projection/base_projection.hpp"
#include "facet/projection/dome_orientation.hpp"
#include "facet/projection/warp.hpp"

namespace facet {

enum class ContentFormat {
  // A dome master: azimuthal equidistant, square, its centre the dome's zenith and its bottom
  // edge the dome's front (FisheyeZenith::centre), any full field of view in (0, 360].
  fisheye,
  // 360° × 180°: s = 0 and s = 1 look behind (+z), s = 0.5 ahead (−z), s grows towards +x;
  // t = 0 is straight up, t = 1 straight down. Width twice the height.
  equirect,
  // Six square faces side by side in one 6:1 strip, in OpenGL's order and orientation (OpenGL
  // 4.5 §8.13, the layout of KTX and DDS cube maps): +x, −x, +y, −y, +z, −z of the content
  // frame. Within face f the major axis is a_m·v, and s = (a_s·v / a_m·v + 1)/2,
  // t = (a_t·v / a_m·v + 1)/2 (kCubeFaces; t = 0 is the face image's top row).
  cubemap,
  // A perspective image over `tan_extent` of the content frame (BaseProjection::perspective): an
  // application's rendering of one projector's frustum (covering_frustum).
  perspective,
};

std::string to_string(ContentFormat format);
// "fisheye", "equirect" (or "equirectangular"), "cubemap", "perspective"; InputError(source,
// field, ...) otherwise.
ContentFormat content_format_from_string(const std::string& name, const std::string& source,
                                         const std::string& field);

// OpenGL's cube-map face axes (OpenGL 4.5 table 8.19), faces +x, −x, +y, −y, +z, −z: the one
// table of cube faces, for the cubemap content format and the driver's cube-map render method.
struct CubeFaceAxes {
  glm::dvec3 a_s, a_t, a_m;
};
extern const std::array<CubeFaceAxes, 6> kCubeFaces;
// The face GL selects for v (the largest |component|; ties go to x, then y).
int cube_face_of(glm::dvec3 v);

// A point of a content image: the cube face (0 for every other format) and st within it.
struct ContentPoint {
  int face = 0;
  glm::dvec2 st{0.0};
};

struct ContentProjection {
  ContentFormat format = ContentFormat::fisheye;
  // fisheye: the full field of view in degrees, (0, 360]; 180 is the usual dome master.
  double fov_deg = 180;
  // perspective: tangents [left, right, top, bottom] of the image edges in the content frame.
  std::array<double, 4> tan_extent{-1.0, 1.0, 1.0, -1.0};
  // Content-frame directions into the eye frame. For a fisheye this is
  // DomeOrientation::R_eye_dome() · R_dome_fisheye(centre) (fisheye_content).
  glm::dmat3 R_eye_content{1.0};

  // InputError(source, OptionName "fov_deg", ...) for a field of view outside (0, 360]; perspective
  // extents must be finite with left < right and top > bottom ("tan_extent").
  void validate(const std::string& source) const;

  // The image point that shows eye direction v_eye (any length > 0); nullopt where the content
  // has no value (beyond a fisheye's field of view, outside a perspective image, behind it).
  // Equirect s is in [0, 1).
  std::optional<ContentPoint> point_from_v_eye(glm::dvec3 v_eye) const;
  // The unit eye direction shown at an image point (the inverse of point_from_v_eye).
  glm::dvec3 v_eye_from_point(const ContentPoint& point) const;
};

// A dome master of `fov_deg` (default 180) on a dome oriented as `orientation` says: its zenith
// where the tilted, turned dome's zenith is, its bottom edge the dome's front.
ContentProjection fisheye_content(double fov_deg = 180, const DomeOrientation& orientation = {});
// An equirectangular panorama or a cube map whose frame is turned by `orientation` (tilt then
// heading, as for a dome; the identity by default).
ContentProjection equirect_content(const DomeOrientation& orientation = {});
ContentProjection cubemap_content(const DomeOrientation& orientation = {});

// A perspective view for applications that render their own content: T_eye_frustum rotates the
// view's frame (x right, y up, looking down −z) into the eye frame; tan_extent as
// BaseProjection::perspective.
struct Frustum {
  glm::dmat3 R_eye_frustum{1.0};
  std::array<double, 4> tan_extent{-1.0, 1.0, 1.0, -1.0};

  // The OpenGL projection matrix (glFrustum's, clip z in [−w, w]) for near and far distances in
  // metres, 0 < z_near < z_far; apply after the view rotation transpose(R_eye_frustum).
  glm::dmat4 gl_projection(double z_near, double z_far) const;
  // The perspective content this frustum's rendering is (format perspective).
  ContentProjection content() const;
};

// The narrowest-looking perspective frustum that holds every direction `warp` shows: its axis
// the normalised mean of the covered directions, its up the eye's +y made perpendicular to the
// axis (the eye's −z when the axis is vertical), its extents the tangents of the covered
// directions (the warp's base image sampled on a 257 × 257 grid of st, edges included, where
// its coverage is at least 0.5) widened by `margin` (a fraction of the extent on each side),
// so it holds every direction the output shows and a little more. InputError
// (source, "warp", ...) when some covered direction is 80° or more from the axis: a single
// perspective image cannot hold it (a 180° dome projector, a 360° cylinder); render a cube map
// or a fisheye instead.
Frustum covering_frustum(const Warp& warp, const std::string& source, double margin = 0.01);

}  // namespace facet
