#pragma once
// Where the eye starts in a scene and how it moves when nobody steers: the view of `facet render`
// and `facet run` (--eye, --look-at, --camera).
//
// Frames as everywhere in the driver: world in metres, y up; the eye frame has x right, y up and
// looks down -z.
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "facet/driver/scene.hpp"

namespace facet::driver {

// What the command line asked for. All empty: the default view.
struct ViewRequest {
  std::optional<glm::dvec3> eye_world;      // --eye
  std::optional<glm::dvec3> look_at_world;  // --look-at; needs eye_world
  std::string camera;                       // --camera: a SceneCamera's name or camera_name
};

// Parses "X,Y,Z": three finite numbers (metres, world frame), separated by commas, spaces
// allowed around them. InputError("command line", flag, what was expected and what was given).
glm::dvec3 parse_point(std::string_view text, std::string_view flag);
// The largest coordinate parse_point accepts, in metres.
inline constexpr double kMaxPointMetres = 1e7;

struct SceneView {
  // The built-in city's camera path (CityCameraPath) drives the eye; the fields below are unused.
  bool follows_city_path = false;
  glm::dmat4 T_world_eye{1.0};  // the starting pose
  // The view turns about the vertical line (world y) through this point: the eye itself (the eye
  // turns on the spot) or the point looked at (the eye circles it, keeping it in view).
  glm::dvec3 pivot_world{0.0};
  // True when the starting eye is inside closed geometry (eye_inside_geometry).
  bool eye_inside = false;
  // One line for the user, or empty: where the default eye was put and why, or a warning that the
  // eye asked for is inside geometry. Without a program name or a trailing newline.
  std::string message;

  // The pose after `turns` whole turns (1: 360°) counter-clockwise seen from above, about the
  // vertical through pivot_world.
  glm::dmat4 T_world_eye_turned(double turns) const;
};

// The view of `scene`:
// - camera: the SceneCamera of that name (its name, else its camera_name), turning on the spot.
//   InputError("command line", OptionName "camera", ...) listing the cameras when none has that
//   name, or saying the scene has none. Not together with eye_world.
// - eye_world: the eye there, looking at look_at_world (default: the bounds' centre), circling
//   the point looked at. InputError naming --eye / --look-at when the two coincide, and naming
//   --look-at when it comes without --eye.
// - neither, a scene holding a SceneCamera named kDepthImageEyeCamera (a depth image's mesh,
//   depth_image.hpp): the eye at that camera, turning on the spot.
// - neither, built-in city: its camera path.
// - neither, other scenes: the eye at the bounds' centre, turning on the spot; but when that
//   centre is inside closed geometry (eye_inside_geometry) the eye goes outside and above the
//   model, at centre + (0, 0.6 r, 1.6 r) with r half the bounds' diagonal, looking at the centre
//   and circling it; `message` says so.
// An explicit eye or camera inside geometry is kept, with a warning in `message`.
SceneView choose_scene_view(const Scene& scene, const ViewRequest& request, bool builtin_city);

// The camera a depth image's mesh carries at the image's eye point (depth_image_mesh).
inline constexpr const char* kDepthImageEyeCamera = "depth-image-eye";

// The number of rays cast by eye_inside_geometry.
inline constexpr int kInsideTestRays = 26;

// Back-face hits among kInsideTestRays rays from p_world towards the 26 neighbours of a cube
// cell (slightly turned, so that no ray runs exactly along an edge or through a vertex of an
// axis-aligned model): a ray whose nearest hit is a triangle seen from its back (clockwise, as
// GL culls it) left the inside of a closed surface.
int back_face_hits(const Scene& scene, const glm::dvec3& p_world);

// True when most rays (more than half) from p_world hit a back face first: p_world is inside
// closed geometry, where the renderers (which cull back faces) show nothing or the far side.
bool eye_inside_geometry(const Scene& scene, const glm::dvec3& p_world);

}  // namespace facet::driver
