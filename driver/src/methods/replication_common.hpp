#pragma once
// What the facet methods share (facets, facets-gs, naive): the scene's record table, per-frame
// object transforms, per-output facets, object culling by bounds and the frame's triangle list
// grouped by material; plus the GPU prefix scan of both pipelines.
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string_view>
#include <vector>

#include "facet/driver/facet_gpu.hpp"
#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/render_method.hpp"
#include "material_programs.hpp"

namespace facet::driver::detail {

// Times a pass with `timer` when there is one (GpuTimer::scope needs a timer).
class TimedPass {
 public:
  TimedPass(GpuTimer* timer, std::string_view pass) : timer_(timer) {
    if (timer_) timer_->begin(pass);
  }
  TimedPass(const TimedPass&) = delete;
  TimedPass& operator=(const TimedPass&) = delete;
  ~TimedPass() { end(); }
  void end() {
    if (timer_) timer_->end();
    timer_ = nullptr;
  }

 private:
  GpuTimer* timer_;
};

// Links the embedded shaders with the replication function library (replication_lib.comp) added
// as a second shader object to every vertex, tessellation control, geometry or compute stage
// among them.
// With `material`, scene/material.frag and the material form the fragment stage.
Program link_replication_program(std::initializer_list<std::string_view> shaders,
                                 const std::vector<ShaderDefine>& defines = {},
                                 const MaterialShader* material = nullptr);

// A buffer texture over a Buffer that ensure_capacity may replace: view() makes it anew when the
// buffer is not the one it was made for.
class BufferView {
 public:
  const Texture& view(const Buffer& buffer, GLenum internal_format, std::size_t texel_bytes);

 private:
  Texture texture_;
  GLuint buffer_id_ = 0;
};

// Grows `buffer` (contents lost) to hold at least `bytes`, doubling to keep reallocations rare.
void ensure_capacity(Buffer& buffer, std::size_t bytes);

// Exclusive prefix sum of uint32 values in place on the GPU: scan.comp over blocks of 1024,
// recursing on the block sums (multi-level for any count).
class PrefixScan {
 public:
  void prepare();
  // data[0, count) becomes its exclusive prefix sum. Issues memory barriers around each level.
  void run(const Buffer& data, std::uint32_t count);

 private:
  void run_level(const Buffer& data, std::uint32_t count, std::size_t level);
  Program scan_, add_;
  std::vector<Buffer> block_sums_;
};

// Replicas per pass-3 draw command on a software rasterizer. llvmpipe's draw module (Mesa 22.3)
// runs a draw in batches of up to 4096 vertices, and for a batch with clipping resets the vertex
// IDs of the whole batch at every flush of its small vertex buffer: a batch costs time quadratic
// in its size. Commands of 128 triangles made the dome master's pass 3 1.5x faster (see
// driver/README.md); a GPU takes one command per material.
inline constexpr std::uint32_t kSoftwareReplicasPerDraw = 128;
// Commands per material at most: one draw_args.comp work group row holds 64 each.
inline constexpr std::uint64_t kMaxDrawsPerMaterial = 65535u * 64u;
inline constexpr std::size_t kDrawCommandBytes = 16;  // DrawArraysIndirectCommand

struct ListEntry {  // std430 ListEntry of replication_lib.comp's List
  std::uint32_t record, first_triangle;
  // sole_piece_of_sphere of the record's object (grid coverage only), else kNoPiece.
  std::uint32_t sole_piece = kNoPiece;
  std::uint32_t padding = 0;
};
static_assert(sizeof(ListEntry) == 16);

// The block table that follows a frame's list and its header in the list buffer: value b is the
// last entry whose first_triangle is at most kListBlockTriangles·b, for b < ceil(triangles /
// kListBlockTriangles), then the last entry; packed four values to a texel (ListEntry-sized,
// RGBA32UI). The entry holding list triangle t lies between the values of t's block and the next.
// Padded with zeros to whole texels.
std::vector<std::uint32_t> list_block_table(std::span<const ListEntry> list,
                                            std::uint32_t triangles);

// The list's indirect arguments (binding::list_args, uint words), written with the list: the cull
// pass's dispatch (a work group per 64 list triangles and one more), the per-triangle dispatch
// of the scatter and replicate.comp (both in rows of kListArgsRowGroups groups), facets-gs'
// pass-1 draw (DrawArraysIndirectCommand of the
// list's triangles), then from kListArgsPatchDraws a patch draw of each material's triangles for
// the tessellator form.
inline constexpr std::uint32_t kListArgsCullDispatch = 0, kListArgsTriangleDispatch = 4,
                               kListArgsTriangleDraw = 8, kListArgsPatchDraws = 16;
// The dispatches come in rows of this many work groups of 64 (GL guarantees 65535 groups a
// dimension): a list of more than 65535 · 64 triangles takes several rows.
inline constexpr std::uint32_t kListArgsRowGroups = 1024;

class FacetMethodBase : public RenderMethod {
 public:
  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override;
  // Prepares anew (the method's own prepare) with the facets of the outputs kept.
  void replace_scene(const Scene& scene, const GpuScene& gpu_scene,
                     std::span<const OutputSpec> outputs, const RenderSettings& settings) override;

