// The image-based cube-map baseline ("cubemap"), as projection-tile screens do it: render the
// scene into the cube faces the outputs need, then give every output pixel the cube map's value
// along its exact eye direction. The directions come from the warp inverse once, in prepare(),
// as an RGBA32F lookup texture per output; colour is sampled bilinearly, triangle IDs from the
// nearest texel. Its error is resampling: about one face texel, in output pixels.
#include <algorithm>
#include <array>
#include <glm/gtc/type_ptr.hpp>

#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/shader_library.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver::detail {
namespace {

// GL's cube-map face selection (GL 4.5 core, table 8.19): for a direction r on face f, the face
// coordinates are sc = a_s·r, tc = a_t·r over the major axis |ma| = a_m·r, and the texel row 0 is
// tc = −1. Faces in GL order +X, −X, +Y, −Y, +Z, −Z.
struct CubeFace {
  glm::dvec3 a_s, a_t, a_m;
};
constexpr std::array<CubeFace, 6> kFaces = {{
    {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}},
    {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}},
    {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},
    {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},
    {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}},
}};

int face_of(const glm::dvec3& v) {
  const glm::dvec3 a = glm::abs(v);
  if (a.x >= a.y && a.x >= a.z) return v.x >= 0 ? 0 : 1;
  if (a.y >= a.z) return v.y >= 0 ? 2 : 3;
  return v.z >= 0 ? 4 : 5;
}

// Clip coordinates of an eye-frame point for face f: (sc, tc, z_near, ma), so that window x, y
// follow the face's texel columns and rows and depth is z_near / ma, reversed-Z.
glm::dmat4 clip_from_eye(const CubeFace& face, double z_near) {
  glm::dmat4 m(0.0);
  for (int c = 0; c < 3; ++c) {
    m[c][0] = face.a_s[c];
    m[c][1] = face.a_t[c];
    m[c][3] = face.a_m[c];
  }
  m[3][2] = z_near;
  return m;
}

