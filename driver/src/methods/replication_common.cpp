#include "replication_common.hpp"

#include <algorithm>
#include <cstdint>
#include <glm/gtc/type_ptr.hpp>
#include <string>

#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/shader_library.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/parallel.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver::detail {

Program link_replication_program(std::initializer_list<std::string_view> shaders,
                                 const std::vector<ShaderDefine>& defines,
                                 const MaterialShader* material) {
  ProgramBuilder builder;
  for (const ShaderDefine& d : defines) builder.define(d.name, d.value);
  const std::string_view lib_name = "replication/replication_lib.comp";
  const std::string lib_text(embedded_shader(lib_name).text);
  bool compute_has_lib = false;
  for (std::string_view name : shaders) {
    builder.shader(name);
    const ShaderStage stage = stage_from_name(name);
    if (stage == ShaderStage::vertex || stage == ShaderStage::tess_control ||
        stage == ShaderStage::geometry || (stage == ShaderStage::compute && !compute_has_lib)) {
      builder.source(stage, std::string(lib_name), lib_text);
      if (stage == ShaderStage::compute) compute_has_lib = true;
    }
  }
  if (!material) return builder.link();
  add_material_stages(builder, *material);
  return link_with_material(builder, *material);
}

std::vector<std::uint32_t> list_block_table(std::span<const ListEntry> list,
                                            std::uint32_t triangles) {
  FACET_ASSERT(!list.empty());
  const std::uint32_t blocks = (triangles + kListBlockTriangles - 1) / kListBlockTriangles;
  std::vector<std::uint32_t> values;
  values.reserve(blocks + 4);
  std::uint32_t entry = 0;
  for (std::uint32_t b = 0; b < blocks; ++b) {
    const std::uint32_t first = b * kListBlockTriangles;
    while (entry + 1 < list.size() && list[entry + 1].first_triangle <= first) ++entry;
    values.push_back(entry);
  }
  values.push_back(std::uint32_t(list.size() - 1));
  values.resize((values.size() + 3) / 4 * 4, 0);  // whole RGBA32UI texels
  return values;
}

const Texture& BufferView::view(const Buffer& buffer, GLenum internal_format,
                                std::size_t texel_bytes) {
  if (!texture_ || buffer_id_ != buffer.id()) {
    texture_ = Texture::create_buffer_view(buffer, internal_format, texel_bytes);
    buffer_id_ = buffer.id();
  }
  return texture_;
}

void ensure_capacity(Buffer& buffer, std::size_t bytes) {
  if (buffer && buffer.size() >= bytes) return;
  std::size_t size = buffer ? buffer.size() : 256;
  while (size < bytes) size *= 2;
  buffer = Buffer::create(size);
}

void PrefixScan::prepare() {
  scan_ = build_program({"replication/scan.comp"});
  add_ = build_program({"replication/scan.comp"}, {{"SCAN_ADD", "1"}});
  // Sized once: run_level recurses on references into this vector. Four levels of 1024-element
  // blocks scan 2^40 values.
  block_sums_.resize(4);
}

void PrefixScan::run(const Buffer& data, std::uint32_t count) {
  if (count > 0) run_level(data, count, 0);
}

