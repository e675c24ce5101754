// The image-based cube-map baseline ("cubemap"), as projection-tile screens do it: render the
// scene into the cube faces the outputs need, then give every output pixel the cube map's value
// along its exact eye direction. The directions come from the warp inverse once, in prepare(),
// as an RGBA32F lookup texture per output; colour is sampled bilinearly, triangle IDs from the
// nearest texel. Its error is resampling: about one face texel, in output pixels.
//
// As in Trapp & Döllner's projection tile screens, the faces are made with per-face frustum
// culling: objects on the CPU (bounding sphere against each face's frustum) and triangles in a
// geometry stage (cube_face.geom); in six passes, one per face needed, or in one layered pass
// (RenderSettings::cube_creation); and mipmaps of the colour faces, sampled trilinearly
// (RenderSettings::cube_mipmaps).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>

#include "../gl/scene_framebuffer.hpp"
#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/shader_library.hpp"
#include "facet/projection/content_projection.hpp"
#include "facet/projection/errors.hpp"
#include "material_programs.hpp"
#include "object_baseline.hpp"
#include "pixel_lookup.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver::detail {
namespace {

// The faces, their axes and GL's face selection are projection's (kCubeFaces, cube_face_of; GL 4.5
// table 8.19): the faces drawn here are those GL's cube lookup samples and a cubemap content
// image holds.

// Clip coordinates of an eye-frame point for face f: (sc, tc, z_near, ma), so that window x, y
// follow the face's texel columns and rows and depth is z_near / ma, reversed-Z.
glm::dmat4 clip_from_eye(const CubeFaceAxes& face, double z_near) {
  glm::dmat4 m(0.0);
  for (int c = 0; c < 3; ++c) {
    m[c][0] = face.a_s[c];
    m[c][1] = face.a_t[c];
    m[c][3] = face.a_m[c];
  }
  m[3][2] = z_near;
  return m;
}

// Bit f set when the sphere (eye frame) may meet face f's frustum: a_m·p >= |a_s·p|,
// a_m·p >= |a_t·p| and a_m·p >= z_near. Conservative: a bit is clear only when the sphere lies
// wholly beyond one of those planes.
unsigned faces_of_sphere(const glm::dvec3& centre, double radius, double z_near) {
  unsigned mask = 0;
  for (int f = 0; f < 6; ++f) {
    const CubeFaceAxes& face = kCubeFaces[std::size_t(f)];
    const double m = glm::dot(face.a_m, centre);
    const double s = glm::dot(face.a_s, centre);
    const double t = glm::dot(face.a_t, centre);
    // The side planes (a_m ∓ a_s)·p >= 0 have normals of length √2.
    const double side = radius * std::sqrt(2.0);
    if (m - s < -side || m + s < -side || m - t < -side || m + t < -side) continue;
    if (m < z_near - radius) continue;
    mask |= 1u << f;
  }
  return mask;
}

class CubemapMethod final : public ObjectBaseline {
 public:
  std::string_view name() const override { return "cubemap"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    refuse_glc_outputs(outputs, name());
    if (settings.cube_face_size < 1 || settings.cube_face_size > 16384) {
      throw InputError("render settings", "cube_face_size",
                       "expected a face edge of 1 to 16384 pixels, got " +
                           std::to_string(settings.cube_face_size));
    }
    keep_scene(scene, gpu_scene, settings);
    face_needed_.fill(false);
    lookups_.clear();
    for (const OutputSpec& output : outputs) {
      lookups_.push_back(pixel_lookup_texture(output.warp, [&](const glm::dvec3& v_eye) {
        face_needed_[cube_face_of(v_eye)] = true;
        return std::optional<glm::vec4>(glm::vec4(glm::vec3(v_eye), 1.0f));
      }));
    }

    const int n = settings.cube_face_size;
    layered_ = settings_.cube_creation == RenderSettings::CubeCreation::layered;
    use_gs_ = layered_ || settings_.cube_culling == RenderSettings::CubeCulling::triangles;
    const int levels = settings_.cube_mipmaps ? int(std::floor(std::log2(double(n)))) + 1 : 1;
    colour_cube_ = Texture::create(GL_TEXTURE_CUBE_MAP);
    glTextureStorage2D(colour_cube_.id(), levels, GL_SRGB8_ALPHA8, n, n);
    glTextureParameteri(colour_cube_.id(), GL_TEXTURE_MIN_FILTER,
                        levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    glTextureParameteri(colour_cube_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    id_cube_ = Texture::create(GL_TEXTURE_CUBE_MAP);
    glTextureStorage2D(id_cube_.id(), 1, GL_R32UI, n, n);
    glTextureParameteri(id_cube_.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id_cube_.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    // Layered: one depth image per face (a cube map), as every attachment of a layered
    // framebuffer must be layered. Six passes share one.
    if (layered_) {
      face_depth_ = Texture::create(GL_TEXTURE_CUBE_MAP);
      glTextureStorage2D(face_depth_.id(), 1, GL_DEPTH_COMPONENT32F, n, n);
    } else {
      face_depth_ = Texture::create_2d(GL_DEPTH_COMPONENT32F, n, n);
    }
    // Held for every frame: the lookup textures (RGBA32F per output pixel), both cube maps (six
    // n x n faces of SRGB8_ALPHA8, with its mipmaps, and of R32UI) and the face depth buffer
    // (DEPTH32F, six faces when layered).
    std::uint64_t colour_texels = 0;
    for (int level = 0; level < levels; ++level) {
      const std::uint64_t edge = std::uint64_t(std::max(1, n >> level));
      colour_texels += edge * edge;
    }
    const std::uint64_t texels = std::uint64_t(n) * std::uint64_t(n);
    buffer_bytes_ = 6ull * (colour_texels * 4 + texels * 4) + (layered_ ? 6ull : 1ull) * texels * 4;
    for (const OutputSpec& output : outputs) {
      buffer_bytes_ += 16ull * std::uint64_t(output.warp.output_size.x) *
                       std::uint64_t(output.warp.output_size.y);
    }
    face_framebuffer_ = Framebuffer::create();
    draw_to_colour_and_ids(face_framebuffer_);
    if (layered_) {
      glNamedFramebufferTexture(face_framebuffer_.id(), GL_COLOR_ATTACHMENT0, colour_cube_.id(), 0);
      glNamedFramebufferTexture(face_framebuffer_.id(), GL_COLOR_ATTACHMENT1, id_cube_.id(), 0);
      glNamedFramebufferTexture(face_framebuffer_.id(), GL_DEPTH_ATTACHMENT, face_depth_.id(), 0);
      face_framebuffer_.check_complete();
    } else {
      face_framebuffer_.attach(GL_DEPTH_ATTACHMENT, face_depth_);
    }
    if (!primitives_query_) primitives_query_ = Query::create(GL_PRIMITIVES_GENERATED);

    if (linked_gs_ != use_gs_) face_programs_.clear();
    linked_gs_ = use_gs_;
    face_programs_.prepare(scene, settings.material, [this](const MaterialShader& shader) {
      return link_perspective_scene_program(shader, use_gs_);
    });
    if (!lookup_program_) lookup_program_ = link_fullscreen_program("baselines/cube_lookup.frag");
    check_gl_error("cubemap prepare");
  }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(scene_ && targets.size() == lookups_.size());
    const Scene& scene = *scene_;
    RenderStats stats = whole_scene_stats(buffer_bytes_);

    if (timer) timer->begin("faces");
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glEnable(GL_FRAMEBUFFER_SRGB);
    begin_pulling(settings_.cull_back_faces);
    // Every face of GL's cube keeps the same handedness, so one winding serves all (layered).
    const CubeFaceAxes& first = kCubeFaces[0];
    const bool mirrored = glm::dot(glm::cross(first.a_s, first.a_t), first.a_m) > 0;
    glFrontFace(mirrored ? GL_CW : GL_CCW);
    const int n = settings_.cube_face_size;
    glViewport(0, 0, n, n);
    unsigned needed_mask = 0;
    for (int f = 0; f < 6; ++f) needed_mask |= face_needed_[f] ? 1u << f : 0u;

    // Per object: the faces its bounding sphere meets (of those the outputs need), and its
    // projection onto each.
    object_faces_.assign(scene.objects.size(), 0u);
    object_clip_.resize(scene.objects.size());
    const std::vector<BoundingSphere> eye_spheres = object_spheres(scene, T_eye_world);
    for (std::size_t o = 0; o < scene.objects.size(); ++o) {
      const Object& object = scene.objects[o];
      const BoundingSphere& sphere = eye_spheres[o];
      if (sphere.radius < 0) continue;
      object_faces_[o] =
          settings_.cube_culling == RenderSettings::CubeCulling::none
              ? needed_mask
              : faces_of_sphere(sphere.centre, sphere.radius, settings_.z_near) & needed_mask;
      for (int f = 0; f < 6; ++f) {
        if (object_faces_[o] & (1u << f)) {
          const glm::dmat4 T_clip_eye = clip_from_eye(kCubeFaces[std::size_t(f)], settings_.z_near);
          object_clip_[o][f] =
              glm::mat4(T_clip_eye * T_eye_world * glm::dmat4(object.T_world_object));
        }
      }
    }

    const float background[4] = {0, 0, 0, 1};
    const GLuint zero_id[4] = {0, 0, 0, 0};
    const float far_depth = 0;
    if (use_gs_) {
      for (std::size_t slot = 0; slot < face_programs_.size(); ++slot) {
        const GLuint program = face_programs_.program(slot).id();
        glProgramUniform1i(program, 6, layered_ ? 1 : 0);
        glProgramUniform1i(
            program, 7, settings_.cube_culling == RenderSettings::CubeCulling::triangles ? 1 : 0);
      }
      glBeginQuery(GL_PRIMITIVES_GENERATED, primitives_query_.id());
    }
    if (layered_) {
      glBindFramebuffer(GL_FRAMEBUFFER, face_framebuffer_.id());
      glClearNamedFramebufferfv(face_framebuffer_.id(), GL_COLOR, 0, background);
      glClearNamedFramebufferuiv(face_framebuffer_.id(), GL_COLOR, 1, zero_id);
      glClearNamedFramebufferfv(face_framebuffer_.id(), GL_DEPTH, 0, &far_depth);
      draw_objects(T_eye_world, ~0u, stats);
    } else {
      for (int f = 0; f < 6; ++f) {
        // Faces no output needs are cleared too: filtering across a face's edge (seamless cube
        // sampling, coarse mip levels) may reach them.
        glNamedFramebufferTextureLayer(face_framebuffer_.id(), GL_COLOR_ATTACHMENT0,
                                       colour_cube_.id(), 0, f);
        glNamedFramebufferTextureLayer(face_framebuffer_.id(), GL_COLOR_ATTACHMENT1, id_cube_.id(),
                                       0, f);
        face_framebuffer_.check_complete();
        glBindFramebuffer(GL_FRAMEBUFFER, face_framebuffer_.id());
        glClearNamedFramebufferfv(face_framebuffer_.id(), GL_COLOR, 0, background);
        glClearNamedFramebufferuiv(face_framebuffer_.id(), GL_COLOR, 1, zero_id);
        if (!face_needed_[f]) continue;
        glClearNamedFramebufferfv(face_framebuffer_.id(), GL_DEPTH, 0, &far_depth);
        draw_objects(T_eye_world, 1u << f, stats);
      }
    }
    if (use_gs_) {
      glEndQuery(GL_PRIMITIVES_GENERATED);
      // Triangles the geometry stage sent to a face: the replicas.
      stats.replicas = primitives_query_.result();
    }
    if (settings_.cube_mipmaps) glGenerateTextureMipmap(colour_cube_.id());
    glFrontFace(GL_CCW);
    end_reversed_z_scene();
    if (timer) timer->end();

    colour_cube_.bind_unit(1);
    id_cube_.bind_unit(2);
    draw_lookup_pass(
        lookup_program_, targets, [this](std::size_t i) { lookups_[i].bind_unit(0); }, timer);
    check_gl_error("cubemap render");
    return stats;
  }

 private:
  // Draws every object that meets a face of `faces` into those faces: six passes give one face
  // (through the geometry stage when it culls triangles, or projected in the vertex stage),
  // layered creation all of them at once.
  void draw_objects(const glm::dmat4& T_eye_world, unsigned faces, RenderStats& stats) {
    const Scene& scene = *scene_;
    const Program* in_use = nullptr;
    for (std::size_t o = 0; o < scene.objects.size(); ++o) {
      const Object& object = scene.objects[o];
      const unsigned mask = object_faces_[o] & faces;
      if (mask == 0) continue;
      const glm::mat4 T_eye_object(T_eye_world * glm::dmat4(object.T_world_object));
      // The object's uniforms, sent to each program that draws one of its primitives.
      const auto send_object = [&] {
        if (use_gs_) {
          glUniform1ui(5, mask);
          glUniformMatrix4fv(10, 6, GL_FALSE, glm::value_ptr(object_clip_[o][0]));
        } else {
          const int f = std::countr_zero(mask);
          glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(object_clip_[o][f]));
        }
        glUniformMatrix4fv(1, 1, GL_FALSE, glm::value_ptr(object.T_world_object));
        glUniformMatrix4fv(4, 1, GL_FALSE, glm::value_ptr(T_eye_object));
      };
      const std::uint64_t drawn =
          draw_object_primitives(scene, *gpu_scene_, o, triangle_base_[o] + 1, face_programs_,
                                 in_use, GL_TRIANGLES, send_object);
      // Without the geometry stage, every triangle of the object is drawn into the face.
      if (!use_gs_) stats.replicas += drawn;
    }
  }

  std::array<bool, 6> face_needed_{};
  std::vector<Texture> lookups_;
  Texture colour_cube_, id_cube_, face_depth_;
  std::uint64_t buffer_bytes_ = 0;  // RenderStats::gpu_buffer_bytes
  Framebuffer face_framebuffer_;
  MaterialPrograms face_programs_;
  Program lookup_program_;
  bool linked_gs_ = false;              // face_programs_ have the geometry stage
  bool layered_ = false;                // settings_.cube_creation == layered
  bool use_gs_ = false;                 // layered, or six passes culling triangles
  Query primitives_query_;              // GL_PRIMITIVES_GENERATED: triangles sent to faces
  std::vector<unsigned> object_faces_;  // per object: faces it meets
  std::vector<std::array<glm::mat4, 6>> object_clip_;  // per object and face: T_clip_object
};

}  // namespace

std::unique_ptr<RenderMethod> make_cubemap_method() { return std::make_unique<CubemapMethod>(); }

}  // namespace facet::driver::detail
