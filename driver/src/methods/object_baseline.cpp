#include "object_baseline.hpp"

#include "facet/projection/errors.hpp"
#include "material_programs.hpp"

namespace facet::driver::detail {

Program link_fullscreen_program(std::string_view fragment) {
  return ProgramBuilder().shader("baselines/fullscreen.vert").shader(fragment).link();
}

void ObjectBaseline::keep_scene(const Scene& scene, const GpuScene& gpu_scene,
                                const RenderSettings& settings) {
  if (!(settings.z_near > 0)) {
    throw InputError("render settings", "z_near", "expected a positive near distance");
  }
  scene_ = &scene;
  gpu_scene_ = &gpu_scene;
  settings_ = settings;
  triangle_base_ = scene_triangle_base(scene);
  if (!empty_vao_) empty_vao_ = VertexArray::create();
}

void ObjectBaseline::begin_pulling(bool cull_back_faces) const {
  begin_reversed_z_scene(cull_back_faces);
  glBindVertexArray(empty_vao_.id());
  gpu_scene_->bind_for_pulling();
}

RenderStats ObjectBaseline::whole_scene_stats(std::uint64_t buffer_bytes) const {
  RenderStats stats;
  stats.triangles_scene = scene_->triangle_count();
  stats.triangles_in = stats.triangles_scene;
  stats.triangles_visible = stats.triangles_in;
  stats.gpu_buffer_bytes = buffer_bytes;
  return stats;
}

void ObjectBaseline::draw_lookup_pass(const Program& lookup, std::span<OutputTarget> targets,
                                      const std::function<void(std::size_t)>& bind_inputs,
                                      GpuTimer* timer) {
  if (timer) timer->begin("lookup");
  lookup.use();
  for (std::size_t i = 0; i < targets.size(); ++i) {
    targets[i].clear();
    targets[i].bind();
    bind_inputs(i);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    targets[i].resolve();
  }
  glBindVertexArray(0);
  if (timer) {
    timer->end();
    timer->end_frame();
  }
}

}  // namespace facet::driver::detail
