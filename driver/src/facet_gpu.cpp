#include "facet/driver/facet_gpu.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "facet/projection/errors.hpp"

namespace facet::driver {

std::vector<GpuFacet> pack_facets(const FacetMesh& mesh, double z_near, double guard_px) {
  std::vector<GpuFacet> packed(mesh.facets.size());
  for (std::uint32_t f = 0; f < mesh.facets.size(); ++f) {
    const glm::dmat4 clip = mesh.facets[f].clip_from_eye(mesh.output_size, z_near);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) packed[f].clip_from_eye[c * 4 + r] = float(clip[c][r]);
    const auto planes = mesh.clip_planes(f, guard_px);
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 n = glm::normalize(planes[k]);
      packed[f].clip_planes[k][0] = float(n.x);
      packed[f].clip_planes[k][1] = float(n.y);
      packed[f].clip_planes[k][2] = float(n.z);
      packed[f].clip_planes[k][3] = 0.0f;
    }
  }
  return packed;
}

std::vector<GpuCoverageNode> pack_coverage_nodes(const CoverageIndex& index) {
  std::vector<GpuCoverageNode> packed(index.nodes().size());
  for (std::size_t i = 0; i < packed.size(); ++i) {
    const CoverageIndex::Node& node = index.nodes()[i];
    GpuCoverageNode& out = packed[i];
    out = {};
    out.first = node.first;
    out.count = node.count;
    // The shader's leaf loop has a constant trip count (kCoverageLeafSize in replication_lib).
    FACET_ASSERT(node.count <= 4);
    out.bounded = node.cos_half_angle > -1 ? 1u : 0u;
    if (!out.bounded) continue;
    out.cone[0] = float(node.axis.x);
    out.cone[1] = float(node.axis.y);
    out.cone[2] = float(node.axis.z);
    out.cone[3] = float(node.sin_half_angle);
    // The same tangent pyramid as CoverageIndex::query: planes sin·a ± cos·e for two unit
    // directions e perpendicular to the axis a.
    const glm::dvec3 a = node.axis;
    const glm::dvec3 helper = std::abs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(a, helper));
    const glm::dvec3 w = glm::cross(a, u);
    const double s = node.sin_half_angle, c = node.cos_half_angle;
    const glm::dvec3 planes[4] = {s * a - c * u, s * a + c * u, s * a - c * w, s * a + c * w};
    for (int k = 0; k < 4; ++k) {
      const glm::dvec3 n = glm::normalize(planes[k]);
      out.pyramid[k][0] = float(n.x);
      out.pyramid[k][1] = float(n.y);
      out.pyramid[k][2] = float(n.z);
      out.pyramid[k][3] = 0.0f;
    }
  }
  // Each split partitions its parent's range of the order, so a subtree's facets are contiguous;
  // children come after their parent, so a backward pass meets them first.
  for (std::size_t i = packed.size(); i-- > 0;) {
    GpuCoverageNode& out = packed[i];
    if (out.count > 0) {
      out.range_first = out.first;
      out.range_count = out.count;
    } else {
      const GpuCoverageNode& a = packed[out.first];
      const GpuCoverageNode& b = packed[out.first + 1];
      out.range_first = std::min(a.range_first, b.range_first);
      out.range_count = a.range_count + b.range_count;
    }
  }
  return packed;
}

std::vector<std::uint32_t> pack_coverage_grid(const CoverageGrid& grid) {
  std::vector<std::uint32_t> words(kGridHeaderWords, 0);
  const auto bits = [](double value) { return std::bit_cast<std::uint32_t>(float(value)); };
  words[0] = std::uint32_t(grid.chart());
  words[1] = grid.periodic() ? 1u : 0u;
  words[2] = grid.columns();
  words[3] = grid.rows();
  words[4] = bits(grid.p0());
  words[5] = bits(grid.q0());
  words[6] = bits(grid.dp());
  words[7] = bits(grid.dq());
  words[8] = bits(grid.radius_cap());
  const glm::dmat3& R = grid.R_base_eye();
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) words[12 + 3 * c + r] = bits(R[c][r]);
  words[9] = std::uint32_t(words.size());
  words.insert(words.end(), grid.bucket_first().begin(), grid.bucket_first().end());
  words[10] = std::uint32_t(words.size());
  words.insert(words.end(), grid.bucket_facets().begin(), grid.bucket_facets().end());
  words[11] = std::uint32_t(words.size());
  for (const BucketRange& r : grid.facet_buckets()) {
    words.insert(words.end(), {r.first_column, r.first_row, r.columns, r.rows});
  }
  words[21] = std::uint32_t(words.size());
  for (const auto& corners : grid.pyramid_corners())
    for (const glm::dvec3& c : corners)
      words.insert(words.end(), {bits(c.x), bits(c.y), bits(c.z)});
  return words;
}

