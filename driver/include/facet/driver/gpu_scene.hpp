#pragma once
// GPU copies of a Scene: buffers for vertex attributes and indices (usable both as vertex
// arrays and as shader storage for vertex pulling), per-material and per-object tables, and
// textures.
#include <cstdint>
#include <vector>

#include "facet/driver/gl_objects.hpp"
#include "facet/driver/scene.hpp"

namespace facet::driver {

// std430 layout of one entry of GpuScene::materials.
struct GpuMaterial {
  float base_colour[4];  // linear RGBA
  std::int32_t texture;  // index into GpuScene::textures, or -1
  std::uint32_t repeat;  // 1: texture coordinates wrap, 0: clamp
  std::uint32_t unlit;   // 1: shown as authored, no lighting (Material::unlit)
  std::uint32_t padding;
};
static_assert(sizeof(GpuMaterial) == 32);

// std430 layout of one entry of GpuScene::objects.
struct GpuObject {
  float T_world_object[16];  // column-major
  float bounds_min[4];       // world frame, metres; w unused
  float bounds_max[4];
  std::uint32_t first_primitive, primitive_count, padding[2];
};
static_assert(sizeof(GpuObject) == 112);

// Where GpuScene::bind_for_pulling puts the scene for shaders that pull their vertices
// (shaders/replication/replication_lib.comp, shaders/baselines/pull_scene.vert): the vertices as
// buffer textures, not shader storage: llvmpipe (Mesa 22.3) loads a shader storage component one
// SIMD lane at a time, in a loop with a branch per lane, and fetches a texel for all lanes at
// once. The indices stay shader storage: as an R32UI buffer texture, the walk pass of `facets`
// (replication/count.comp) took 530 ms a cylinder frame instead of 6, for reasons not found.
namespace pulling {
inline constexpr GLuint indices_binding = 3;
inline constexpr GLuint position_unit = 8, normal_unit = 9, uv_unit = 10;
}  // namespace pulling

// The uniform block binding of shaders/scene/material.frag's MaterialShading block (one uint:
// 1 for an unlit material). bind_material_texture binds the material's entry of
// GpuScene::material_shading there, so every renderer that binds a material's texture gets its
// shading too.
inline constexpr GLuint material_shading_binding = 0;

struct GpuScene {
  // Tightly packed floats, 3 per vertex (12-byte stride): in GLSL `float positions[]`, not
  // `vec3[]`, whose std430 stride is 16 bytes.
  Buffer positions;  // metres, object frame
  Buffer normals;
  Buffer uvs;        // 2 floats per vertex
  Buffer indices;    // uint32 triangle list (Scene::indices)
  Buffer materials;  // GpuMaterial per Scene::materials entry
  Buffer objects;    // GpuObject per Scene::objects entry
  // The vertex buffers as buffer textures: RGB32F positions and normals, RG32F uvs.
  Texture position_texels, normal_texels, uv_texels;
  // Attribute 0: position (vec3), 1: normal (vec3), 2: uv (vec2); element buffer = indices.
  VertexArray vertex_array;
  // One SRGB8_ALPHA8 texture per Scene::images entry, mipmapped, trilinear, with anisotropic
  // filtering up to `max_anisotropy`; wrap mode comes from the samplers below.
  std::vector<Texture> textures;
  Texture white;  // 1x1 white, bound for materials with no texture
  Sampler repeat_sampler, clamp_sampler;
  std::vector<std::int32_t> material_texture;  // Scene::materials[i].texture, kept for binding
  std::vector<bool> material_repeat;
  // One std140 MaterialShading block per material, then a lit one (bound by upload_scene, so the
  // block is never unbound), each material_shading_stride bytes apart
  // (GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT or more).
  Buffer material_shading;
  std::size_t material_shading_stride = 0;
  float max_anisotropy = 1.0f;  // as applied to both samplers; 1: anisotropic filtering off

  // Binds the indices and the vertex buffer textures at the pulling:: points.
  void bind_for_pulling() const;
  // Binds material `m`'s texture (or `white`) and sampler to texture unit `unit`, and its
  // shading block to material_shading_binding.
  void bind_material_texture(std::uint32_t m, GLuint unit) const;
};

// Requests the driver's choice of anisotropic filtering: 8 on GPUs, off (1) on software
// rasterizers. llvmpipe's anisotropic sampler walks the texel footprint, whose length has no
// useful bound where a facet squashes the scene (a fisheye's rim, looking along the ground):
// the 180° dome at 64×64 took 17.6 s a frame with 8x and 0.25 s without.
inline constexpr float kAutomaticAnisotropy = 0.0f;

// The anisotropy `requested` resolves to on the current context: kAutomaticAnisotropy as above,
// otherwise `requested` clamped to [1, GL_MAX_TEXTURE_MAX_ANISOTROPY] (1 where the context has
// no anisotropic filtering).
float resolve_anisotropy(float requested);

// True when the current context's GL_RENDERER is a CPU rasterizer (llvmpipe, softpipe,
// SwiftShader).
bool is_software_renderer();

// Uploads the scene. Needs a current GL context; the GpuScene must be destroyed while a context
// of the same share group is current.
GpuScene upload_scene(const Scene& scene, float max_anisotropy = kAutomaticAnisotropy);
// Replaces the vertex and index buffers (new buffer objects: bind them anew) and the object
// table of `gpu` with `scene`'s, which must have the materials and images of the scene uploaded
// (a view-dependent mesh rebuilt with other triangles); keeps the textures and material tables.
void replace_geometry(GpuScene& gpu, const Scene& scene);

}  // namespace facet::driver