void PrefixScan::run_level(const Buffer& data, std::uint32_t count, std::size_t level) {
  constexpr std::uint32_t kBlock = 4 * 256;  // scan.comp: 4 elements per thread, 256 threads
  const std::uint32_t groups = (count + kBlock - 1) / kBlock;
  FACET_ASSERT(level < block_sums_.size());
  ensure_capacity(block_sums_[level], std::size_t(groups) * sizeof(std::uint32_t));
  const auto bind = [&] {
    data.bind_base(GL_SHADER_STORAGE_BUFFER, binding::scan);
    block_sums_[level].bind_base(GL_SHADER_STORAGE_BUFFER, binding::block_sums);
  };
  bind();
  scan_.use();
  glUniform1ui(0, count);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  glDispatchCompute(groups, 1, 1);
  if (groups == 1) return;
  run_level(block_sums_[level], groups, level + 1);
  bind();
  add_.use();
  glUniform1ui(0, count);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  glDispatchCompute(groups, 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void FacetMethodBase::prepare(const Scene& scene, const GpuScene& gpu_scene,
                              std::span<const OutputSpec> outputs, const RenderSettings& settings) {
  refuse_glc_outputs(outputs, name());
  if (!(settings.z_near > 0)) {
    throw InputError("render settings", "z_near", "expected a near distance > 0 metres");
  }
  scene_ = &scene;
  gpu_ = &gpu_scene;
  settings_ = settings;
  records_ = culls_clusters() ? make_cluster_records(scene) : make_records(scene);
  // On every hardware thread: a depth image's 570,509 triangles took 20 ms on one.
  cluster_bounds_.assign(culls_clusters() ? records_.size() : 0, {});
  facet::detail::parallel_for(
      cluster_bounds_.size(),
      [&](std::size_t r, std::size_t) { cluster_bounds_[r] = cluster_bounds(scene, records_[r]); },
      1024);
  records_by_material_.assign(std::max<std::size_t>(scene.materials.size(), 1), {});
  for (std::uint32_t r = 0; r < records_.size(); ++r) {
    records_by_material_.at(records_[r].material).push_back(r);
  }
  entry_records_.clear();
  material_first_entries_.clear();
  std::uint64_t scene_triangles = 0;
  for (const auto& material_records : records_by_material_) {
    material_first_entries_.push_back(std::uint32_t(entry_records_.size()));
    for (std::uint32_t r : material_records) {
      entry_records_.push_back(r);
      scene_triangles += records_[r].triangle_count;
    }
  }
  material_first_entries_.push_back(std::uint32_t(entry_records_.size()));
  // One more triangle is the cull pass's end marker; the list positions are uint32.
  if (scene_triangles >= UINT32_MAX)
    throw InputError("scene", "triangles",
                     "fewer than 2^32 - 1 triangles for the facet methods; it has " +
                         std::to_string(scene_triangles));
  scene_list_triangles_ = std::uint32_t(scene_triangles);
  const std::uint32_t no_entry = 0;
  entry_records_buffer_ = entry_records_.empty() ? Buffer::create(sizeof no_entry, &no_entry)
                                                 : Buffer::create_from(entry_records_);
  material_first_entries_buffer_ = Buffer::create_from(material_first_entries_);
  object_spheres_buffer_ =
      Buffer::create(std::max<std::size_t>(scene.objects.size(), 1) * sizeof(glm::vec4));
  cluster_spheres_buffer_ =
      Buffer::create(std::max<std::size_t>(cluster_bounds_.size(), 1) * sizeof(glm::vec4));
  const GpuRecord no_record{};
  records_buffer_ = records_.empty() ? Buffer::create(sizeof no_record, &no_record)
                                     : Buffer::create_from(records_);
  object_frames_ =
      Buffer::create(std::max<std::size_t>(scene.objects.size(), 1) * sizeof(GpuObjectFrame));
  record_texels_ =
      Texture::create_buffer_view(records_buffer_, GL_RGBA32UI, 4 * sizeof(std::uint32_t));
  object_frame_texels_ = Texture::create_buffer_view(object_frames_, GL_RGBA32F, 4 * sizeof(float));
  if (!empty_vao_) empty_vao_ = VertexArray::create();
  software_renderer_ = is_software_renderer();
  chunked_draws_ = software_renderer_ && (epoxy_gl_version() >= 46 ||
                                          epoxy_has_gl_extension("GL_ARB_indirect_parameters"));
  const bool gpu_lists =
      lists_on_gpu_allowed() &&
      (settings.triangle_list == TriangleListBuild::gpu ||
       (settings.triangle_list == TriangleListBuild::automatic && !is_software_renderer()));
  if (gpu_lists && !list_write_) {
    list_objects_ =
        link_replication_program({"replication/list_build.comp"}, {{"OBJECT_PASS", "1"}});
    list_counts_ = link_replication_program({"replication/list_build.comp"}, {{"COUNT_PASS", "1"}});
    list_write_ = link_replication_program({"replication/list_build.comp"}, {{"WRITE_PASS", "1"}});
    list_scan_.prepare();
  }
  // The list buffer: the entries, the header texel, and a block table for every triangle.
  const std::size_t table_values = scene_list_triangles_ / kListBlockTriangles + 2;
  const std::size_t list_texels = list_entries() + 1 + (table_values + 3) / 4;
  const std::size_t args_words = kListArgsPatchDraws + 4 * std::size_t(material_count());
  std::vector<FacetSet> kept = std::move(kept_facets_);
  const std::vector<std::uint32_t> kept_pairs = std::move(kept_pair_capacities_);
  kept_facets_.clear();
  kept_pair_capacities_.clear();
  outputs_.clear();
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    OutputState state(kept.size() == outputs.size()
                          ? std::move(kept[i])
                          : FacetSet::build(outputs[i].warp, settings.facets, settings.z_near,
                                            settings.merge_coplanar_facets));
    const std::uint32_t no_stats[6] = {0, 0, 0, 0, 0, 0};
    state.stats = Buffer::create(sizeof no_stats, no_stats);
    state.list_on_gpu = gpu_lists && list_entries() > 0 && !state.facets.mesh.facets.empty();
    state.list_buffer = Buffer::create(list_texels * sizeof(ListEntry));
    state.list_texels =
        Texture::create_buffer_view(state.list_buffer, GL_RGBA32UI, sizeof(ListEntry));
    state.ranges_buffer = Buffer::create(2 * std::size_t(material_count()) * sizeof(std::uint32_t));
    state.list_args = Buffer::create(args_words * sizeof(std::uint32_t));
    if (state.list_on_gpu) {
      state.object_visible_flags =
          Buffer::create(std::max<std::size_t>(scene.objects.size(), 1) * sizeof(std::uint32_t));
      state.list_offsets =
          Buffer::create((std::size_t(list_entries()) + 1) * sizeof(std::uint32_t));
      state.entry_states =
          Buffer::create(std::max<std::size_t>(list_entries(), 1) * sizeof(std::uint32_t));
    }
    if (kept_pairs.size() == outputs.size()) state.pair_capacity = kept_pairs[i];
    outputs_.push_back(std::move(state));
  }
  have_view_ = false;
}

void FacetMethodBase::replace_scene(const Scene& scene, const GpuScene& gpu_scene,
                                    std::span<const OutputSpec> outputs,
                                    const RenderSettings& settings) {
  kept_facets_.clear();
  kept_pair_capacities_.clear();
  if (outputs.size() == outputs_.size())
    for (OutputState& out : outputs_) {
      kept_facets_.push_back(std::move(out.facets));
      kept_pair_capacities_.push_back(out.pair_capacity);
    }
  prepare(scene, gpu_scene, outputs, settings);
}

std::uint32_t FacetMethodBase::list_capacity(std::size_t i) const {
  const OutputState& out = outputs_[i];
  return out.list_on_gpu ? scene_list_triangles_ : out.triangles;
}

bool FacetMethodBase::may_draw(std::size_t i) const {
  return list_capacity(i) != 0 && !outputs_[i].facets.mesh.facets.empty();
}

void FacetMethodBase::take_list_counts(std::size_t i, const std::uint32_t* stats) {
  OutputState& out = outputs_[i];
  out.triangles = stats[4];
  out.triangles_sole_piece = stats[5];
}

bool FacetMethodBase::update_view(const glm::dmat4& T_eye_world, GpuTimer* timer) {
  const Scene& scene = *scene_;
  bool objects_moved = last_T_world_object_.size() != scene.objects.size();
  for (std::size_t o = 0; !objects_moved && o < scene.objects.size(); ++o)
    objects_moved = scene.objects[o].T_world_object != last_T_world_object_[o];
  if (have_view_ && T_eye_world == last_T_eye_world_ && !objects_moved) return false;
  have_view_ = true;
  last_T_eye_world_ = T_eye_world;
  last_T_world_object_.resize(scene.objects.size());
  for (std::size_t o = 0; o < scene.objects.size(); ++o)
    last_T_world_object_[o] = scene.objects[o].T_world_object;
  std::vector<GpuObjectFrame> frames(std::max<std::size_t>(scene.objects.size(), 1));
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    const glm::mat4 T_eye_object(T_eye_world * glm::dmat4(object.T_world_object));
    std::copy_n(glm::value_ptr(T_eye_object), 16, frames[o].T_eye_object);
    std::copy_n(glm::value_ptr(object.T_world_object), 16, frames[o].T_world_object);
  }
  eye_spheres_ = object_spheres(scene, T_eye_world);
  update_eye_clusters(T_eye_world);
  object_frames_.sub_data(0, frames.size() * sizeof(GpuObjectFrame), frames.data());
  if (std::any_of(outputs_.begin(), outputs_.end(),
                  [](const OutputState& out) { return out.list_on_gpu; })) {
    // In float, grown by 1e-6 of the distance: more than the centre's rounding (about 1e-7 of it)
    // and the plane tests' (a few ulps of the distance).
    const auto float_sphere = [](const BoundingSphere& sphere) {
      const double grown = sphere.radius * 1.0001 + 1e-6 * glm::length(sphere.centre);
      return glm::vec4(glm::vec3(sphere.centre), float(grown));
    };
    std::vector<glm::vec4> spheres(std::max<std::size_t>(eye_spheres_.size(), 1), glm::vec4(-1));
    for (std::size_t o = 0; o < eye_spheres_.size(); ++o)
      if (eye_spheres_[o].radius >= 0) spheres[o] = float_sphere(eye_spheres_[o]);
    object_spheres_buffer_.sub_data(0, spheres.size() * sizeof(glm::vec4), spheres.data());
    // The clusters' likewise, with w = kClusterCulledAlways or kClusterAsObject where their own
    // spheres are not tested.
    if (!eye_clusters_.empty()) {
      std::vector<glm::vec4> cluster_spheres(eye_clusters_.size());
      for (std::size_t r = 0; r < eye_clusters_.size(); ++r) {
        const EyeCluster& cluster = eye_clusters_[r];
        cluster_spheres[r] = float_sphere(cluster.sphere);
        if (cluster.cull == ClusterCull::always) cluster_spheres[r].w = kClusterCulledAlways;
        if (cluster.cull == ClusterCull::as_object) cluster_spheres[r].w = kClusterAsObject;
      }
      cluster_spheres_buffer_.sub_data(0, cluster_spheres.size() * sizeof(glm::vec4),
                                       cluster_spheres.data());
    }
  }
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    outputs_[i].replication_valid = false;
    TimedPass scope(timer, "pass1 coverage");
    if (outputs_[i].list_on_gpu) {
      build_list_on_gpu(i);
    } else {
      build_list_on_cpu(i);
    }
  }
  return true;
}