std::vector<GpuRecord> make_records(const Scene& scene) {
  std::vector<GpuRecord> records;
  std::uint32_t next_id = 1;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
      const Primitive& p = scene.primitives[object.first_primitive + k];
      GpuRecord record{};
      record.first_index = p.first_index;
      record.triangle_count = p.index_count / 3;
      record.object = o;
      record.material = p.material;
      record.first_id = next_id;
      next_id += record.triangle_count;
      if (record.triangle_count > 0) records.push_back(record);
    }
  }
  return records;
}

FacetSet FacetSet::build(const Warp& warp, const FacetBuildOptions& options, double z_near) {
  FacetMesh mesh = build_facets(warp, options);
  CoverageIndex index(mesh);
  CoverageGrid grid(mesh, warp.base, warp.R_eye_base);
  FacetSet set{std::move(mesh), std::move(index), std::move(grid), {}, {}, {}, {}, {}};
  set.gpu_facets = pack_facets(set.mesh, z_near);
  const auto nodes = pack_coverage_nodes(set.index);
  // Empty buffers cannot be bound; keep one dummy element so that every binding is valid.
  const GpuFacet no_facet{};
  const GpuCoverageNode no_node{};
  const std::uint32_t no_order = 0;
  set.facets = set.gpu_facets.empty() ? Buffer::create(sizeof no_facet, &no_facet)
                                      : Buffer::create_from(set.gpu_facets);
  set.nodes = nodes.empty() ? Buffer::create(sizeof no_node, &no_node) : Buffer::create_from(nodes);
  set.grid_words = Buffer::create_from(pack_coverage_grid(set.grid));
  set.order = set.index.order().empty() ? Buffer::create(sizeof no_order, &no_order)
                                        : Buffer::create_from(set.index.order());
  return set;
}

void FacetSet::bind() const {
  facets.bind_base(GL_SHADER_STORAGE_BUFFER, binding::facets);
  nodes.bind_base(GL_SHADER_STORAGE_BUFFER, binding::nodes);
  order.bind_base(GL_SHADER_STORAGE_BUFFER, binding::order);
  grid_words.bind_base(GL_SHADER_STORAGE_BUFFER, binding::grid);
}

bool sphere_may_meet_cone(const glm::dvec3& centre, double radius, const glm::dvec3* planes,
                          int plane_count) {
  // Planes pass through the eye; a sphere wholly on the outside of one misses the cone.
  for (int k = 0; k < plane_count; ++k) {
    const double length = glm::length(planes[k]);
    if (length > 0 && glm::dot(planes[k], centre) / length < -radius) return false;
  }
  return true;
}

bool sphere_may_meet_facets(const FacetSet& set, const glm::dvec3& centre, double radius) {
  const auto& nodes = set.index.nodes();
  if (nodes.empty()) return false;
  if (glm::length(centre) <= radius) return true;  // the eye is inside: every direction
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const CoverageIndex::Node& node = nodes[stack[--top]];
    if (node.cos_half_angle > -1) {
      // Angular test of the sphere's cone against the node's cone.
      const double distance = glm::length(centre);
      const double sphere_half = std::asin(std::min(1.0, radius / distance));
      const double node_half = std::acos(std::clamp(node.cos_half_angle, -1.0, 1.0));
      const double between =
          std::acos(std::clamp(glm::dot(node.axis, centre / distance), -1.0, 1.0));
      if (between > node_half + sphere_half + 1e-9) continue;
    }
    if (node.count > 0) {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        const auto& planes = set.index.planes()[set.index.order()[k]];
        if (sphere_may_meet_cone(centre, radius, planes.data(), 3)) return true;
      }
    } else {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
    }
  }
  return false;
}

}  // namespace facet::driver
