#include "facet/driver/scene_view.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <numbers>
#include <stdexcept>

#include "facet/driver/reference.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

std::string format_point(const glm::dvec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.3g, %.3g, %.3g)", p.x, p.y, p.z);
  return text;
}

// The pose of an eye at p_eye looking at p_target, with world y up on the view (world -z when
// looking straight up or down).
glm::dmat4 look_at(const glm::dvec3& p_eye, const glm::dvec3& p_target) {
  const glm::dvec3 forward = glm::normalize(p_target - p_eye);
  const glm::dvec3 up = glm::length(glm::cross(forward, glm::dvec3(0, 1, 0))) > 1e-9
                            ? glm::dvec3(0, 1, 0)
                            : glm::dvec3(0, 0, -1);
  return glm::inverse(glm::lookAt(p_eye, p_target, up));
}

// The world-frame corners of the triangle with reference ID `id` (numbering of
// render_method.hpp), computed in float as the ray caster and the vertex shaders do.
std::array<glm::vec3, 3> triangle_world(const Scene& scene, std::uint32_t id) {
  std::uint64_t remaining = id - 1u;
  for (const Object& object : scene.objects) {
    for (std::uint32_t i = 0; i < object.primitive_count; ++i) {
      const Primitive& primitive = scene.primitives[object.first_primitive + i];
      const std::uint64_t triangles = primitive.index_count / 3;
      if (remaining >= triangles) {
        remaining -= triangles;
        continue;
      }
      std::array<glm::vec3, 3> corners;
      for (std::size_t k = 0; k < 3; ++k) {
        const glm::vec3& p_object =
            scene.positions[scene.indices[primitive.first_index + 3 * remaining + k]];
        corners[k] = glm::vec3(object.T_world_object * glm::vec4(p_object, 1.0f));
      }
      return corners;
    }
  }
  throw std::logic_error("triangle_world: no triangle has ID " + std::to_string(id));
}

}  // namespace

glm::dvec3 parse_point(std::string_view text, std::string_view flag) {
  const auto refuse = [&](const std::string& why) {
    throw InputError("command line", std::string(flag),
                     "expected X,Y,Z: three numbers in metres, world frame (y up); got '" +
                         std::string(text) + "' (" + why + ")");
  };
  glm::dvec3 point(0.0);
  std::string_view rest = text;
  for (int axis = 0; axis < 3; ++axis) {
    const std::size_t comma = rest.find(',');
    if ((comma == std::string_view::npos) != (axis == 2))
      refuse(axis == 2 ? "more than three numbers" : "fewer than three numbers");
    std::string_view item = rest.substr(0, comma);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (!item.empty() && item.front() == '+') item.remove_prefix(1);
    double value = 0;
    const auto [end, error] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || error != std::errc() || end != item.data() + item.size() ||
        !std::isfinite(value))
      refuse("'" + std::string(item) + "' is not a finite number");
    // 10,000 km: past it a float (what the GL draws with) keeps less than a metre.
    if (std::abs(value) > kMaxPointMetres) refuse("'" + std::string(item) + "' is past ±1e7 m");
    point[axis] = value;
    if (comma != std::string_view::npos) rest = rest.substr(comma + 1);
  }
  return point;
}

glm::dmat4 SceneView::T_world_eye_turned(double turns) const {
  const double angle = 2 * std::numbers::pi * turns;
  const glm::dmat4 turn = glm::translate(
      glm::rotate(glm::translate(glm::dmat4(1.0), pivot_world), angle, glm::dvec3(0, 1, 0)),
      -pivot_world);
  return turn * T_world_eye;
}

int back_face_hits(const Scene& scene, const glm::dvec3& p_world) {
  if (scene.triangle_count() == 0) return 0;
  const ReferenceRaycaster raycaster(scene, {.cull_back_faces = false});
  // A small fixed turn off the axes, so that no ray grazes an edge of an axis-aligned box.
  const glm::dmat4 R_tilt = glm::rotate(glm::rotate(glm::dmat4(1.0), 0.0937, glm::dvec3(1, 0, 0)),
                                        0.0611, glm::dvec3(0, 1, 0));
  int hits = 0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        if (x == 0 && y == 0 && z == 0) continue;
        const glm::dvec3 v_world = glm::dvec3(R_tilt * glm::dvec4(x, y, z, 0.0));
        const std::uint32_t id = raycaster.id_along(p_world, v_world);
        if (id == 0) continue;
        const auto [a, b, c] = triangle_world(scene, id);
        const glm::dvec3 normal = glm::cross(glm::dvec3(b - a), glm::dvec3(c - a));
        if (glm::dot(normal, v_world) > 0) ++hits;
      }
  return hits;
}

