#pragma once
// A scene as plain CPU data: no GL. `upload_scene` (gpu_scene.hpp) turns it into buffers.
//
// Frames and units: vertex positions are in the object's own frame, in metres; an object's
// T_world_object maps them into the world frame (metres, y up, ground at y = 0 for the built-in
// city, as in glTF). Triangles are counter-clockwise when seen from their front side.
#include <array>
#include <cstdint>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "facet/driver/animation.hpp"

namespace facet::driver {

// Axis-aligned box. Empty (p_min > p_max) until a point is added.
struct Aabb {
  glm::vec3 p_min{std::numeric_limits<float>::infinity()};
  glm::vec3 p_max{-std::numeric_limits<float>::infinity()};

  bool empty() const { return p_min.x > p_max.x || p_min.y > p_max.y || p_min.z > p_max.z; }
  void extend(const glm::vec3& p);
  void extend(const Aabb& box);
  // True when p lies inside the box grown by `margin` (same units) on every side.
  bool contains(const glm::vec3& p, float margin = 0) const;
  glm::vec3 centre() const { return 0.5f * (p_min + p_max); }
};

// An RGBA8 image, rows from the top, sRGB-encoded colour with linear alpha.
struct Image {
  std::string name;
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4 bytes
};

// A material's fragment shading (driver/material_shader.hpp loads and links it): GLSL defining
// `vec4 shade(MaterialInput m)` against shaders/scene/material_interface.frag.
struct MaterialShader {
  std::string name = "lit";  // a built-in's name, or the file as the user gave it
  // What compiler messages name: shaders/scene/materials/NAME.frag, or the user's file.
  std::string file;
  std::string text;  // the material's GLSL; empty: the built-in `name`
  bool operator==(const MaterialShader&) const = default;
};

struct Material {
  std::string name;
  glm::vec4 base_colour{1.0f};  // linear RGBA factor, multiplied with the texture
  int texture = -1;             // index into Scene::images, or -1 for none
  bool repeat = true;           // texture coordinates wrap (else clamp to edge)
  // Shown as authored: base colour times texture, no lighting (glTF KHR_materials_unlit).
  bool unlit = false;
  // Its own shading; none: the render's (RenderSettings::material, the CLI's --material).
  std::optional<MaterialShader> shader{};
};

// A run of triangles that share one material: indices [first_index, first_index + index_count).
struct Primitive {
  std::uint32_t first_index = 0;
  std::uint32_t index_count = 0;  // a multiple of 3
  std::uint32_t material = 0;     // index into Scene::materials
};

// One placed mesh instance. Several objects may share primitives (instancing).
struct Object {
  std::string name;
  glm::mat4 T_world_object{1.0f};
  std::uint32_t first_primitive = 0, primitive_count = 0;  // range in Scene::primitives
  Aabb bounds_world;  // tight box around this object's vertices, in the world frame
};

// A viewpoint stored in the scene file (a glTF node with a camera). The camera frame is the eye
// frame: x right, y up, looking down -z.
struct SceneCamera {
  std::string name;                // the node's name, else the camera's, else "nodes[i]"
  std::string camera_name;         // the glTF camera's own name (may be empty)
  glm::dmat4 T_world_camera{1.0};  // rigid: the node's world transform with scale removed
  bool orthographic = false;       // drawn with the display's own projection either way
};

struct Scene {
  std::string name;
  // Vertex attributes, one entry per vertex, in the object frame of the objects using them.
  std::vector<glm::vec3> positions;    // metres
  std::vector<glm::vec3> normals;      // unit length
  std::vector<glm::vec2> uvs;          // texture coordinates, (0,0) = first texel of the first row
  std::vector<std::uint32_t> indices;  // triangle list into the vertex arrays
  std::vector<Primitive> primitives;
  std::vector<Object> objects;
  std::vector<Material> materials;
  std::vector<Image> images;
  std::vector<SceneCamera> cameras;  // in the order the scene graph is visited
  // Keyframed node animations (glTF); empty for a still scene. Object::T_world_object stays the
  // rest pose; Session places animated objects at each frame's time.
  SceneAnimation animation;

  // Triangles drawn, counting each instance: sum over objects of their primitives' triangles.
  std::size_t triangle_count() const;
  // Union of the objects' world bounds.
  Aabb bounds_world() const;
  // Recomputes every object's bounds_world from its vertices and T_world_object.
  void update_bounds();
};

// An object's bounding sphere about its world box (the box's centre, half its diagonal), carried
// into another frame by a rigid transform; radius < 0 for an object without vertices.
struct BoundingSphere {
  glm::dvec3 centre{0.0};
  double radius = -1;
};
// Every object's BoundingSphere in the frame T_frame_world (rigid) leads to, in the objects' order.
std::vector<BoundingSphere> object_spheres(const Scene& scene, const glm::dmat4& T_frame_world);
// True when `sphere` lies wholly outside one of `planes` (in the sphere's frame; a point X is
// inside plane p when dot(p.xyz, X) + p.w >= 0, p.xyz of any length), as frustum culling asks.
bool sphere_outside_a_plane(const BoundingSphere& sphere, std::span<const glm::dvec4> planes);
// The side planes (x >= -w, x <= w, y >= -w, y <= w) of the clip transform T_clip_frame, in the
// frame it takes points from, as sphere_outside_a_plane reads them.
std::array<glm::dvec4, 4> frustum_side_planes(const glm::dmat4& T_clip_frame);

// The scene with every triangle cut into n² (regular subdivision: each edge in n equal parts,
// the pieces of one triangle sharing their vertices), positions, texture coordinates and normals
// interpolated linearly (normals renormalised). Primitives, objects, materials and images keep
// their order, so primitive p of the result holds n² times the triangles of primitive p, in the
// original triangles' order; object bounds are recomputed (update_bounds). Throws
// std::invalid_argument when n is not in [1, 64] or the result would need more than 2^32 - 1
// vertices or indices.
Scene subdivide_triangles(const Scene& scene, int n);

// 64-bit FNV-1a over the vertex, index and primitive data (exact bits): equal scenes hash equal.
std::uint64_t geometry_hash(const Scene& scene);

}  // namespace facet::driver