void FacetMethodBase::update_eye_clusters(const glm::dmat4& T_eye_world) {
  const Scene& scene = *scene_;
  eye_clusters_.assign(cluster_bounds_.size(), {});
  if (cluster_bounds_.empty()) return;
  // Per object: T_eye_object, the factor that bounds how it scales lengths, and for a similarity
  // (the columns orthogonal and of one length) the sign of its determinant, which turns winding
  // normals; 0 for any other transform, whose normal cones are not kept.
  struct Frame {
    glm::dmat4 T_eye_object;
    double scale;
    double normal_sign;
  };
  std::vector<Frame> frames(scene.objects.size());
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const glm::dmat4 T = T_eye_world * glm::dmat4(scene.objects[o].T_world_object);
    const glm::dmat3 M(T);
    const double l0 = glm::length(M[0]), l1 = glm::length(M[1]), l2 = glm::length(M[2]);
    const double longest = std::max({l0, l1, l2});
    const double tolerance = 1e-6 * longest * longest;
    const bool similarity =
        std::abs(l0 * l0 - l1 * l1) <= tolerance && std::abs(l0 * l0 - l2 * l2) <= tolerance &&
        std::abs(glm::dot(M[0], M[1])) <= tolerance &&
        std::abs(glm::dot(M[0], M[2])) <= tolerance && std::abs(glm::dot(M[1], M[2])) <= tolerance;
    // The spectral norm is at most the Frobenius norm; for a similarity it is the column length.
    const double scale = similarity ? longest * (1 + 1e-6) : std::sqrt(l0 * l0 + l1 * l1 + l2 * l2);
    frames[o] = {T, scale, similarity ? (glm::determinant(M) < 0 ? -1.0 : 1.0) : 0.0};
  }
  for (std::size_t r = 0; r < records_.size(); ++r) {
    const ClusterBounds& bounds = cluster_bounds_[r];
    EyeCluster& eye = eye_clusters_[r];
    if (bounds.radius < 0) {
      eye.cull = ClusterCull::always;
      continue;
    }
    const std::uint32_t object = records_[r].object;
    const Frame& frame = frames[object];
    eye.sphere.centre = glm::dvec3(frame.T_eye_object * glm::dvec4(bounds.centre, 1.0));
    eye.sphere.radius = bounds.radius * frame.scale;
    if (settings_.cull_back_faces && frame.normal_sign != 0) {
      const glm::dvec3 axis =
          frame.normal_sign * glm::normalize(glm::dmat3(frame.T_eye_object) * bounds.normal_axis);
      if (cluster_faces_away(eye.sphere.centre, eye.sphere.radius, axis,
                             bounds.normal_spread_sin)) {
        eye.cull = ClusterCull::always;
        continue;
      }
    }
    eye.cull = eye.sphere.radius < kOwnSphereRatio * eye_spheres_[object].radius
                   ? ClusterCull::own_sphere
                   : ClusterCull::as_object;
  }
}

