// The seed's form of the replication pipeline ("facets-gs", Lorenz & Döllner 2009): a geometry
// shader counts each triangle's facets into transform feedback, the counts are scanned and
// expanded into a replicated index of (triangle, replica) entries, and a geometry shader renders
// each replica through its facet. Same triangle list, walk order and arithmetic as "facets", so
// both give the same image; the pair buffer, its overflow rerun and the indirect draws without a
// read-back are PairPipelineBase's, as for "facets".
#include <algorithm>
#include <cstdint>

#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"
#include "replication_common.hpp"

namespace facet::driver::detail {
namespace {

class FacetGsPipeline final : public PairPipelineBase {
 public:
  std::string_view name() const override { return "facets-gs"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    FacetMethodBase::prepare(scene, gpu_scene, outputs, settings);
    if (!count_) {
      count_ =
          link_replication_program({"replication/triangle_index.vert", "replication/count.geom"});
      replicate_ = link_replication_program({"replication/replicate.comp"});
      args_ = build_program({"replication/draw_args.comp"}, {{"VERTICES_PER_REPLICA", "1"}});
      scan_.prepare();
      feedback_ = TransformFeedback::create();
    }
    draw_.prepare(scene, settings.material, [](const MaterialShader& shader) {
      return link_replication_program({"replication/triangle_index.vert", "replication/draw.geom"},
                                      {{"WRITE_TRIANGLE_ID", "1"}}, &shader);
    });
  }

  void draw(std::size_t i, OutputTarget& target, GpuTimer* timer) override {
    TimedPass scope(timer, "pass3 draw");
    draw_replicas(i, target, draw_, GL_POINTS);
  }

  // Passes 1 and 2 of output i without reading anything back: replicate.comp writes the pair
  // count and, beyond the pair capacity, the overflow flag that makes draw_args.comp draw nothing.
  void replicate(std::size_t i, OutputTarget& target, GpuTimer* timer) override {
    OutputState& out = outputs_[i];
    const std::uint32_t n = list_capacity(i);  // the list's triangles, or at most
    ensure_capacity(out.scan, (std::size_t(n) + 1) * sizeof(std::uint32_t));
    const std::uint32_t capacity = pair_capacity(i);
    ensure_capacity(out.pairs, std::size_t(capacity) * 2 * sizeof(std::uint32_t));
    size_draw_commands(out, capacity);
    {
      TimedPass scope(timer, "pass1 coverage");
      const std::uint32_t zero[4] = {0, 0, 0, 0};
      out.stats.sub_data(0, sizeof zero, zero);
      // Transform feedback writes the list's counts; the scan's end marker, past them, is 0. A
      // list built on the GPU may end anywhere up to n, so every word is cleared; a CPU list's
      // has n triangles, so only the marker is.
      const std::uint32_t no_count = 0;
      const std::size_t cleared_from = out.list_on_gpu ? 0 : n;
      glClearNamedBufferSubData(out.scan.id(), GL_R32UI, cleared_from * sizeof(std::uint32_t),
                                (std::size_t(n) + 1 - cleared_from) * sizeof(std::uint32_t),
                                GL_RED_INTEGER, GL_UNSIGNED_INT, &no_count);
      // Pass 1 draws (with rasterizer discard), which needs a complete framebuffer bound.
      target.bind();
      bind_output(i);
      set_list_uniforms(count_, i);
      count_.use();
      feedback_.attach(0, out.scan);
      glBindVertexArray(empty_vao_.id());
      glEnable(GL_RASTERIZER_DISCARD);
      glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, feedback_.id());
      glBeginTransformFeedback(GL_POINTS);
      glBindBuffer(GL_DRAW_INDIRECT_BUFFER, out.list_args.id());
      glMemoryBarrier(GL_COMMAND_BARRIER_BIT);
      glDrawArraysIndirect(GL_POINTS, reinterpret_cast<const void*>(std::uintptr_t(
                                          kListArgsTriangleDraw * sizeof(std::uint32_t))));
      glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
      glEndTransformFeedback();
      glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, 0);
      glDisable(GL_RASTERIZER_DISCARD);
      glBindVertexArray(0);
    }
    TimedPass scope(timer, "pass2 replicate");
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    scan_.run(out.scan, n + 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    bind_output(i);
    dispatch_for_output(replicate_, i, out.list_args, kListArgsTriangleDispatch);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    write_draw_commands(i, args_);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    out.replication_valid = true;
  }

  // The replicated index, 8 bytes a pair, is one shader storage block.
  std::uint64_t max_pairs() const override {
    GLint64 block_bytes = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block_bytes);
    return std::uint64_t(std::max<GLint64>(block_bytes, 0)) / 8;
  }
  std::string_view max_pairs_reason() const override {
    return "the replicated index is one shader storage block of 8 bytes a pair";
  }

  Program count_, replicate_, args_;
  MaterialPrograms draw_;
  PrefixScan scan_;
  TransformFeedback feedback_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_facet_gs_pipeline() {
  return std::make_unique<FacetGsPipeline>();
}

}  // namespace facet::driver::detail
