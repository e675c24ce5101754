#include "facet/driver/gpu_scene.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <glm/gtc/type_ptr.hpp>
#include <string_view>

#include "facet/projection/errors.hpp"

namespace facet::driver {

void GpuScene::bind_for_pulling() const {
  indices.bind_base(GL_SHADER_STORAGE_BUFFER, pulling::indices_binding);
  position_texels.bind_unit(pulling::position_unit);
  normal_texels.bind_unit(pulling::normal_unit);
  uv_texels.bind_unit(pulling::uv_unit);
}

void GpuScene::bind_material_texture(std::uint32_t m, GLuint unit) const {
  FACET_ASSERT(m < material_texture.size());
  const std::int32_t t = material_texture[m];
  if (t >= 0)
    textures[static_cast<std::size_t>(t)].bind_unit(unit);
  else
    white.bind_unit(unit);
  (material_repeat[m] ? repeat_sampler : clamp_sampler).bind_unit(unit);
  glBindBufferRange(GL_UNIFORM_BUFFER, material_shading_binding, material_shading.id(),
                    static_cast<GLintptr>(m * material_shading_stride), sizeof(std::uint32_t) * 4);
}

bool is_software_renderer() {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (renderer == nullptr) return false;
  const std::string_view name(renderer);
  return name.starts_with("llvmpipe") || name.starts_with("softpipe") ||
         name.find("SwiftShader") != std::string_view::npos;
}

float resolve_anisotropy(float requested) {
  // Core since GL 4.6; on 4.5 drivers it is the ARB/EXT extension with the same enum value.
  const bool anisotropic = epoxy_gl_version() >= 46 ||
                           epoxy_has_gl_extension("GL_ARB_texture_filter_anisotropic") ||
                           epoxy_has_gl_extension("GL_EXT_texture_filter_anisotropic");
  if (!anisotropic) return 1.0f;
  float max_anisotropy = 1.0f;
  glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &max_anisotropy);
  if (requested == kAutomaticAnisotropy) requested = is_software_renderer() ? 1.0f : 8.0f;
  return std::clamp(requested, 1.0f, std::max(1.0f, max_anisotropy));
}

namespace {

// The vertex and index buffers, their buffer textures and vertex array, and the object table.
void upload_geometry(GpuScene& gpu, const Scene& scene) {
  FACET_ASSERT(scene.normals.size() == scene.positions.size());
  FACET_ASSERT(scene.uvs.size() == scene.positions.size());
  gpu.positions = Buffer::create_from(scene.positions);
  gpu.normals = Buffer::create_from(scene.normals);
  gpu.uvs = Buffer::create_from(scene.uvs);
  gpu.position_texels = Texture::create_buffer_view(gpu.positions, GL_RGB32F, 3 * sizeof(float));
  gpu.normal_texels = Texture::create_buffer_view(gpu.normals, GL_RGB32F, 3 * sizeof(float));
  gpu.uv_texels = Texture::create_buffer_view(gpu.uvs, GL_RG32F, 2 * sizeof(float));
  gpu.indices = Buffer::create_from(scene.indices);
  std::vector<GpuObject> objects;
  for (const auto& o : scene.objects) {
    GpuObject g{};
    std::memcpy(g.T_world_object, glm::value_ptr(o.T_world_object), sizeof g.T_world_object);
    std::memcpy(g.bounds_min, glm::value_ptr(o.bounds_world.p_min), 3 * sizeof(float));
    std::memcpy(g.bounds_max, glm::value_ptr(o.bounds_world.p_max), 3 * sizeof(float));
    g.first_primitive = o.first_primitive;
    g.primitive_count = o.primitive_count;
    objects.push_back(g);
  }
  gpu.objects = Buffer::create_from(objects);

  gpu.vertex_array = VertexArray::create();
  const GLuint vao = gpu.vertex_array.id();
  glVertexArrayVertexBuffer(vao, 0, gpu.positions.id(), 0, 3 * sizeof(float));
  glVertexArrayVertexBuffer(vao, 1, gpu.normals.id(), 0, 3 * sizeof(float));
  glVertexArrayVertexBuffer(vao, 2, gpu.uvs.id(), 0, 2 * sizeof(float));
  const GLint sizes[3] = {3, 3, 2};
  for (GLuint a = 0; a < 3; ++a) {
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, sizes[a], GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, a, a);
  }
  glVertexArrayElementBuffer(vao, gpu.indices.id());
}

}  // namespace

