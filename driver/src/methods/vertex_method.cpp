// The per-vertex nonlinear projection baseline ("vertex"): every scene vertex goes through the
// display's exact map P (base projection and bilinear offsets, FORMATS.md §2) on the GPU, and
// the rasterizer joins the projected vertices with straight edges. Exact at the vertices, wrong
// between them where P bends a large triangle's edges; with RenderSettings::max_tessellation > 1
// the tessellation stages cut each triangle until the straight pieces are within
// kTessellationTolerancePx of the exact curve (up to that cap).
//
// Shaders: baselines/vertex.vert (pull, eye frame), vertex.tesc/.tese (optional), vertex.geom
// (P per vertex, seam copies, culling), scene/material.frag (shading and triangle IDs), all
// projecting stages linked with baselines/vertex_projection.vert. See driver/README.md.
#include <algorithm>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>
#include <numbers>
#include <string>

#include "../gl/image_rows.hpp"
#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/shader_library.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "material_programs.hpp"
#include "object_baseline.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver::detail {
namespace {

// Largest chord error the tessellation aims for, output pixels (see vertex.tesc).
constexpr float kTessellationTolerancePx = 0.25f;
// GL 4.5 guarantees tessellation levels up to 64.
constexpr int kMaxTessellation = 64;

constexpr std::uint32_t kCounters = 4;  // VertexCounters in vertex.geom

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// Links `names` with the projection library added to every stage that projects.
Program link_vertex_program(std::initializer_list<std::string_view> names, bool tessellated,
                            const MaterialShader& material) {
  ProgramBuilder builder;
  builder.define("WRITE_TRIANGLE_ID", "1").define("TESSELLATED", tessellated ? "1" : "0");
  const std::string_view lib_name = "baselines/vertex_projection.vert";
  const std::string lib_text(embedded_shader(lib_name).text);
  for (std::string_view name : names) {
    builder.shader(name);
    const ShaderStage stage = stage_from_name(name);
    if (stage == ShaderStage::geometry || stage == ShaderStage::tess_control) {
      builder.source(stage, std::string(lib_name), lib_text);
    }
  }
  add_material_stages(builder, material);
  return link_with_material(builder, material);
}

// Everything about one output that the shaders need, made in prepare().
struct OutputState {
  glm::ivec2 size{0, 0};
  glm::mat3 R_base_eye{1.0f};
  int base_kind = 0;
  glm::vec4 base_params{0.0f};
  float s_period = 0;
  float fisheye_rho_limit = 0;
  bool wraps = false;
  Texture node_offsets;             // RGBA32F Gw×Gh: dx, dy, A
  Texture coverage_mask;            // R8, output-sized, GL rows; empty when every pixel is covered
  std::uint64_t texture_bytes = 0;  // node_offsets and coverage_mask, for gpu_buffer_bytes
  // The cone of eye directions through covered pixel centres, widened by one pixel: objects
  // whose bounding sphere misses it are not drawn. half_angle = π when it is every direction.
  glm::dvec3 axis{0, 0, -1};
  double half_angle = std::numbers::pi;
};

OutputState make_output_state(const OutputSpec& output) {
  const Warp& warp = output.warp;
  warp.validate("output '" + output.name + "'");
  OutputState out;
  out.size = warp.output_size;
  out.R_base_eye = glm::mat3(glm::transpose(warp.R_eye_base));
  const BaseProjection& base = warp.base;
  out.base_kind = int(base.kind);
  switch (base.kind) {
    case BaseKind::perspective:
      out.base_params =
          glm::vec4(base.tan_extent[0], base.tan_extent[1], base.tan_extent[2], base.tan_extent[3]);
      break;
    case BaseKind::fisheye:
      out.base_params = glm::vec4(float(radians(base.fov_deg) / 2), 0, 0, 0);
      {
        // Halfway between the output's farthest point (a corner, ρ = √2) and the singular ρ
        // straight behind (360° / fov); see beyond_guard in vertex_projection.vert.
        const double rho_singular = 360.0 / base.fov_deg;
        out.fisheye_rho_limit =
            float(0.5 * (rho_singular + std::min(rho_singular, std::numbers::sqrt2)));
      }
      break;
    case BaseKind::cylindrical:
    case BaseKind::equirectangular: {
      const double a0 = radians(base.azimuth_deg[0]), a1 = radians(base.azimuth_deg[1]);
      const bool cylinder = base.kind == BaseKind::cylindrical;
      out.base_params =
          glm::vec4(a0, a1, cylinder ? base.tan_elevation[0] : radians(base.elevation_deg[0]),
                    cylinder ? base.tan_elevation[1] : radians(base.elevation_deg[1]));
      out.s_period = float(2 * std::numbers::pi / std::abs(a1 - a0));
      out.wraps = base.wraps_horizontally();
      // A 360° span given as, say, 359.9999999° must still be exactly one turn in s.
      if (out.wraps) out.s_period = 1.0f;
      break;
    }
  }

  std::vector<glm::vec4> nodes(warp.offset_px.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    nodes[k] = glm::vec4(warp.offset_px[k], warp.coverage[k], 0.0f);
  }
  out.node_offsets = Texture::create_2d(GL_RGBA32F, warp.grid_size.x, warp.grid_size.y);
  glTextureSubImage2D(out.node_offsets.id(), 0, 0, 0, warp.grid_size.x, warp.grid_size.y, GL_RGBA,
                      GL_FLOAT, nodes.data());
  out.texture_bytes = 16ull * std::uint64_t(warp.grid_size.x) * std::uint64_t(warp.grid_size.y);

  const WarpInverse inverse(warp);
  const auto st = inverse.st_at_pixel_centres();
  const glm::ivec2 size = warp.output_size;
  std::vector<std::uint8_t> mask(st.size(), 0);  // GL rows
  std::vector<glm::dvec3> v_eye(st.size(), glm::dvec3(0));
  glm::dvec3 sum(0);
  std::size_t covered = 0;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const std::size_t k = std::size_t(y) * size.x + x;
      if (std::isnan(st[k].x)) continue;
      v_eye[k] = warp.v_eye_from_st(st[k]);
      sum += v_eye[k];
      mask[flipped_row_start(y, size.y, size.x) + x] = 255;
      ++covered;
    }
  }
  if (covered < st.size()) {
    out.coverage_mask = Texture::create_2d(GL_R8, size.x, size.y);
    out.texture_bytes += std::uint64_t(size.x) * std::uint64_t(size.y);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(out.coverage_mask.id(), 0, 0, 0, size.x, size.y, GL_RED, GL_UNSIGNED_BYTE,
                        mask.data());
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  }
  if (covered == 0) {
    out.half_angle = -1;  // nothing is drawn
    return out;
  }
  // Cone: the widest angle from the mean direction, plus the widest angle between neighbouring
  // pixel centres (geometry between two covered centres may reach beyond both).
  const double sum_length = glm::length(sum);
  if (sum_length < 1e-3 * double(covered)) return out;  // directions all around: no culling
  out.axis = sum / sum_length;
  double widest = 0, step = 0;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const glm::dvec3& v = v_eye[std::size_t(y) * size.x + x];
      if (v == glm::dvec3(0)) continue;
      widest = std::max(widest, std::acos(std::clamp(glm::dot(v, out.axis), -1.0, 1.0)));
      for (const glm::ivec2 d : {glm::ivec2(1, 0), glm::ivec2(0, 1)}) {
        if (x + d.x >= size.x || y + d.y >= size.y) continue;
        const glm::dvec3& w = v_eye[std::size_t(y + d.y) * size.x + x + d.x];
        if (w == glm::dvec3(0)) continue;
        step = std::max(step, std::acos(std::clamp(glm::dot(v, w), -1.0, 1.0)));
      }
    }
  }
  out.half_angle = std::min(widest + step, std::numbers::pi);
  return out;
}

