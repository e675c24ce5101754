#pragma once
// What the baselines that draw the scene object by object share (cubemap, perspective, vertex):
// the scene and settings that prepare() was given, each object's first triangle ID, the empty
// vertex array of their pulling draws, and the full-screen pass that ends an image baseline's
// frame.
#include <cstdint>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include "facet/driver/gl_objects.hpp"
#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/render_method.hpp"

namespace facet::driver::detail {

// baselines/fullscreen.vert's one triangle over the viewport, shaded by `fragment`.
Program link_fullscreen_program(std::string_view fragment);

class ObjectBaseline : public RenderMethod {
 protected:
  // Throws InputError unless settings.z_near is positive; then keeps the scene, its GPU copy,
  // the settings and each object's triangle base, and makes the empty vertex array once.
  void keep_scene(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& settings);
  // The reversed-Z scene state (begin_reversed_z_scene) with the empty vertex array bound and
  // the scene's buffers bound for pulling.
  void begin_pulling(bool cull_back_faces) const;
  // The figures of a frame that draws the whole scene into images: every triangle goes in and
  // counts as visible; `buffer_bytes` is RenderStats::gpu_buffer_bytes.
  RenderStats whole_scene_stats(std::uint64_t buffer_bytes) const;
  // The image baselines' last pass, timed as "lookup": `lookup` into each target, with
  // `bind_inputs(i)` binding output i's textures; then unbinds the vertex array and ends the
  // frame's timing. Expects the depth test off (end_reversed_z_scene).
  static void draw_lookup_pass(const Program& lookup, std::span<OutputTarget> targets,
                               const std::function<void(std::size_t)>& bind_inputs,
                               GpuTimer* timer);

  const Scene* scene_ = nullptr;
  const GpuScene* gpu_scene_ = nullptr;
  RenderSettings settings_;
  std::vector<std::uint32_t> triangle_base_;  // scene_triangle_base(*scene_)
  VertexArray empty_vao_;  // core profile draws need a vertex array; attributes are pulled
};

}  // namespace facet::driver::detail