void FacetMethodBase::build_list_on_cpu(std::size_t i) {
  const Scene& scene = *scene_;
  OutputState& out = outputs_[i];
  // Each object's and then each record's state in this output's list: culled, its sole piece
  // (an object or cluster inside one piece and clear of the others, whose triangles pass 1 gives
  // that piece without the grid; the walk, the reference, always walks), or kNoPiece. On one
  // thread: with two, sharing the cores with llvmpipe's, the cylinder's lists at 160 strips took
  // 1.3-2.2 ms against 1.6.
  constexpr std::uint32_t kCulled = kNoPiece - 1;
  const bool sole_pieces = settings_.coverage == FacetCoverage::grid;
  std::vector<std::uint32_t> object_state(scene.objects.size(), kCulled);
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const BoundingSphere& sphere = eye_spheres_[o];
    const double radius = sphere.radius * 1.0001;
    if (!(sphere.radius >= 0) || !sphere_may_meet_facets(out.facets, sphere.centre, radius))
      continue;
    object_state[o] =
        sole_pieces ? sole_piece_of_sphere(out.facets, sphere.centre, radius) : kNoPiece;
  }
  out.object_visible.assign(scene.objects.size(), 0);
  for (std::size_t o = 0; o < scene.objects.size(); ++o)
    out.object_visible[o] = object_state[o] != kCulled;
  // A cluster of a seen object is culled when it faces away, or, where its object meets several
  // pieces, when its own sphere meets none; else it may lie in one piece alone (then its sphere
  // meets a facet).
  std::vector<std::uint32_t> record_state(records_.size());
  for (std::size_t r = 0; r < records_.size(); ++r) {
    std::uint32_t state = object_state[records_[r].object];
    if (state != kCulled && !eye_clusters_.empty()) {
      const EyeCluster& cluster = eye_clusters_[r];
      if (cluster.cull == ClusterCull::always) {
        state = kCulled;
      } else if (cluster.cull == ClusterCull::own_sphere && state == kNoPiece) {
        const glm::dvec3& centre = cluster.sphere.centre;
        const double radius = cluster.sphere.radius * 1.0001;
        if (sole_pieces) state = sole_piece_of_sphere(out.facets, centre, radius);
        if (state == kNoPiece && !sphere_may_meet_facets(out.facets, centre, radius))
          state = kCulled;
      }
    }
    record_state[r] = state;
  }
  out.list.clear();
  out.material_ranges.clear();
  std::uint32_t triangles = 0;
  out.triangles_sole_piece = 0;
  std::vector<std::uint32_t> args(kListArgsPatchDraws + 4 * std::size_t(material_count()), 0);
  for (std::uint32_t m = 0; m < material_count(); ++m) {
    out.material_ranges.push_back(triangles);
    for (std::uint32_t k = material_first_entries_[m]; k < material_first_entries_[m + 1]; ++k) {
      const std::uint32_t r = entry_records_[k];
      const bool seen = record_state[r] != kCulled;
      const std::uint32_t sole = seen ? record_state[r] : kNoPiece;
      out.list.push_back({r, triangles, sole, 0});
      if (!seen) continue;
      triangles += records_[r].triangle_count;
      if (sole != kNoPiece) out.triangles_sole_piece += records_[r].triangle_count;
    }
    out.material_ranges.push_back(triangles);
    const std::uint32_t begin = out.material_ranges[2 * m], end = out.material_ranges[2 * m + 1];
    const std::size_t at = kListArgsPatchDraws + 4 * std::size_t(m);
    args[at] = end - begin;
    args[at + 1] = patch_instances(out);
    args[at + 2] = begin;
  }
  out.triangles = triangles;
  const std::uint32_t cull_groups = triangles / 64 + 1, triangle_groups = (triangles + 63) / 64;
  const auto rows = [](std::uint32_t groups) {
    return (groups + kListArgsRowGroups - 1) / kListArgsRowGroups;
  };
  const std::uint32_t fixed_args[kListArgsPatchDraws] = {
      std::min(cull_groups, kListArgsRowGroups),
      rows(cull_groups),
      1,
      0,
      std::min(triangle_groups, kListArgsRowGroups),
      rows(triangle_groups),
      1,
      0,
      triangles,
      1,
      0,
      0,
      0,
      0,
      0,
      0};
  std::copy_n(fixed_args, kListArgsPatchDraws, args.begin());
  out.list_args.sub_data(0, args.size() * sizeof(std::uint32_t), args.data());
  const std::uint32_t list_counts[2] = {triangles, out.triangles_sole_piece};
  out.stats.sub_data(4 * sizeof(std::uint32_t), sizeof list_counts, list_counts);

  const ListEntry header{triangles, out.triangles_sole_piece, 0, 0};
  const std::size_t list_bytes = out.list.size() * sizeof(ListEntry);
  if (!out.list.empty()) out.list_buffer.sub_data(0, list_bytes, out.list.data());
  out.list_buffer.sub_data(list_bytes, sizeof header, &header);
  if (!out.list.empty()) {
    const std::vector<std::uint32_t> block_table = list_block_table(out.list, triangles);
    out.list_buffer.sub_data(list_bytes + sizeof header, block_table.size() * sizeof(std::uint32_t),
                             block_table.data());
  }
  if (!out.material_ranges.empty())
    out.ranges_buffer.sub_data(0, out.material_ranges.size() * sizeof(std::uint32_t),
                               out.material_ranges.data());
}