class CubemapMethod final : public RenderMethod {
 public:
  std::string_view name() const override { return "cubemap"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    if (settings.cube_face_size < 1 || settings.cube_face_size > 16384) {
      throw InputError("render settings", "cube_face_size",
                       "expected a face edge of 1 to 16384 pixels, got " +
                           std::to_string(settings.cube_face_size));
    }
    if (!(settings.z_near > 0)) {
      throw InputError("render settings", "z_near", "expected a positive near distance");
    }
    scene_ = &scene;
    gpu_scene_ = &gpu_scene;
    settings_ = settings;
    triangle_base_ = scene_triangle_base(scene);
    face_needed_.fill(false);
    lookups_.clear();
    for (const OutputSpec& output : outputs) {
      const WarpInverse inverse(output.warp);
      const glm::ivec2 size = output.warp.output_size;
      const auto st = inverse.st_at_pixel_centres();
      // GL rows start at the bottom.
      std::vector<glm::vec4> lookup(st.size(), glm::vec4(0));
      for (int y = 0; y < size.y; ++y) {
        for (int x = 0; x < size.x; ++x) {
          const glm::dvec2 s = st[std::size_t(y) * size.x + x];
          if (std::isnan(s.x)) continue;
          const glm::dvec3 v_eye = output.warp.v_eye_from_st(s);
          face_needed_[face_of(v_eye)] = true;
          lookup[std::size_t(size.y - 1 - y) * size.x + x] = glm::vec4(glm::vec3(v_eye), 1.0f);
        }
      }
      Texture texture = Texture::create_2d(GL_RGBA32F, size.x, size.y);
      glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glTextureSubImage2D(texture.id(), 0, 0, 0, size.x, size.y, GL_RGBA, GL_FLOAT, lookup.data());
      lookups_.push_back(std::move(texture));
    }

    const int n = settings.cube_face_size;
    colour_cube_ = Texture::create(GL_TEXTURE_CUBE_MAP);
    glTextureStorage2D(colour_cube_.id(), 1, GL_SRGB8_ALPHA8, n, n);
    glTextureParameteri(colour_cube_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(colour_cube_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    id_cube_ = Texture::create(GL_TEXTURE_CUBE_MAP);
    glTextureStorage2D(id_cube_.id(), 1, GL_R32UI, n, n);
    glTextureParameteri(id_cube_.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id_cube_.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    face_depth_ = Texture::create_2d(GL_DEPTH_COMPONENT32F, n, n);
    // Held for every frame: the lookup textures (RGBA32F per output pixel), both cube maps (six
    // n x n faces of SRGB8_ALPHA8 and of R32UI) and the face depth buffer (DEPTH32F).
    buffer_bytes_ = 6ull * std::uint64_t(n) * std::uint64_t(n) * (4 + 4) +
                    std::uint64_t(n) * std::uint64_t(n) * 4;
    for (const OutputSpec& output : outputs) {
      buffer_bytes_ += 16ull * std::uint64_t(output.warp.output_size.x) *
                       std::uint64_t(output.warp.output_size.y);
    }
    face_framebuffer_ = Framebuffer::create();
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(face_framebuffer_.id(), 2, buffers);
    face_framebuffer_.attach(GL_DEPTH_ATTACHMENT, face_depth_);
    if (!empty_vao_) empty_vao_ = VertexArray::create();

    if (!face_program_ || linked_material_ != settings.material) {
      ProgramBuilder face;
      face.define("WRITE_TRIANGLE_ID", "1")
          .shader("baselines/cube_face.vert")
          .shader("baselines/pull_scene.vert");
      add_material_stages(face, settings.material);
      face_program_ = link_with_material(face, settings.material);
      linked_material_ = settings.material;
    }
    if (!lookup_program_) {
      lookup_program_ = ProgramBuilder()
                            .shader("baselines/fullscreen.vert")
                            .shader("baselines/cube_lookup.frag")
                            .link();
    }
    check_gl_error("cubemap prepare");
  }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(scene_ && targets.size() == lookups_.size());
    const Scene& scene = *scene_;
    RenderStats stats;
    stats.triangles_in = scene.triangle_count();
    stats.triangles_visible = stats.triangles_in;
    stats.gpu_buffer_bytes = buffer_bytes_;

    if (timer) timer->begin("faces");
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glEnable(GL_FRAMEBUFFER_SRGB);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    if (settings_.cull_back_faces) {
      glEnable(GL_CULL_FACE);
      glCullFace(GL_BACK);
    } else {
      glDisable(GL_CULL_FACE);
    }
    face_program_.use();
    glBindVertexArray(empty_vao_.id());
    gpu_scene_->bind_for_pulling();
    const int n = settings_.cube_face_size;
    for (int f = 0; f < 6; ++f) {
      if (!face_needed_[f]) continue;
      const CubeFace& face = kFaces[f];
      glNamedFramebufferTextureLayer(face_framebuffer_.id(), GL_COLOR_ATTACHMENT0,
                                     colour_cube_.id(), 0, f);
      glNamedFramebufferTextureLayer(face_framebuffer_.id(), GL_COLOR_ATTACHMENT1, id_cube_.id(), 0,
                                     f);
      face_framebuffer_.check_complete();
      glBindFramebuffer(GL_FRAMEBUFFER, face_framebuffer_.id());
      glViewport(0, 0, n, n);
      const float background[4] = {0, 0, 0, 1};
      const GLuint zero_id[4] = {0, 0, 0, 0};
      const float far_depth = 0;
      glClearNamedFramebufferfv(face_framebuffer_.id(), GL_COLOR, 0, background);
      glClearNamedFramebufferuiv(face_framebuffer_.id(), GL_COLOR, 1, zero_id);
      glClearNamedFramebufferfv(face_framebuffer_.id(), GL_DEPTH, 0, &far_depth);
      // A face whose (a_s, a_t) frame is mirrored against the view direction flips the winding
      // that the rasterizer sees.
      const bool mirrored = glm::dot(glm::cross(face.a_s, face.a_t), face.a_m) > 0;
      glFrontFace(mirrored ? GL_CW : GL_CCW);
      const glm::dmat4 T_clip_eye = clip_from_eye(face, settings_.z_near);
      for (std::size_t o = 0; o < scene.objects.size(); ++o) {
        const Object& object = scene.objects[o];
        if (!in_front_of_face(object.bounds_world, T_eye_world, face)) continue;
        const glm::mat4 T_clip_object(T_clip_eye * T_eye_world * glm::dmat4(object.T_world_object));
        glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(T_clip_object));
        glUniformMatrix4fv(1, 1, GL_FALSE, glm::value_ptr(object.T_world_object));
        const glm::mat4 T_eye_object(T_eye_world * glm::dmat4(object.T_world_object));
        glUniformMatrix4fv(4, 1, GL_FALSE, glm::value_ptr(T_eye_object));
        std::uint32_t id = triangle_base_[o] + 1;
        for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
          const Primitive& primitive = scene.primitives[object.first_primitive + k];
          set_material(primitive.material);
          glUniform1ui(2, primitive.first_index);
          glUniform1ui(3, id);
          glDrawArrays(GL_TRIANGLES, 0, GLsizei(primitive.index_count));
          stats.replicas += primitive.index_count / 3;
          id += primitive.index_count / 3;
        }
      }
    }
    glFrontFace(GL_CCW);
    glDisable(GL_CULL_FACE);
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    if (timer) timer->end();

    if (timer) timer->begin("lookup");
    glDisable(GL_DEPTH_TEST);
    lookup_program_.use();
    colour_cube_.bind_unit(1);
    id_cube_.bind_unit(2);
    for (std::size_t i = 0; i < targets.size(); ++i) {
      targets[i].clear();
      targets[i].bind();
      lookups_[i].bind_unit(0);
      glDrawArrays(GL_TRIANGLES, 0, 3);
      targets[i].resolve();
    }
    glBindVertexArray(0);
    glDepthFunc(GL_LESS);
    if (timer) {
      timer->end();
      timer->end_frame();
    }
    check_gl_error("cubemap render");
    return stats;
  }