class VertexMethod final : public ObjectBaseline {
 public:
  std::string_view name() const override { return "vertex"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    refuse_glc_outputs(outputs, name());
    if (settings.max_tessellation < 1 || settings.max_tessellation > kMaxTessellation) {
      throw InputError("render settings", "max_tessellation",
                       "expected a tessellation level cap of 1 to " +
                           std::to_string(kMaxTessellation) + ", got " +
                           std::to_string(settings.max_tessellation));
    }
    keep_scene(scene, gpu_scene, settings);
    outputs_.clear();
    for (const OutputSpec& output : outputs) outputs_.push_back(make_output_state(output));

    if (!counters_) counters_ = Buffer::create(kCounters * sizeof(std::uint32_t));
    const bool tessellated = settings.max_tessellation > 1;
    vertices_per_draw_ = tessellated && is_software_renderer() ? 3 * kSoftwarePatchesPerDraw : 0;
    MaterialPrograms& draw = tessellated ? tess_programs_ : plain_programs_;
    draw.prepare(scene, settings.material, [tessellated](const MaterialShader& shader) {
      return tessellated
                 ? link_vertex_program(
                       {"baselines/vertex.vert", "baselines/pull_scene.vert",
                        "baselines/vertex.tesc", "baselines/vertex.tese", "baselines/vertex.geom"},
                       true, shader)
                 : link_vertex_program({"baselines/vertex.vert", "baselines/pull_scene.vert",
                                        "baselines/vertex.geom"},
                                       false, shader);
    });
    if (!mask_program_) mask_program_ = link_fullscreen_program("baselines/vertex_mask.frag");
    check_gl_error("vertex prepare");
  }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(scene_ && targets.size() == outputs_.size());
    const Scene& scene = *scene_;
    RenderStats stats;
    stats.triangles_scene = scene.triangle_count();
    // Per output its warp's node texture and coverage mask, and the shared counters.
    stats.gpu_buffer_bytes = counters_.size();
    for (const OutputState& out : outputs_) stats.gpu_buffer_bytes += out.texture_bytes;
    const bool tessellated = settings_.max_tessellation > 1;
    const MaterialPrograms& draw = tessellated ? tess_programs_ : plain_programs_;