void FacetMethodBase::build_list_on_gpu(std::size_t i) {
  OutputState& out = outputs_[i];
  const auto groups = [](std::size_t invocations) { return GLuint((invocations + 63) / 64); };
  out.facets.bind();
  record_texels_.bind_unit(texture_unit::records);
  object_spheres_buffer_.bind_base(GL_SHADER_STORAGE_BUFFER, binding::object_spheres);
  out.object_visible_flags.bind_base(GL_SHADER_STORAGE_BUFFER, binding::object_visible);
  entry_records_buffer_.bind_base(GL_SHADER_STORAGE_BUFFER, binding::entry_records);
  out.stats.bind_base(GL_SHADER_STORAGE_BUFFER, binding::stats);
  const std::uint32_t objects = std::uint32_t(scene_->objects.size());
  const CoverageGrid& grid = out.facets.grid;
  const bool sole_pieces =
      settings_.coverage == FacetCoverage::grid && grid.cell_buckets() && grid.pads_under_a_cell();
  glProgramUniform1ui(list_objects_.id(), list_objects_.uniform_location("object_count"), objects);
  glProgramUniform1ui(list_objects_.id(), list_objects_.uniform_location("sole_pieces"),
                      sole_pieces ? 1u : 0u);
  list_objects_.use();
  glDispatchCompute(groups(objects), 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

  out.list_offsets.bind_base(GL_SHADER_STORAGE_BUFFER, binding::scan);
  cluster_spheres_buffer_.bind_base(GL_SHADER_STORAGE_BUFFER, binding::cluster_spheres);
  out.entry_states.bind_base(GL_SHADER_STORAGE_BUFFER, binding::entry_states);
  const std::pair<const char*, std::uint32_t> count_uniforms[] = {
      {"list_entries", list_entries()},
      {"sole_pieces", sole_pieces ? 1u : 0u},
      {"cluster_culling", eye_clusters_.empty() ? 0u : 1u}};
  for (const auto& [name, value] : count_uniforms)
    glProgramUniform1ui(list_counts_.id(), list_counts_.uniform_location(name), value);
  list_counts_.use();
  glDispatchCompute(groups(std::size_t(list_entries()) + 1), 1, 1);
  list_scan_.run(out.list_offsets, list_entries() + 1);
  out.entry_states.bind_base(GL_SHADER_STORAGE_BUFFER, binding::entry_states);

  out.list_offsets.bind_base(GL_SHADER_STORAGE_BUFFER, binding::scan);
  out.list_buffer.bind_base(GL_SHADER_STORAGE_BUFFER, binding::list_out);
  out.ranges_buffer.bind_base(GL_SHADER_STORAGE_BUFFER, binding::material_ranges);
  material_first_entries_buffer_.bind_base(GL_SHADER_STORAGE_BUFFER,
                                           binding::material_first_entries);
  out.list_args.bind_base(GL_SHADER_STORAGE_BUFFER, binding::list_args);
  out.stats.bind_base(GL_SHADER_STORAGE_BUFFER, binding::stats);
  const std::pair<const char*, std::uint32_t> uniforms[] = {
      {"list_entries", list_entries()},
      {"material_count", material_count()},
      {"patch_instances", patch_instances(out)}};
  for (const auto& [name, value] : uniforms)
    glProgramUniform1ui(list_write_.id(), list_write_.uniform_location(name), value);
  list_write_.use();
  const std::size_t blocks = scene_list_triangles_ / kListBlockTriangles + 2;
  glDispatchCompute(
      groups(std::max({std::size_t(list_entries()), blocks, std::size_t(material_count())})), 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                  GL_COMMAND_BARRIER_BIT);
}

void FacetMethodBase::bind_output(std::size_t i) const {
  const GpuScene& gpu = *gpu_;
  gpu.bind_for_pulling();
  record_texels_.bind_unit(texture_unit::records);
  object_frame_texels_.bind_unit(texture_unit::object_frames);
  const OutputState& out = outputs_[i];
  out.facets.bind();
  out.list_texels.bind_unit(texture_unit::list);
  out.ranges_buffer.bind_base(GL_SHADER_STORAGE_BUFFER, binding::material_ranges);
  out.stats.bind_base(GL_SHADER_STORAGE_BUFFER, binding::stats);
  if (out.scan) out.scan.bind_base(GL_SHADER_STORAGE_BUFFER, binding::scan);
  if (out.pairs) out.pairs.bind_base(GL_SHADER_STORAGE_BUFFER, binding::pairs);
  if (out.staged) out.staged.bind_base(GL_SHADER_STORAGE_BUFFER, binding::staged);
  if (out.stage_offsets)
    out.stage_offsets.bind_base(GL_SHADER_STORAGE_BUFFER, binding::stage_offsets);
  if (out.walk_queue) out.walk_queue.bind_base(GL_SHADER_STORAGE_BUFFER, binding::walk_queue);
  if (out.grid_queue) out.grid_queue.bind_base(GL_SHADER_STORAGE_BUFFER, binding::grid_queue);
  if (out.wide_queue) out.wide_queue.bind_base(GL_SHADER_STORAGE_BUFFER, binding::wide_queue);
  if (out.draw_args) out.draw_args.bind_base(GL_SHADER_STORAGE_BUFFER, binding::draw_args);
}

void FacetMethodBase::set_list_uniforms(const Program& program, std::size_t i) const {
  const OutputState& out = outputs_[i];
  // By name: a location the linker dropped from this program must not be set.
  const std::pair<const char*, std::uint32_t> values[] = {
      {"list_entries", list_entries()},
      {"cull_back_faces", settings_.cull_back_faces ? 1u : 0u},
      {"material_count", material_count()},
      {"coverage_by_grid", settings_.coverage == FacetCoverage::grid ? 1u : 0u},
      {"pair_capacity", out.pair_capacity},
      {"staged_capacity", std::uint32_t(staged_words(out.pair_capacity))}};
  for (const auto& [uniform, value] : values) {
    const GLint location = program.uniform_location(uniform);
    if (location >= 0) glProgramUniform1ui(program.id(), location, value);
  }
}

void FacetMethodBase::dispatch_for_output(const Program& program, std::size_t i, const Buffer& args,
                                          std::uint32_t args_word) const {
  set_list_uniforms(program, i);
  program.use();
  glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, args.id());
  glDispatchComputeIndirect(GLintptr(args_word) * GLintptr(sizeof(std::uint32_t)));
  glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
}