 protected:
  struct OutputState {
    explicit OutputState(FacetSet set) : facets(std::move(set)) {}
    FacetSet facets;
    // Whether this output's list is built on the GPU (list_build.comp); else on the CPU, which
    // fills object_visible, list and material_ranges.
    bool list_on_gpu = false;
    std::vector<std::uint8_t> object_visible;
    std::vector<ListEntry> list;
    std::vector<std::uint32_t> material_ranges;  // (begin, end) list triangles per material
    // List triangles, and of those the ones in entries with a sole piece: the CPU's, or on the
    // GPU the last read of the statistics.
    std::uint32_t triangles = 0;
    std::uint32_t triangles_sole_piece = 0;
    // The list: list_entries() entries, the header texel, the block table (sized for every
    // triangle of the scene); its indirect arguments; the list build's object flags, offsets
    // and entry states (GPU only).
    Buffer list_buffer, ranges_buffer, list_args, object_visible_flags, list_offsets, entry_states;
    Texture list_texels;  // list_buffer as a buffer texture
    // Replication results, reused while neither the view nor any object transform changes.
    // stats: visible triangles, pairs, overflow, staged pairs (std430 uints, count.comp), then
    // the list's triangles and those with a sole piece (list_build.comp).
    Buffer scan, pairs, stats, draw_args;
    // Pass 3's commands: draws_per_material per material, each of at most replicas_per_draw
    // replicas, and how many of them each material uses (replication/draw_args.comp).
    Buffer draw_counts;
    std::uint32_t draws_per_material = 1, replicas_per_draw = 1;
    // Pass 1's facets per triangle (facets only), and where each triangle's run starts; the
    // triangles the cull pass leaves to the grid pass, and those the grid pass leaves to the wide
    // pass and to the walk pass (each queue: its pass's indirect dispatch and count, then the list
    // triangles).
    Buffer staged, stage_offsets, grid_queue, wide_queue, walk_queue;
    // scan, staged and stage_offsets as R32UI buffer textures for the scatter (facets only).
    BufferView scan_texels, staged_texels, stage_offset_texels;
    std::uint32_t pair_capacity = 0;  // pairs that pairs and staged hold
    bool replication_valid = false;
    std::uint64_t replicas = 0, visible = 0;
  };

