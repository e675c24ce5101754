// The modern replication pipeline ("facets"): compute-shader coverage, a parallel exclusive scan,
// a scatter of (triangle, facet) pairs with the indirect arguments, and indirect draws per
// material with vertex pulling (FacetMethodBase::draw_replicas; DESIGN.md, "The replication
// pipeline").
#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include "facet/driver/facet_gpu.hpp"
#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"
#include "replication_common.hpp"

namespace facet::driver {
std::vector<std::vector<std::uint32_t>> gpu_triangle_coverage(
    const Warp& warp, const RenderSettings& settings,
    const std::vector<std::array<glm::vec3, 3>>& triangles_eye, GpuCoverageRoutes* routes);
}

namespace facet::driver::detail {
namespace {

// A queue's header: its pass's indirect dispatch (x, y, z), then the queue's length
// (replication/count.comp).
constexpr std::size_t kQueueHeaderWords = 4;

class FacetPipeline final : public PairPipelineBase {
 public:
  std::string_view name() const override { return "facets"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    FacetMethodBase::prepare(scene, gpu_scene, outputs, settings);
    if (!count_) {
      count_ = link_replication_program({"replication/count.comp"});
      walk_ = link_replication_program({"replication/count.comp"}, {{"WALK_PASS", "1"}});
      // Eight triangles walked side by side per SIMD row, where every triangle walks: the walk
      // pass's one per work group took 806 ms a cylinder frame (400x300, 0.25 px), this 160.
      count_walk_ =
          link_replication_program({"replication/count.comp"}, {{"WALK_EVERY_TRIANGLE", "1"}});
      scatter_ = link_replication_program({"replication/scatter.comp"});
      args_ = build_program({"replication/draw_args.comp"}, {{"VERTICES_PER_REPLICA", "3"}});
      scan_.prepare();
    }
    draw_.prepare(scene, settings.material, [](const MaterialShader& shader) {
      return link_replication_program({"replication/draw.vert"}, {{"WRITE_TRIANGLE_ID", "1"}},
                                      &shader);
    });
    // The grid and wide passes are built for each output's kind of grid (replication_lib.comp,
    // grid_chart).
    for (const OutputState& out : outputs_) {
      const CoverageGrid& grid = out.facets.grid;
      const std::uint32_t kind = grid_kind(grid);
      if (grid_programs_.contains(kind)) continue;
      const std::vector<ShaderDefine> grid_defines = {
          {"GRID_CHART", std::to_string(std::uint32_t(grid.chart()))},
          {"GRID_PERIODIC", grid.periodic() ? "1" : "0"},
          {"GRID_CELL_BUCKETS", grid.cell_buckets() ? "1" : "0"}};
      std::vector<ShaderDefine> lane_defines = grid_defines;
      lane_defines.push_back({"GRID_PASS", "1"});
      grid_programs_.emplace(
          kind,
          GridPrograms{link_replication_program({"replication/count.comp"}, lane_defines),
                       link_replication_program({"replication/count_wide.comp"}, grid_defines)});
    }
  }

 private:
  void draw(std::size_t i, OutputTarget& target, GpuTimer* timer) override {
    TimedPass scope(timer, "pass3 draw");
    draw_replicas(i, target, draw_, GL_TRIANGLES);
  }