void replace_geometry(GpuScene& gpu, const Scene& scene) {
  FACET_ASSERT(scene.materials.size() == gpu.material_texture.size());
  FACET_ASSERT(scene.images.size() == gpu.textures.size());
  upload_geometry(gpu, scene);
}

GpuScene upload_scene(const Scene& scene, float max_anisotropy) {
  GpuScene gpu;
  upload_geometry(gpu, scene);

  std::vector<GpuMaterial> materials;
  for (const auto& m : scene.materials) {
    GpuMaterial g{};
    std::memcpy(g.base_colour, glm::value_ptr(m.base_colour), sizeof g.base_colour);
    g.texture = m.texture;
    g.repeat = m.repeat ? 1u : 0u;
    g.unlit = m.unlit ? 1u : 0u;
    materials.push_back(g);
    gpu.material_texture.push_back(m.texture);
    gpu.material_repeat.push_back(m.repeat);
  }
  gpu.materials = Buffer::create_from(materials);

  GLint alignment = 16;
  glGetIntegerv(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, &alignment);
  constexpr std::size_t kBlockBytes = 4 * sizeof(std::uint32_t);  // std140: a uint padded to 16
  gpu.material_shading_stride = std::max(kBlockBytes, static_cast<std::size_t>(alignment));
  std::vector<std::uint8_t> shading((scene.materials.size() + 1) * gpu.material_shading_stride, 0);
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const std::uint32_t unlit = scene.materials[i].unlit ? 1u : 0u;
    std::memcpy(&shading[i * gpu.material_shading_stride], &unlit, sizeof unlit);
  }
  gpu.material_shading = Buffer::create_from(shading);
  glBindBufferRange(GL_UNIFORM_BUFFER, material_shading_binding, gpu.material_shading.id(),
                    static_cast<GLintptr>(scene.materials.size() * gpu.material_shading_stride),
                    kBlockBytes);

  gpu.max_anisotropy = resolve_anisotropy(max_anisotropy);
  for (const auto& image : scene.images) {
    FACET_ASSERT(image.rgba.size() == static_cast<std::size_t>(image.width) *
                                          static_cast<std::size_t>(image.height) * 4u);
    const auto largest = static_cast<unsigned>(std::max(image.width, image.height));
    const int levels = std::bit_width(largest);  // down to 1x1
    Texture texture = Texture::create_2d(GL_SRGB8_ALPHA8, image.width, image.height, levels);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(texture.id(), 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE,
                        image.rgba.data());
    glGenerateTextureMipmap(texture.id());
    gpu.textures.push_back(std::move(texture));
  }
  gpu.white = Texture::create_2d(GL_SRGB8_ALPHA8, 1, 1, 1);
  const std::uint8_t white[4] = {255, 255, 255, 255};
  glTextureSubImage2D(gpu.white.id(), 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);

  gpu.repeat_sampler = Sampler::create();
  gpu.clamp_sampler = Sampler::create();
  for (const Sampler* sampler : {&gpu.repeat_sampler, &gpu.clamp_sampler}) {
    const GLenum wrap = sampler == &gpu.repeat_sampler ? GL_REPEAT : GL_CLAMP_TO_EDGE;
    glSamplerParameteri(sampler->id(), GL_TEXTURE_WRAP_S, static_cast<GLint>(wrap));
    glSamplerParameteri(sampler->id(), GL_TEXTURE_WRAP_T, static_cast<GLint>(wrap));
    glSamplerParameteri(sampler->id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glSamplerParameteri(sampler->id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    if (gpu.max_anisotropy > 1.0f)
      glSamplerParameterf(sampler->id(), GL_TEXTURE_MAX_ANISOTROPY, gpu.max_anisotropy);
  }
  return gpu;
}

}  // namespace facet::driver