std::uint64_t FacetMethodBase::buffer_bytes(const OutputState& out) const {
  const FacetSet& set = out.facets;
  std::uint64_t bytes =
      set.facets.size() + set.nodes.size() + set.order.size() + set.grid_words.size();
  for (const Buffer* b :
       {&out.list_buffer, &out.ranges_buffer, &out.list_args, &out.object_visible_flags,
        &out.entry_states, &out.list_offsets, &out.scan, &out.pairs, &out.stats, &out.draw_args,
        &out.draw_counts, &out.staged, &out.stage_offsets, &out.grid_queue, &out.wide_queue,
        &out.walk_queue})
    bytes += b->size();
  return bytes;
}

void FacetMethodBase::add_output_stats(const OutputState& out, RenderStats& stats) const {
  stats.facets += out.facets.mesh.facets.size();
  stats.triangles_in += out.triangles;
  stats.triangles_sole_piece += out.triangles_sole_piece;
  stats.triangle_list_on_gpu = stats.triangle_list_on_gpu || out.list_on_gpu;
  stats.gpu_buffer_bytes += buffer_bytes(out);
}

void FacetMethodBase::set_material(const Program& program, std::uint32_t m) const {
  if (m >= scene_->materials.size()) {
    const glm::vec4 white(1.0f);
    glProgramUniform4fv(program.id(), 8, 1, glm::value_ptr(white));
    glProgramUniform1i(program.id(), 9, 0);
    return;
  }
  const Material& material = scene_->materials[m];
  glProgramUniform4fv(program.id(), 8, 1, glm::value_ptr(material.base_colour));
  glProgramUniform1i(program.id(), 9, material.texture >= 0 ? 1 : 0);
  gpu_->bind_material_texture(m, 0);
}