bool eye_inside_geometry(const Scene& scene, const glm::dvec3& p_world) {
  return 2 * back_face_hits(scene, p_world) > kInsideTestRays;
}

SceneView choose_scene_view(const Scene& scene, const ViewRequest& request, bool builtin_city) {
  const Aabb bounds = scene.bounds_world();
  const glm::dvec3 centre = bounds.empty() ? glm::dvec3(0.0) : glm::dvec3(bounds.centre());
  SceneView view;
  const auto warn_if_inside = [&](const std::string& what, const glm::dvec3& p_eye_world) {
    const int hits = back_face_hits(scene, p_eye_world);
    view.eye_inside = 2 * hits > kInsideTestRays;
    if (view.eye_inside)
      view.message = "warning: " + what + " " + format_point(p_eye_world) +
                     " is inside geometry (" + std::to_string(hits) + " of " +
                     std::to_string(kInsideTestRays) +
                     " rays from it hit a back face first): little or nothing may be seen";
  };

  if (!request.camera.empty()) {
    if (request.eye_world || request.look_at_world)
      throw InputError("command line", OptionName{"camera"},
                       "expected either a scene camera or an eye point (and a point to look at), "
                       "not both");
    if (scene.cameras.empty())
      throw InputError("command line", OptionName{"camera"},
                       "expected the name of one of the scene's cameras; " +
                           (scene.name.empty() ? std::string("the scene") : scene.name) +
                           " has none");
    // A node name first; a camera's own name when no node has the name.
    const auto by_name =
        std::find_if(scene.cameras.begin(), scene.cameras.end(),
                     [&](const SceneCamera& c) { return c.name == request.camera; });
    const auto by_camera_name =
        std::find_if(scene.cameras.begin(), scene.cameras.end(),
                     [&](const SceneCamera& c) { return c.camera_name == request.camera; });
    const auto found = by_name != scene.cameras.end() ? by_name : by_camera_name;
    if (found == scene.cameras.end()) {
      std::string names;
      for (const SceneCamera& camera : scene.cameras)
        names += (names.empty() ? "'" : ", '") + camera.name + "'";
      throw InputError(
          "command line", OptionName{"camera"},
          "expected one of the scene's cameras: " + names + "; got '" + request.camera + "'");
    }
    view.T_world_eye = found->T_world_camera;
    view.pivot_world = glm::dvec3(view.T_world_eye[3]);
    warn_if_inside("camera '" + found->name + "' at", view.pivot_world);
    return view;
  }

  if (request.eye_world) {
    const glm::dvec3 target = request.look_at_world.value_or(centre);
    if (glm::length(target - *request.eye_world) < 1e-9)
      throw InputError("command line",
                       OptionName{request.look_at_world ? "look_at_world" : "eye_world"},
                       "expected an eye point apart from the point looked at (by default the scene "
                       "bounds' centre " +
                           format_point(centre) + "); both are " + format_point(target));
    view.T_world_eye = look_at(*request.eye_world, target);
    view.pivot_world = target;
    warn_if_inside("the eye point", *request.eye_world);
    return view;
  }
  if (request.look_at_world)
    throw InputError("command line", OptionName{"look_at_world"},
                     "expected an eye point as well: the point to look from");

  const auto depth_eye =
      std::find_if(scene.cameras.begin(), scene.cameras.end(),
                   [](const SceneCamera& c) { return c.name == kDepthImageEyeCamera; });
  if (depth_eye != scene.cameras.end()) {
    view.T_world_eye = depth_eye->T_world_camera;
    view.pivot_world = glm::dvec3(view.T_world_eye[3]);
    return view;
  }
  if (builtin_city) {
    view.follows_city_path = true;
    return view;
  }
  view.T_world_eye = glm::translate(glm::dmat4(1.0), centre);
  view.pivot_world = centre;
  const int hits = back_face_hits(scene, centre);
  if (2 * hits > kInsideTestRays) {
    const double r = 0.5 * glm::length(glm::dvec3(bounds.p_max - bounds.p_min));
    const glm::dvec3 eye = centre + glm::dvec3(0, 0.6 * r, 1.6 * r);
    view.T_world_eye = look_at(eye, centre);
    view.message = "the eye is at " + format_point(eye) +
                   ", outside and above the model, looking at its bounds' centre " +
                   format_point(centre) + ", which is inside geometry (" + std::to_string(hits) +
                   " of " + std::to_string(kInsideTestRays) +
                   " rays from it hit a back face first); an eye point, a point to look at or a "
                   "scene camera chooses another view";
  }
  return view;
}

}  // namespace facet::driver