 private:
  void set_material(std::uint32_t m) {
    const Material& material = scene_->materials.at(m);
    glUniform4fv(8, 1, glm::value_ptr(material.base_colour));
    glUniform1i(9, material.texture >= 0 ? 1 : 0);
    gpu_scene_->bind_material_texture(m, 0);
  }

  // False when every corner of the world box lies behind the face's near plane: nothing of the
  // object can reach that face.
  bool in_front_of_face(const Aabb& box, const glm::dmat4& T_eye_world,
                        const CubeFace& face) const {
    if (box.empty()) return false;
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 p_world((c & 1) ? box.p_max.x : box.p_min.x,
                               (c & 2) ? box.p_max.y : box.p_min.y,
                               (c & 4) ? box.p_max.z : box.p_min.z);
      const glm::dvec3 p_eye(T_eye_world * glm::dvec4(p_world, 1.0));
      if (glm::dot(face.a_m, p_eye) >= settings_.z_near) return true;
    }
    return false;
  }

  const Scene* scene_ = nullptr;
  const GpuScene* gpu_scene_ = nullptr;
  RenderSettings settings_;
  std::vector<std::uint32_t> triangle_base_;
  std::array<bool, 6> face_needed_{};
  std::vector<Texture> lookups_;
  Texture colour_cube_, id_cube_, face_depth_;
  std::uint64_t buffer_bytes_ = 0;  // RenderStats::gpu_buffer_bytes
  Framebuffer face_framebuffer_;
  VertexArray empty_vao_;
  Program face_program_, lookup_program_;
  MaterialShader linked_material_;  // face_program_'s
};

}  // namespace

std::unique_ptr<RenderMethod> make_cubemap_method() { return std::make_unique<CubemapMethod>(); }

}  // namespace facet::driver::detail
