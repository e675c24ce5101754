// The single-pass tessellator form of the replication ("tessellated"; Lorenz & Döllner's
// piecewise perspective projection in its tessellation form): one draw per material of one patch
// per list triangle. The control stage counts the facets the triangle covers and sets the
// tessellation levels from them (level 0 culls the patch), the evaluation stage passes (u, v),
// and the geometry stage picks the facet from (u, v) and emits the triangle through it
// (shaders/replication/tess_replicas.*). No pass 1 or 2, no buffers of pairs: the facet walk runs
// once in the control stage and again for each replica in the geometry stage, as in facets-gs.
// Same triangle list, walk order and arithmetic as "facets", so both give the same image.
#include <algorithm>
#include <map>
#include <string>

#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"
#include "replication_common.hpp"

namespace facet::driver::detail {
namespace {

class TessellatedPipeline final : public FacetMethodBase {
 public:
  std::string_view name() const override { return "tessellated"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    FacetMethodBase::prepare(scene, gpu_scene, outputs, settings);
    GLint max_level = 0;
    glGetIntegerv(GL_MAX_TESS_GEN_LEVEL, &max_level);
    // GL 4.5 guarantees 64.
    max_level_ = std::uint32_t(std::max(max_level, 64));
    if (settings.tessellated_max_level < 0) {
      throw InputError("render settings", "tessellated_max_level",
                       "expected 0 (the GL's maximum) or a level >= 1");
    }
    if (settings.tessellated_max_level > 0)
      max_level_ = std::min(max_level_, std::uint32_t(settings.tessellated_max_level));
    // The grid code is specialised per kind of grid, as for `facets`' grid pass.
    for (const OutputState& out : outputs_) {
      const CoverageGrid& grid = out.facets.grid;
      const std::uint32_t kind = grid_kind(grid);
      programs_[kind].prepare(scene, settings.material, [&grid](const MaterialShader& shader) {
        return link_replication_program(
            {"replication/tess_patch.vert", "replication/tess_replicas.tesc",
             "replication/tess_replicas.tese", "replication/tess_replicas.geom"},
            {{"WRITE_TRIANGLE_ID", "1"},
             {"GRID_CHART", std::to_string(std::uint32_t(grid.chart()))},
             {"GRID_PERIODIC", grid.periodic() ? "1" : "0"},
             {"GRID_CELL_BUCKETS", grid.cell_buckets() ? "1" : "0"}},
            &shader);
      });
    }
  }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(targets.size() == outputs_.size());
    update_view(T_eye_world);
    RenderStats stats;
    stats.triangles_scene = scene_->triangle_count();
    for (std::size_t i = 0; i < outputs_.size(); ++i) {
      OutputState& out = outputs_[i];
      targets[i].clear();
      if (!may_draw(i)) {
        add_output_stats(out, stats);
        targets[i].resolve();
        continue;
      }
      TimedPass scope(timer, "draw");
      const std::uint32_t zero[2] = {0, 0};
      out.stats.sub_data(0, sizeof zero, zero);
      draw(i, targets[i]);
      targets[i].resolve();
      scope.end();
      // Visible triangles, replicas, two unused words, list triangles, those with a sole piece.
      std::uint32_t counted[6] = {0, 0, 0, 0, 0, 0};
      out.stats.get_sub_data(0, sizeof counted, counted);
      take_list_counts(i, counted);
      add_output_stats(out, stats);
      stats.triangles_visible += counted[0];
      stats.replicas += counted[1];
    }
    if (timer) timer->end_frame();
    return stats;
  }

 private:
  void draw(std::size_t i, const OutputTarget& target) {
    const OutputState& out = outputs_[i];
    const MaterialPrograms& programs = programs_.at(grid_kind(out.facets.grid));
    bind_output(i);
    target.bind();
    begin_facet_drawing(false);
    for (std::size_t slot = 0; slot < programs.size(); ++slot) {
      const Program& program = programs.program(slot);
      set_list_uniforms(program, i);
      glProgramUniform1ui(program.id(), program.uniform_location("max_level"), max_level_);
    }
    glPatchParameteri(GL_PATCH_VERTICES, 1);
    glBindVertexArray(empty_vao_.id());
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, out.list_args.id());
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT);
    const Program* in_use = nullptr;
    for (std::uint32_t m = 0; m < material_count(); ++m) {
      if (!out.list_on_gpu && out.material_ranges[2 * m] == out.material_ranges[2 * m + 1])
        continue;
      const Program& program = programs.program_of(m);
      if (&program != in_use) {
        program.use();
        in_use = &program;
      }
      set_material(program, m);
      if (!out.list_on_gpu && software_renderer_) {
        // The list is the CPU's, so its material ranges are known here (see
        // kSoftwarePatchesPerDraw).
        const std::uint32_t begin = out.material_ranges[2 * m];
        const std::uint32_t end = out.material_ranges[2 * m + 1];
        for (std::uint32_t first = begin; first < end; first += kSoftwarePatchesPerDraw) {
          glDrawArraysInstanced(GL_PATCHES, GLint(first),
                                GLsizei(std::min(kSoftwarePatchesPerDraw, end - first)),
                                GLsizei(patch_instances(out)));
        }
        continue;
      }
      // list_args holds each material's patches as (count, instances, first, 0).
      const std::uintptr_t command = (kListArgsPatchDraws + 4 * std::uintptr_t(m)) * 4;
      glDrawArraysIndirect(GL_PATCHES, reinterpret_cast<const void*>(command));
    }
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    glBindVertexArray(0);
    end_facet_drawing();
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  }

  // The walk finds a facet at most once per triangle (a quad's two facets each count); one patch
  // makes at most max_level² replicas.
  std::uint32_t patch_instances(const OutputState& out) const override {
    const std::uint64_t most_replicas = out.facets.mesh.facets.size();
    const std::uint64_t per_patch = std::uint64_t(max_level_) * max_level_;
    return std::uint32_t(std::max<std::uint64_t>((most_replicas + per_patch - 1) / per_patch, 1));
  }

  static std::uint32_t grid_kind(const CoverageGrid& grid) {
    return std::uint32_t(grid.chart()) | (grid.periodic() ? 16u : 0u) |
           (grid.cell_buckets() ? 32u : 0u);
  }

  std::uint32_t max_level_ = 64;
  std::map<std::uint32_t, MaterialPrograms> programs_;  // per grid_kind
};

}  // namespace

std::unique_ptr<RenderMethod> make_tessellated_pipeline() {
  return std::make_unique<TessellatedPipeline>();
}

}  // namespace facet::driver::detail
