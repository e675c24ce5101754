// The image-based baseline of view deformation ("perspective"; the seed paper's IB row): render
// the scene once per output into one perspective image that holds every direction the output
// shows (covering_frustum: the narrowest such frustum about the mean covered direction), then
// give every output pixel that image's value along its exact eye direction. The directions come
// from the warp inverse once, in prepare(), as image coordinates per output pixel; colour is
// sampled bilinearly, triangle IDs from the nearest texel. Its error is resampling: about one
// image texel, in output pixels. An output that shows a direction 80° or more from its mean
// (a 180° dome, a 360° cylinder) cannot be held by one image: an InputError.
#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_access.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "../gl/scene_framebuffer.hpp"
#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/perspective_image.hpp"
#include "facet/driver/program.hpp"
#include "facet/projection/content_projection.hpp"
#include "facet/projection/errors.hpp"
#include "material_programs.hpp"
#include "object_baseline.hpp"
#include "pixel_lookup.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver {

glm::ivec2 perspective_image_size(const Frustum& frustum, int larger_side) {
  const double width = frustum.tan_extent[1] - frustum.tan_extent[0];
  const double height = frustum.tan_extent[2] - frustum.tan_extent[3];
  const double longer = std::max(width, height);
  return {std::max(1, int(std::lround(larger_side * width / longer))),
          std::max(1, int(std::lround(larger_side * height / longer)))};
}

glm::dmat4 perspective_image_clip_from_eye(const Frustum& frustum, double z_near) {
  const double l = frustum.tan_extent[0], r = frustum.tan_extent[1];
  const double t = frustum.tan_extent[2], b = frustum.tan_extent[3];
  glm::dmat4 P(0.0);  // columns
  P[0][0] = 2 / (r - l);
  P[2][0] = (r + l) / (r - l);
  P[1][1] = 2 / (t - b);
  P[2][1] = (t + b) / (t - b);
  P[3][2] = z_near;
  P[2][3] = -1;
  return P * glm::dmat4(glm::transpose(frustum.R_eye_frustum));
}

std::optional<glm::dvec2> perspective_image_st(const Frustum& frustum, const glm::dvec3& v_eye) {
  const glm::dvec3 v = glm::transpose(frustum.R_eye_frustum) * v_eye;
  if (!(v.z < 0)) return std::nullopt;
  const double u = v.x / -v.z, w = v.y / -v.z;
  const double l = frustum.tan_extent[0], r = frustum.tan_extent[1];
  const double t = frustum.tan_extent[2], b = frustum.tan_extent[3];
  return glm::dvec2((u - l) / (r - l), (w - b) / (t - b));
}

