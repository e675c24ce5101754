// The naive multi-pass baseline ("naive"): for every piece (FacetPieces: a facet, or the quad of
// a cell's two facets that share a projection, as the replication pipelines draw them), one draw
// of each object run whose bounds may meet that piece's pyramid, with its matrix and clip planes.
// No coverage pass, no replication: the rasterizer's clipping does all the work.
#include <glm/gtc/type_ptr.hpp>
#include <optional>

#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"
#include "replication_common.hpp"

namespace facet::driver::detail {
namespace {

// naive.vert's uniforms, past replication_lib.comp's locations (the two link into one stage).
constexpr GLint kFacetLocation = 53;
constexpr GLint kRecordLocation = 54;

class NaiveMethod final : public FacetMethodBase {
 public:
  std::string_view name() const override { return "naive"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    FacetMethodBase::prepare(scene, gpu_scene, outputs, settings);
    draw_.prepare(scene, settings.material, [](const MaterialShader& shader) {
      return link_replication_program({"replication/naive.vert"}, {{"WRITE_TRIANGLE_ID", "1"}},
                                      &shader);
    });
  }

  // Draws per piece the objects the CPU culled.
  bool lists_on_gpu_allowed() const override { return false; }
  bool culls_clusters() const override { return false; }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(targets.size() == outputs_.size());
    update_view(T_eye_world);
    RenderStats stats;
    stats.triangles_scene = scene_->triangle_count();
    // The record table and object frames, shared by the outputs.
    stats.gpu_buffer_bytes = records_buffer_.size() + object_frames_.size();
    TimedPass scope(timer, "draw");
    for (std::size_t i = 0; i < outputs_.size(); ++i) {
      OutputState& out = outputs_[i];
      targets[i].clear();
      stats.facets += out.facets.mesh.facets.size();
      stats.triangles_in += out.triangles;
      // The facet tables and coverage structures it binds (and any list buffers prepare made).
      stats.gpu_buffer_bytes += buffer_bytes(out);
      bind_output(i);
      targets[i].bind();
      begin_facet_drawing(settings_.cull_back_faces);
      glBindVertexArray(empty_vao_.id());
      const FacetPieces& pieces = out.facets.pieces;
      std::uint32_t bound_material = UINT32_MAX;
      const Program* in_use = nullptr;
      for (std::uint32_t f = 0; f < pieces.size(); ++f) {
        if (!pieces.drawn(f)) continue;
        for (std::size_t slot = 0; slot < draw_.size(); ++slot)
          glProgramUniform1ui(draw_.program(slot).id(), kFacetLocation, f);
        for (std::uint32_t m = 0; m < material_count(); ++m) {
          for (std::uint32_t r : records_by_material_[m]) {
            const GpuRecord& record = records_[r];
            if (!out.object_visible[record.object]) continue;
            const BoundingSphere& sphere = eye_spheres_[record.object];
            if (!sphere_may_meet_cone(sphere.centre, sphere.radius * 1.0001,
                                      pieces.planes[f].data(), 4)) {
              continue;
            }
            if (m != bound_material) {
              const Program& program = draw_.program_of(m);
              if (&program != in_use) {
                program.use();
                in_use = &program;
              }
              set_material(program, m);
              bound_material = m;
            }
            glUniform1ui(kRecordLocation, r);
            glDrawArrays(GL_TRIANGLES, 0, GLsizei(3 * record.triangle_count));
            stats.replicas += record.triangle_count;
          }
        }
      }
      glBindVertexArray(0);
      end_facet_drawing();
      targets[i].resolve();
    }
    scope.end();
    if (timer) timer->end_frame();
    return stats;
  }

 private:
  MaterialPrograms draw_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_naive_method() { return std::make_unique<NaiveMethod>(); }

}  // namespace facet::driver::detail