void FacetMethodBase::size_draw_commands(OutputState& out, std::uint64_t replica_capacity) const {
  const std::uint64_t capacity = std::max<std::uint64_t>(replica_capacity, 1);
  std::uint64_t per_draw = chunked_draws_ ? kSoftwareReplicasPerDraw : capacity;
  if ((capacity + per_draw - 1) / per_draw > kMaxDrawsPerMaterial)
    per_draw = (capacity + kMaxDrawsPerMaterial - 1) / kMaxDrawsPerMaterial;
  out.replicas_per_draw = std::uint32_t(std::min<std::uint64_t>(per_draw, UINT32_MAX));
  out.draws_per_material = std::uint32_t((capacity + per_draw - 1) / per_draw);
  ensure_capacity(out.draw_args,
                  std::size_t(material_count()) * out.draws_per_material * kDrawCommandBytes);
  ensure_capacity(out.draw_counts, std::size_t(material_count()) * sizeof(std::uint32_t));
}

void FacetMethodBase::write_draw_commands(std::size_t i, const Program& args_program) const {
  const OutputState& out = outputs_[i];
  out.draw_counts.bind_base(GL_SHADER_STORAGE_BUFFER, binding::draw_counts);
  set_list_uniforms(args_program, i);
  glProgramUniform1ui(args_program.id(), args_program.uniform_location("draws_per_material"),
                      out.draws_per_material);
  glProgramUniform1ui(args_program.id(), args_program.uniform_location("replicas_per_draw"),
                      out.replicas_per_draw);
  args_program.use();
  glDispatchCompute((out.draws_per_material + 63) / 64, material_count(), 1);
}

