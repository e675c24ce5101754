// The seed's form of the replication pipeline ("facets-gs", Lorenz & Döllner 2009): a geometry
// shader counts each triangle's facets into transform feedback, the counts are scanned and
// expanded into a replicated index of (triangle, replica) entries, and a geometry shader renders
// each replica through its facet. Same triangle list, walk order and arithmetic as "facets", so
// both give the same image.
#include <optional>

#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"
#include "replication_common.hpp"

namespace facet::driver::detail {
namespace {

class FacetGsPipeline final : public FacetMethodBase {
 public:
  std::string_view name() const override { return "facets-gs"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    FacetMethodBase::prepare(scene, gpu_scene, outputs, settings);
    if (!count_) {
      count_ =
          link_replication_program({"replication/triangle_index.vert", "replication/count.geom"});
      replicate_ = build_program({"replication/replicate.comp"});
      args_ = build_program({"replication/draw_args.comp"}, {{"VERTICES_PER_REPLICA", "1"}});
      scan_.prepare();
      feedback_ = TransformFeedback::create();
    }
    if (!draw_ || linked_material_ != settings.material) {
      draw_ = link_replication_program({"replication/triangle_index.vert", "replication/draw.geom"},
                                       {{"WRITE_TRIANGLE_ID", "1"}}, &settings.material);
      linked_material_ = settings.material;
    }
  }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(targets.size() == outputs_.size());
    const bool changed = update_view(T_eye_world);
    RenderStats stats;
    stats.reused_replication = !outputs_.empty();
    for (std::size_t i = 0; i < outputs_.size(); ++i) {
      OutputState& out = outputs_[i];
      targets[i].clear();
      if (!add_output_stats(out, stats)) {
        targets[i].resolve();
        continue;
      }
      if (changed || !out.replication_valid) {
        stats.reused_replication = false;
        // Pass 1 draws (with rasterizer discard), which needs a complete framebuffer bound.
        targets[i].bind();
        replicate(i, timer);
      }
      stats.replicas += out.replicas;
      stats.triangles_visible += out.visible;

      TimedPass scope(timer, "pass3 draw");
      draw_replicas(i, targets[i], draw_, GL_POINTS);
      targets[i].resolve();
    }
    if (timer) timer->end_frame();
    return stats;
  }

 private:
  void replicate(std::size_t i, GpuTimer* timer) {
    OutputState& out = outputs_[i];
    const std::uint32_t n = out.triangles;
    ensure_capacity(out.scan, (std::size_t(n) + 1) * sizeof(std::uint32_t));
    {
      TimedPass scope(timer, "pass1 coverage");
      const std::uint32_t zero = 0;
      out.stats.sub_data(0, sizeof zero, &zero);
      out.scan.sub_data(std::size_t(n) * sizeof zero, sizeof zero, &zero);
      bind_output(i);
      set_list_uniforms(count_, i);
      count_.use();
      feedback_.attach(0, out.scan);
      glBindVertexArray(empty_vao_.id());
      glEnable(GL_RASTERIZER_DISCARD);
      glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, feedback_.id());
      glBeginTransformFeedback(GL_POINTS);
      glDrawArrays(GL_POINTS, 0, GLsizei(n));
      glEndTransformFeedback();
      glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, 0);
      glDisable(GL_RASTERIZER_DISCARD);
      glBindVertexArray(0);
    }
    TimedPass scope(timer, "pass2 replicate");
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    scan_.run(out.scan, n + 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    std::uint32_t total = 0, visible = 0;
    out.scan.get_sub_data(std::size_t(n) * sizeof(std::uint32_t), sizeof total, &total);
    out.stats.get_sub_data(0, sizeof visible, &visible);
    out.replicas = total;
    out.visible = visible;
    ensure_capacity(out.pairs, std::max<std::size_t>(total, 1) * 2 * sizeof(std::uint32_t));
    size_draw_commands(out, total);
    bind_output(i);
    set_list_uniforms(replicate_, i);
    replicate_.use();
    glDispatchCompute((n + 63) / 64, 1, 1);
    write_draw_commands(i, args_);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    out.replication_valid = true;
  }

  Program count_, replicate_, args_, draw_;
  MaterialShader linked_material_;  // draw_'s
  PrefixScan scan_;
  TransformFeedback feedback_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_facet_gs_pipeline() {
  return std::make_unique<FacetGsPipeline>();
}

}  // namespace facet::driver::detail