    const std::vector<BoundingSphere> eye_spheres = object_spheres(scene, T_eye_world);

    if (timer) timer->begin("draw");
    glClearNamedBufferData(counters_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, counters_.id());
    // Back faces are culled in 3D by the shaders: a large triangle's projected winding is not
    // reliable.
    begin_pulling(false);
    if (tessellated) glPatchParameteri(GL_PATCH_VERTICES, 3);

    for (std::size_t i = 0; i < outputs_.size(); ++i) {
      const OutputState& out = outputs_[i];
      OutputTarget& target = targets[i];
      FACET_ASSERT(target.size() == out.size);
      target.clear();
      target.bind();
      if (out.coverage_mask) draw_mask(out, 1.0f);
      glDepthFunc(GL_GREATER);

      for (std::size_t slot = 0; slot < draw.size(); ++slot) {
        const GLuint program = draw.program(slot).id();
        glProgramUniformMatrix3fv(program, 20, 1, GL_FALSE, glm::value_ptr(out.R_base_eye));
        glProgramUniform1i(program, 21, out.base_kind);
        glProgramUniform4fv(program, 22, 1, glm::value_ptr(out.base_params));
        glProgramUniform2f(program, 23, float(out.size.x), float(out.size.y));
        glProgramUniform1f(program, 24, out.s_period);
        glProgramUniform1i(program, 25, out.wraps ? 1 : 0);
        glProgramUniform1i(program, 26, settings_.cull_back_faces ? 1 : 0);
        if (tessellated) {
          glProgramUniform1f(program, 27, kTessellationTolerancePx);
          glProgramUniform1f(program, 28, float(settings_.max_tessellation));
        }
        glProgramUniform1f(program, 29, float(settings_.z_near));
        glProgramUniform1f(program, 30, out.fisheye_rho_limit);
      }
      out.node_offsets.bind_unit(1);

      const Program* in_use = nullptr;
      for (std::size_t o = 0; o < scene.objects.size(); ++o) {
        if (!may_be_seen(out, eye_spheres[o].centre, eye_spheres[o].radius * 1.0001)) continue;
        const Object& object = scene.objects[o];
        const glm::mat4 T_eye_object(T_eye_world * glm::dmat4(object.T_world_object));
        draw_object_primitives(
            scene, *gpu_scene_, o, triangle_base_[o] + 1, draw, in_use,
            tessellated ? GL_PATCHES : GL_TRIANGLES,
            [&] {
              glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(T_eye_object));
              glUniformMatrix4fv(1, 1, GL_FALSE, glm::value_ptr(object.T_world_object));
            },
            vertices_per_draw_);
        stats.triangles_in += triangle_base_[o + 1] - triangle_base_[o];
      }
      if (out.coverage_mask) draw_mask(out, 0.0f);
      target.resolve();
    }
    glBindVertexArray(0);
    end_reversed_z_scene();
    if (timer) {
      timer->end();
      timer->end_frame();
    }
    // One small read-back per frame, as the facet pipelines do for their counts.
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::uint32_t counts[kCounters] = {};
    counters_.get_sub_data(0, sizeof counts, counts);
    stats.triangles_visible = counts[0];
    stats.replicas = counts[1];
    stats.dropped_triangles = counts[2];
    stats.seam_copies = counts[3];
    check_gl_error("vertex render");
    return stats;
  }

 private:
  // Conservative: false only when the sphere lies wholly outside the output's cone.
  static bool may_be_seen(const OutputState& out, const glm::dvec3& centre, double radius) {
    if (radius < 0 || out.half_angle < 0) return false;
    if (out.half_angle >= std::numbers::pi) return true;
    const double distance = glm::length(centre);
    if (distance <= radius) return true;
    const double off_axis = std::acos(std::clamp(glm::dot(centre, out.axis) / distance, -1.0, 1.0));
    return off_axis - std::asin(radius / distance) <= out.half_angle;
  }

  // Sets the depth of the uncovered pixels to `depth` (vertex_mask.frag), colour untouched.
  void draw_mask(const OutputState& out, float depth) {
    glDepthFunc(GL_ALWAYS);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    mask_program_.use();
    glUniform1f(0, depth);
    out.coverage_mask.bind_unit(0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  }

  std::vector<OutputState> outputs_;
  Buffer counters_;
  MaterialPrograms plain_programs_, tess_programs_;
  // draw_object_primitives' split of the patches (0: whole primitives).
  std::uint32_t vertices_per_draw_ = 0;
  Program mask_program_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_vertex_method() { return std::make_unique<VertexMethod>(); }

}  // namespace facet::driver::detail