  // Uploads the object transforms, culls objects per output and rebuilds the triangle lists when
  // T_eye_world or any object's T_world_object (read from the scene at every call: a moving
  // scene changes them between frames) differs from the last frame's; returns whether it did.
  // A list built on the GPU is queued, not read back. With `timer`, each output's culling and
  // list count as its "pass1 coverage".
  bool update_view(const glm::dmat4& T_eye_world, GpuTimer* timer = nullptr);
  // Whether this method may build its lists on the GPU (naive draws from the CPU's culling).
  virtual bool lists_on_gpu_allowed() const { return true; }
  // Whether the records are clusters (make_cluster_records), culled one by one in the lists, or
  // whole primitives (naive draws each object whole).
  virtual bool culls_clusters() const { return true; }
  // Instances of the tessellator form's patch draws for output `out` (list_args).
  virtual std::uint32_t patch_instances(const OutputState&) const { return 1; }
  // eye_clusters_ for the view T_eye_world.
  void update_eye_clusters(const glm::dmat4& T_eye_world);
  // Output i's list, culled and built on the CPU or queued on the GPU.
  void build_list_on_cpu(std::size_t i);
  void build_list_on_gpu(std::size_t i);
  // Entries of every output's list: one per record.
  std::uint32_t list_entries() const { return std::uint32_t(entry_records_.size()); }
  // Triangles output i's list may hold this frame: the CPU's count, else every triangle.
  std::uint32_t list_capacity(std::size_t i) const;
  // Whether output i has facets and its list may hold triangles.
  bool may_draw(std::size_t i) const;
  // Sets output i's list triangles from statistics words 4 and 5 (`stats`, read by the caller).
  void take_list_counts(std::size_t i, const std::uint32_t* stats);
  // Binds the scene, record and object-frame buffers, and output i's facets and triangle list.
  void bind_output(std::size_t i) const;
  // Sets scene/material.frag's uniforms and texture for material m on `program`.
  void set_material(const Program& program, std::uint32_t m) const;
  // Sizes output i's draw commands for `replica_capacity` replicas (see kSoftwareReplicasPerDraw).
  void size_draw_commands(OutputState& out, std::uint64_t replica_capacity) const;
  // Pass 2c for output i: draw_args.comp writes the commands and their counts.
  void write_draw_commands(std::size_t i, const Program& args_program) const;
  // Pass 3 for output i into `target`: the commands of each material, drawn with its program of
  // `programs` as `mode` (one glDrawArraysIndirect, or a glMultiDrawArraysIndirectCount of
  // chunks).
  void draw_replicas(std::size_t i, const OutputTarget& target, const MaterialPrograms& programs,
                     GLenum mode) const;
  // Depth, clip-control and clip-distance state of pass 3, and its undoing.
  static void begin_facet_drawing(bool cull_back_faces);
  static void end_facet_drawing();
  std::uint32_t material_count() const { return std::uint32_t(records_by_material_.size()); }
  // GPU bytes of output state `out`: facet tables, coverage grid and hierarchy, triangle list,
  // scan, staging, pairs, statistics and draw arguments.
  std::uint64_t buffer_bytes(const OutputState& out) const;
  // Adds output `out`'s fixed figures to `stats` (facets, list triangles, those on one facet,
  // buffer_bytes).
  void add_output_stats(const OutputState& out, RenderStats& stats) const;
  // Program uniforms of replication_lib.comp for output i.
  void set_list_uniforms(const Program& program, std::size_t i) const;
  // Runs compute `program` for output i, with its uniforms set, over the indirect dispatch at
  // word `args_word` of `args` (output i's list arguments or one of its queues).
  void dispatch_for_output(const Program& program, std::size_t i, const Buffer& args,
                           std::uint32_t args_word) const;