  // Passes 1 and 2 for output i: coverage with every facet staged, scan, the pairs' copy and the
  // indirect arguments, all without reading anything back.
  void replicate(std::size_t i, OutputTarget&, GpuTimer* timer) override {
    OutputState& out = outputs_[i];
    const std::uint32_t n = list_capacity(i);  // the list's triangles, or at most
    ensure_capacity(out.scan, (std::size_t(n) + 1) * sizeof(std::uint32_t));
    ensure_capacity(out.stage_offsets, std::max<std::size_t>(n, 1) * sizeof(std::uint32_t));
    for (Buffer* queue : {&out.grid_queue, &out.wide_queue, &out.walk_queue})
      ensure_capacity(*queue, (kQueueHeaderWords + std::size_t(n)) * sizeof(std::uint32_t));
    const std::uint32_t capacity = pair_capacity(i);
    ensure_capacity(out.staged, staged_words(capacity) * sizeof(std::uint32_t));
    ensure_capacity(out.pairs, std::size_t(capacity) * sizeof(GpuReplica));
    size_draw_commands(out, capacity);
    {
      TimedPass scope(timer, "pass1 coverage");
      const std::uint32_t zero[4] = {0, 0, 0, 0};
      out.stats.sub_data(0, sizeof zero, zero);
      const std::uint32_t empty_queue[kQueueHeaderWords] = {0, 0, 1, 0};
      out.grid_queue.sub_data(0, sizeof empty_queue, empty_queue);
      out.wide_queue.sub_data(0, sizeof empty_queue, empty_queue);
      out.walk_queue.sub_data(0, sizeof empty_queue, empty_queue);
      bind_output(i);
      const Program& first = settings_.coverage == FacetCoverage::walk ? count_walk_ : count_;
      dispatch_for_output(first, i, out.list_args, kListArgsCullDispatch);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
      const GridPrograms& grid = grid_programs_.at(grid_kind(out.facets.grid));
      for (const auto& [program, queue] :
           {std::pair<const Program*, const Buffer*>{&grid.lane, &out.grid_queue},
            std::pair<const Program*, const Buffer*>{&grid.wide, &out.wide_queue},
            std::pair<const Program*, const Buffer*>{&walk_, &out.walk_queue}}) {
        dispatch_for_output(*program, i, *queue, 0);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
      }
    }
    TimedPass scope(timer, "pass2 replicate");
    scan_.run(out.scan, n + 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    bind_output(i);
    out.scan_texels.view(out.scan, GL_R32UI, 4).bind_unit(texture_unit::scan);
    out.staged_texels.view(out.staged, GL_R32UI, 4).bind_unit(texture_unit::staged);
    out.stage_offset_texels.view(out.stage_offsets, GL_R32UI, 4)
        .bind_unit(texture_unit::stage_offsets);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    dispatch_for_output(scatter_, i, out.list_args, kListArgsTriangleDispatch);
    write_draw_commands(i, args_);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    out.replication_valid = true;
  }

  // The scatter reads the staged words, two a pair and 16 more at most, as a buffer texture.
  std::uint64_t max_pairs() const override {
    GLint max_texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    const std::uint64_t max_words = std::min<std::uint64_t>(
        std::numeric_limits<std::int32_t>::max(), std::uint64_t(std::max(max_texels, 16)));
    return (max_words - 16) / 2;
  }
  std::string_view max_pairs_reason() const override {
    return "pass 1 stages up to two words a pair, read as a buffer texture";
  }

  friend std::vector<std::vector<std::uint32_t>> facet::driver::gpu_triangle_coverage(
      const Warp&, const RenderSettings&, const std::vector<std::array<glm::vec3, 3>>&,
      GpuCoverageRoutes*);

  static std::uint32_t grid_kind(const CoverageGrid& grid) {
    return std::uint32_t(grid.chart()) | (grid.periodic() ? 16u : 0u) |
           (grid.cell_buckets() ? 32u : 0u);
  }

  Program count_, walk_, count_walk_, scatter_, args_;
  MaterialPrograms draw_;
  struct GridPrograms {
    Program lane, wide;  // the grid pass (count.comp's GRID_PASS) and the wide pass
  };
  std::map<std::uint32_t, GridPrograms> grid_programs_;  // per grid_kind
  PrefixScan scan_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_facet_pipeline() { return std::make_unique<FacetPipeline>(); }

}  // namespace facet::driver::detail

namespace facet::driver {

std::vector<std::vector<std::uint32_t>> gpu_triangle_coverage(
    const Warp& warp, const RenderSettings& settings,
    const std::vector<std::array<glm::vec3, 3>>& triangles_eye, GpuCoverageRoutes* routes) {
  std::vector<std::vector<std::uint32_t>> result(triangles_eye.size());
  if (triangles_eye.empty()) return result;
  Scene scene;
  scene.materials.push_back({});
  for (const auto& triangle : triangles_eye) {
    for (const glm::vec3& p : triangle) {
      scene.indices.push_back(std::uint32_t(scene.positions.size()));
      scene.positions.push_back(p);
      scene.normals.push_back({0, 0, 1});
      scene.uvs.push_back({0, 0});
    }
  }
  scene.primitives.push_back({0, std::uint32_t(scene.indices.size()), 0});
  Object object;
  object.primitive_count = 1;
  scene.objects.push_back(object);
  scene.update_bounds();
  const GpuScene gpu = upload_scene(scene);
  detail::FacetPipeline pipeline;
  const OutputSpec output{"coverage", warp};
  pipeline.prepare(scene, gpu, std::span(&output, 1), settings);
  pipeline.update_view(glm::dmat4(1.0));
  auto& out = pipeline.outputs_[0];
  if (!pipeline.may_draw(0)) return result;
  OutputTarget unused_target;
  pipeline.replicate(0, unused_target, nullptr);
  if (!pipeline.read_replication(0)) {
    pipeline.replicate(0, unused_target, nullptr);
    const bool fits = pipeline.read_replication(0);
    FACET_ASSERT(fits);
  }
  if (routes) {
    const auto queued = [](const Buffer& queue) {
      std::uint32_t header[detail::kQueueHeaderWords] = {};
      queue.get_sub_data(0, sizeof header, header);
      return header[detail::kQueueHeaderWords - 1];
    };
    *routes = {queued(out.grid_queue), queued(out.wide_queue), queued(out.walk_queue)};
  }
  std::vector<GpuReplica> replicas(out.replicas);
  if (!replicas.empty())
    out.pairs.get_sub_data(0, replicas.size() * sizeof(GpuReplica), replicas.data());
  // The scene's one primitive lists triangle t at index 3t.
  for (const GpuReplica& replica : replicas)
    result.at(replica.first_index / 3).push_back(replica.piece);
  for (auto& facets : result) std::sort(facets.begin(), facets.end());
  return result;
}

}  // namespace facet::driver