namespace detail {
namespace {

class PerspectiveMethod final : public ObjectBaseline {
 public:
  std::string_view name() const override { return "perspective"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    refuse_glc_outputs(outputs, name());
    if (settings.cube_face_size < 1 || settings.cube_face_size > 16384) {
      throw InputError("render settings", "cube_face_size",
                       "expected the perspective image's longer side, 1 to 16384 pixels, got " +
                           std::to_string(settings.cube_face_size));
    }
    keep_scene(scene, gpu_scene, settings);
    outputs_.clear();
    buffer_bytes_ = 0;
    for (const OutputSpec& output : outputs) {
      OutputState out;
      out.frustum = covering_frustum(output.warp, output.name);
      out.image_size = perspective_image_size(out.frustum, settings.cube_face_size);
      const glm::ivec2 size = output.warp.output_size;
      out.lookup = pixel_lookup_texture(output.warp, [&](const glm::dvec3& v_eye) {
        const auto image_st = perspective_image_st(out.frustum, v_eye);
        return image_st ? std::optional<glm::vec4>(
                              glm::vec4(float(image_st->x), float(image_st->y), 0.0f, 1.0f))
                        : std::nullopt;
      });
      const glm::ivec2 n = out.image_size;
      out.colour = Texture::create_2d(GL_SRGB8_ALPHA8, n.x, n.y);
      glTextureParameteri(out.colour.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(out.colour.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTextureParameteri(out.colour.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(out.colour.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      out.ids = create_id_texture(n);
      out.depth = Texture::create_2d(GL_DEPTH_COMPONENT32F, n.x, n.y);
      out.framebuffer = scene_framebuffer(out.colour, out.ids, out.depth);
      // Held for every frame: the lookup (RGBA32F per output pixel) and the image's colour
      // (SRGB8_ALPHA8), IDs (R32UI) and depth (DEPTH32F).
      buffer_bytes_ += 16ull * std::uint64_t(size.x) * std::uint64_t(size.y) +
                       12ull * std::uint64_t(n.x) * std::uint64_t(n.y);
      outputs_.push_back(std::move(out));
    }
    scene_programs_.prepare(scene, settings.material, [](const MaterialShader& shader) {
      return link_perspective_scene_program(shader, false);
    });
    if (!lookup_program_) {
      lookup_program_ = link_fullscreen_program("baselines/perspective_lookup.frag");
    }
    check_gl_error("perspective prepare");
  }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(scene_ && targets.size() == outputs_.size());
    RenderStats stats = whole_scene_stats(buffer_bytes_);
    if (timer) timer->begin("image");
    glEnable(GL_FRAMEBUFFER_SRGB);
    begin_pulling(settings_.cull_back_faces);
    const float background[4] = {0, 0, 0, 1};
    const GLuint zero_id[4] = {0, 0, 0, 0};
    const float far_depth = 0;
    for (const OutputState& out : outputs_) {
      glBindFramebuffer(GL_FRAMEBUFFER, out.framebuffer.id());
      glViewport(0, 0, out.image_size.x, out.image_size.y);
      glClearNamedFramebufferfv(out.framebuffer.id(), GL_COLOR, 0, background);
      glClearNamedFramebufferuiv(out.framebuffer.id(), GL_COLOR, 1, zero_id);
      glClearNamedFramebufferfv(out.framebuffer.id(), GL_DEPTH, 0, &far_depth);
      const glm::dmat4 T_clip_eye = perspective_image_clip_from_eye(out.frustum, settings_.z_near);
      stats.replicas += draw_objects(T_eye_world, T_clip_eye);
    }
    end_reversed_z_scene();
    if (timer) timer->end();

    draw_lookup_pass(
        lookup_program_, targets,
        [this](std::size_t i) {
          outputs_[i].lookup.bind_unit(0);
          outputs_[i].colour.bind_unit(1);
          outputs_[i].ids.bind_unit(2);
        },
        timer);
    check_gl_error("perspective render");
    return stats;
  }

 private:
  struct OutputState {
    Frustum frustum;
    glm::ivec2 image_size{0, 0};
    Texture lookup, colour, ids, depth;
    Framebuffer framebuffer;
  };

  // Draws every object whose bounding sphere may meet the image's frustum; returns the triangles
  // drawn.
  std::uint64_t draw_objects(const glm::dmat4& T_eye_world, const glm::dmat4& T_clip_eye) {
    const Scene& scene = *scene_;
    // The frustum's side and near planes in the eye frame: (n, d) with n·p + d >= 0 inside.
    glm::dvec4 planes[5];
    std::ranges::copy(frustum_side_planes(T_clip_eye), planes);
    // w = distance along the axis
    planes[4] = glm::row(T_clip_eye, 3) - glm::dvec4(0, 0, 0, settings_.z_near);
    std::uint64_t drawn = 0;
    const Program* in_use = nullptr;
    const std::vector<BoundingSphere> eye_spheres = object_spheres(scene, T_eye_world);
    for (std::size_t o = 0; o < scene.objects.size(); ++o) {
      const Object& object = scene.objects[o];
      const BoundingSphere& sphere = eye_spheres[o];
      if (sphere.radius < 0) continue;
      if (sphere_outside_a_plane(sphere, planes)) continue;
      const glm::dmat4 T_eye_object = T_eye_world * glm::dmat4(object.T_world_object);
      const glm::mat4 T_clip_object(T_clip_eye * T_eye_object), T_eye_object_f(T_eye_object);
      drawn += draw_object_primitives(
          scene, *gpu_scene_, o, triangle_base_[o] + 1, scene_programs_, in_use, GL_TRIANGLES, [&] {
            glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(T_clip_object));
            glUniformMatrix4fv(1, 1, GL_FALSE, glm::value_ptr(object.T_world_object));
            glUniformMatrix4fv(4, 1, GL_FALSE, glm::value_ptr(T_eye_object_f));
          });
    }
    return drawn;
  }

  std::vector<OutputState> outputs_;
  std::uint64_t buffer_bytes_ = 0;  // RenderStats::gpu_buffer_bytes
  MaterialPrograms scene_programs_;
  Program lookup_program_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_perspective_method() {
  return std::make_unique<PerspectiveMethod>();
}

}  // namespace detail
}  // namespace facet::driver