  const Scene* scene_ = nullptr;
  const GpuScene* gpu_ = nullptr;
  RenderSettings settings_;
  std::vector<GpuRecord> records_;
  std::vector<std::vector<std::uint32_t>> records_by_material_;
  // The lists' entries: every record in material order, and each material's first entry (and
  // one past the last), as vectors and as the GPU list build's buffers.
  std::vector<std::uint32_t> entry_records_, material_first_entries_;
  std::uint32_t scene_list_triangles_ = 0;  // triangles of every record
  Buffer records_buffer_, object_frames_, entry_records_buffer_, material_first_entries_buffer_,
      object_spheres_buffer_, cluster_spheres_buffer_;
  Program list_objects_, list_counts_, list_write_;
  PrefixScan list_scan_;
  Texture record_texels_,
      object_frame_texels_;         // records_buffer_, object_frames_ as buffer textures
  bool software_renderer_ = false;  // is_software_renderer(), at prepare
  // Pass 3 splits each material's replicas into draws of kSoftwareReplicasPerDraw (see there).
  bool chunked_draws_ = false;
  VertexArray empty_vao_;  // core profile draws need a vertex array; attributes are pulled
  std::vector<OutputState> outputs_;
  glm::dmat4 last_T_eye_world_{0.0};
  bool have_view_ = false;
  std::vector<glm::mat4> last_T_world_object_;  // the transforms of the last update_view
  std::vector<BoundingSphere> eye_spheres_;     // the objects' spheres at the last update_view
  // The clusters' bounds in the object frame (empty where records are whole primitives), and at
  // the last update_view their spheres in the eye frame and how the lists cull them: as their
  // object (a sphere of at least kOwnSphereRatio of the object's culls little more, at two tests
  // per cluster and output: the city's lists on the cylinder at 160 strips took 1.46 ms a frame
  // at 3/4, 1.04 at 1/2, 0.64 with no cluster tested), by their own sphere, or always (they face
  // away, or hold no triangle).
  std::vector<ClusterBounds> cluster_bounds_;
  enum class ClusterCull : std::uint8_t { as_object, own_sphere, always };
  static constexpr double kOwnSphereRatio = 0.5;
  struct EyeCluster {
    BoundingSphere sphere;
    ClusterCull cull = ClusterCull::as_object;
  };
  std::vector<EyeCluster> eye_clusters_;
  // The outputs' facets and pair capacities while replace_scene prepares anew, taken by prepare
  // in output order (a rebuilt scene replicates about as much as the one it replaces, so its
  // first frame starts from the last frame's room rather than overflowing and replicating twice).
  std::vector<FacetSet> kept_facets_;
  std::vector<std::uint32_t> kept_pair_capacities_;
};

// The pipelines that replicate into a pair buffer (facets, facets-gs). A frame queues every
// output's passes 1 and 2 (`replicate`) and pass 3 (`draw`) without reading anything back, then
// reads each replicated output's statistics once (visible triangles, pairs, overflow). The pair
// buffers are sized from the last frame (the first: one pair per list triangle, at least
// kFirstPairCapacity); an output whose pairs overflowed them draws nothing, and is replicated and
// drawn again with room for 1.25x its pairs (RenderStats::overflow_reruns).
class PairPipelineBase : public FacetMethodBase {
 public:
  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override;

 protected:
  static constexpr std::uint32_t kFirstPairCapacity = 4096;
  // Passes 1 and 2 of output i, with `target` bound where a pass needs a framebuffer.
  virtual void replicate(std::size_t i, OutputTarget& target, GpuTimer* timer) = 0;
  // Pass 3 of output i into `target`.
  virtual void draw(std::size_t i, OutputTarget& target, GpuTimer* timer) = 0;
  // The most (triangle, facet) pairs one output may take in a frame, and why (for the error).
  virtual std::uint64_t max_pairs() const = 0;
  virtual std::string_view max_pairs_reason() const = 0;
  // Output i's pair capacity for this frame: the last frame's, or the first frame's.
  std::uint32_t pair_capacity(std::size_t i);
  // Reads output i's statistics after its passes; false when its pairs overflowed, after making
  // room for them (the caller replicates again). Pairs beyond max_pairs() are an InputError.
  bool read_replication(std::size_t i);
};

}  // namespace facet::driver::detail