void FacetMethodBase::draw_replicas(std::size_t i, const OutputTarget& target,
                                    const MaterialPrograms& programs, GLenum mode) const {
  const OutputState& out = outputs_[i];
  bind_output(i);
  target.bind();
  begin_facet_drawing(false);
  for (std::size_t slot = 0; slot < programs.size(); ++slot)
    set_list_uniforms(programs.program(slot), i);
  glBindVertexArray(empty_vao_.id());
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, out.draw_args.id());
  if (out.draws_per_material > 1) glBindBuffer(GL_PARAMETER_BUFFER_ARB, out.draw_counts.id());
  glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  const Program* in_use = nullptr;
  for (std::uint32_t m = 0; m < material_count(); ++m) {
    if (!out.list_on_gpu && out.material_ranges[2 * m] == out.material_ranges[2 * m + 1]) continue;
    const Program& program = programs.program_of(m);
    if (&program != in_use) {
      program.use();
      in_use = &program;
    }
    set_material(program, m);
    const std::uintptr_t first_command = std::uintptr_t(m) * out.draws_per_material;
    const auto* commands = reinterpret_cast<const void*>(first_command * kDrawCommandBytes);
    if (out.draws_per_material == 1) {
      glDrawArraysIndirect(mode, commands);
    } else {
      glMultiDrawArraysIndirectCountARB(mode, commands,
                                        GLintptr(m) * GLintptr(sizeof(std::uint32_t)),
                                        GLsizei(out.draws_per_material), 0);
    }
  }
  if (out.draws_per_material > 1) glBindBuffer(GL_PARAMETER_BUFFER_ARB, 0);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
  glBindVertexArray(0);
  end_facet_drawing();
}

void FacetMethodBase::begin_facet_drawing(bool cull_back_faces) {
  begin_reversed_z_scene(cull_back_faces);
  glFrontFace(GL_CCW);
  glDepthMask(GL_TRUE);
  for (int k = 0; k < 4; ++k) glEnable(GL_CLIP_DISTANCE0 + k);
}

void FacetMethodBase::end_facet_drawing() {
  for (int k = 0; k < 4; ++k) glDisable(GL_CLIP_DISTANCE0 + k);
  end_reversed_z_scene();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace facet::driver::detail

namespace facet::driver::detail {

RenderStats PairPipelineBase::render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                                     GpuTimer* timer) {
  FACET_ASSERT(targets.size() == outputs_.size());
  const bool changed = update_view(T_eye_world, timer);
  RenderStats stats;
  stats.triangles_scene = scene_->triangle_count();
  stats.reused_replication = !outputs_.empty();
  std::vector<std::size_t> replicated;
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    OutputState& out = outputs_[i];
    targets[i].clear();
    if (!may_draw(i)) continue;
    if (changed || !out.replication_valid) {
      stats.reused_replication = false;
      replicate(i, targets[i], timer);
      replicated.push_back(i);
    }
    draw(i, targets[i], timer);
  }
  // One read of each replicated output's statistics, after every output's passes are queued.
  for (std::size_t i : replicated) {
    if (read_replication(i)) continue;
    ++stats.overflow_reruns;
    targets[i].clear();
    replicate(i, targets[i], timer);
    draw(i, targets[i], timer);
    const bool fits = read_replication(i);
    FACET_ASSERT(fits);
  }
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    const OutputState& out = outputs_[i];
    targets[i].resolve();
    add_output_stats(out, stats);
    if (!may_draw(i)) continue;
    stats.replicas += out.replicas;
    stats.triangles_visible += out.visible;
  }
  if (timer) timer->end_frame();
  return stats;
}

std::uint32_t PairPipelineBase::pair_capacity(std::size_t i) {
  OutputState& out = outputs_[i];
  if (out.pair_capacity == 0) out.pair_capacity = std::max(list_capacity(i), kFirstPairCapacity);
  return out.pair_capacity;
}

bool PairPipelineBase::read_replication(std::size_t i) {
  OutputState& out = outputs_[i];
  // Visible triangles, pairs, overflow, staged pairs, list triangles, those with a sole piece.
  std::uint32_t values[6] = {0, 0, 0, 0, 0, 0};
  out.stats.get_sub_data(0, sizeof values, values);
  take_list_counts(i, values);
  out.visible = values[0];
  out.replicas = values[1];
  if (values[2] == 0) return true;
  const std::uint64_t wanted = std::uint64_t(values[1]) + values[1] / 4 + kFirstPairCapacity;
  const std::uint64_t most = std::min<std::uint64_t>(max_pairs(), UINT32_MAX);
  if (values[1] > most)
    throw InputError(
        "scene", "pairs",
        "at most " + std::to_string(most) + " (triangle, facet) pairs per output and frame (" +
            std::string(max_pairs_reason()) + "); this view needs " + std::to_string(values[1]));
  out.pair_capacity = std::uint32_t(std::min(wanted, most));
  out.replication_valid = false;
  return false;
}

}  // namespace facet::driver::detail
