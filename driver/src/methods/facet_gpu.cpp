#include "facet/driver/facet_gpu.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numbers>
#include <optional>

#include "facet/projection/errors.hpp"

namespace facet::driver {

namespace {

// Where pyramid planes a and b meet: the unit direction on the inner side of `inside`.
glm::dvec3 pyramid_corner(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& inside) {
  const glm::dvec3 corner = glm::normalize(glm::cross(a, b));
  return glm::dot(corner, inside) < 0 ? -corner : corner;
}

// Equal chord planes and M_q_eye up to rounding: either facet's projection draws the other's
// pixels within 1e-9 of its size (1e-6 px on a 1000 px output).
bool same_projection(const Facet& a, const Facet& b) {
  double scale = 0, difference = 0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) {
      scale = std::max(scale, std::abs(a.M_q_eye[c][r]));
      difference = std::max(difference, std::abs(a.M_q_eye[c][r] - b.M_q_eye[c][r]));
    }
  return difference <= 1e-9 * scale && glm::length(a.n - b.n) <= 1e-9 &&
         std::abs(a.h - b.h) <= 1e-9 * a.h;
}

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// The quad of facets a and b when they share an edge and a projection and their four corners are
// strictly convex in q: its guarded planes in order around it (a's two outer edges, then b's).
std::optional<std::array<glm::dvec3, 4>> quad_planes(const FacetMesh& mesh, std::uint32_t a,
                                                     std::uint32_t b, double guard_px) {
  const Facet& A = mesh.facets[a];
  const Facet& B = mesh.facets[b];
  if (!same_projection(A, B)) return std::nullopt;
  // The diagonal: a's edge k, from corner k to k + 1, is b's edge m reversed.
  int k = -1, m = -1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (A.vertex[i] == B.vertex[(j + 1) % 3] && A.vertex[(i + 1) % 3] == B.vertex[j])
        k = i, m = j;
  if (k < 0) return std::nullopt;
  // Around the quad: a's corners k + 1, k + 2, k, then b's corner m + 2.
  const std::uint32_t around[4] = {A.vertex[(k + 1) % 3], A.vertex[(k + 2) % 3], A.vertex[k],
                                   B.vertex[(m + 2) % 3]};
  glm::dvec2 q[4];
  for (int i = 0; i < 4; ++i) q[i] = mesh.vertices[around[i]].q;
  double turn[4], size = 0;
  for (int i = 0; i < 4; ++i) {
    turn[i] = cross2(q[(i + 1) % 4] - q[i], q[(i + 2) % 4] - q[(i + 1) % 4]);
    size = std::max(size, glm::length(q[(i + 1) % 4] - q[i]));
  }
  for (int i = 0; i < 4; ++i)
    if (!(turn[i] * turn[0] > 0 && std::abs(turn[i]) > 1e-9 * size * size)) return std::nullopt;
  const auto pa = mesh.clip_planes(a, guard_px);
  const auto pb = mesh.clip_planes(b, guard_px);
  return std::array<glm::dvec3, 4>{pa[(k + 1) % 3], pa[(k + 2) % 3], pb[(m + 1) % 3],
                                   pb[(m + 2) % 3]};
}

// The smallest range that holds both; periodic: the shorter way round.
BucketRange range_union(const BucketRange& a, const BucketRange& b, bool periodic,
                        std::uint32_t columns) {
  if (a.rows == 0) return b;
  if (b.rows == 0) return a;
  BucketRange u;
  u.first_row = std::min(a.first_row, b.first_row);
  u.rows = std::max(a.first_row + a.rows, b.first_row + b.rows) - u.first_row;
  if (!periodic) {
    u.first_column = std::min(a.first_column, b.first_column);
    u.columns = std::max(a.first_column + a.columns, b.first_column + b.columns) - u.first_column;
    return u;
  }
  const auto span_from = [columns](const BucketRange& from, const BucketRange& to) {
    return std::max(from.columns,
                    (to.first_column + columns - from.first_column) % columns + to.columns);
  };
  const std::uint32_t from_a = span_from(a, b), from_b = span_from(b, a);
  if (std::min(from_a, from_b) >= columns) {
    u.first_column = 0;
    u.columns = columns;
  } else if (from_a <= from_b) {
    u.first_column = a.first_column;
    u.columns = from_a;
  } else {
    u.first_column = b.first_column;
    u.columns = from_b;
  }
  return u;
}

}  // namespace

FacetPieces make_facet_pieces(const FacetMesh& mesh, bool merge_coplanar, double guard_px) {
  FacetPieces pieces;
  pieces.facet_count = std::uint32_t(mesh.facets.size());
  pieces.piece_of_facet.resize(mesh.facets.size());
  for (std::uint32_t f = 0; f < pieces.facet_count; ++f) {
    pieces.piece_of_facet[f] = f;
    const auto p = mesh.clip_planes(f, guard_px);
    pieces.planes.push_back({p[0], p[1], p[2], p[0]});
    std::array<glm::dvec3, 4> corners;
    for (int k = 0; k < 3; ++k) corners[k] = pyramid_corner(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
    corners[3] = corners[0];
    pieces.corners.push_back(corners);
  }
  if (!merge_coplanar) return pieces;
  for (const std::uint32_t first : mesh.cell_first_facet) {
    if (first == UINT32_MAX) continue;
    const auto planes = quad_planes(mesh, first, first + 1, guard_px);
    if (!planes) continue;
    const std::uint32_t piece = pieces.size();
    pieces.piece_of_facet[first] = pieces.piece_of_facet[first + 1] = piece;
    pieces.quads.push_back({first, first + 1});
    pieces.planes.push_back(*planes);
    std::array<glm::dvec3, 4> corners;
    for (int k = 0; k < 4; ++k)
      corners[k] = pyramid_corner((*planes)[k], (*planes)[(k + 1) % 4], (*planes)[(k + 2) % 4]);
    pieces.corners.push_back(corners);
  }
  return pieces;
}

std::vector<GpuFacet> pack_facets(const FacetMesh& mesh, const FacetPieces& pieces, double z_near) {
  std::vector<GpuFacet> packed(pieces.size());
  for (std::uint32_t p = 0; p < pieces.size(); ++p) {
    // A facet in a quad takes the quad's projection too (equal up to rounding), so that the walk,
    // which lists facets, writes the same depths as the grid.
    const std::uint32_t source =
        pieces.facet(p < pieces.facet_count ? pieces.piece_of_facet[p] : p);
    const glm::dmat4 clip = mesh.facets[source].clip_from_eye(mesh.output_size, z_near);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) packed[p].clip_from_eye[c * 4 + r] = float(clip[c][r]);
    for (int k = 0; k < 4; ++k) {
      const glm::dvec3 n = glm::normalize(pieces.planes[p][k]);
      packed[p].clip_planes[k][0] = float(n.x);
      packed[p].clip_planes[k][1] = float(n.y);
      packed[p].clip_planes[k][2] = float(n.z);
      packed[p].clip_planes[k][3] = 0.0f;
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

std::vector<std::uint32_t> pack_coverage_grid(const CoverageGrid& grid, const FacetPieces& pieces) {
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
  // Bucket ranges per piece: a facet's own where it is drawn, a quad's both facets'.
  const auto& facet_ranges = grid.facet_buckets();
  std::vector<BucketRange> ranges(pieces.size());
  for (std::uint32_t p = 0; p < pieces.size(); ++p) {
    if (!pieces.drawn(p)) continue;
    if (p < pieces.facet_count) {
      ranges[p] = facet_ranges[p];
    } else {
      const auto& quad = pieces.quads[p - pieces.facet_count];
      ranges[p] = range_union(facet_ranges[quad[0]], facet_ranges[quad[1]], grid.periodic(),
                              grid.columns());
    }
  }
  const std::uint32_t columns = grid.columns();
  const auto for_each_bucket = [&](const BucketRange& r, auto&& visit) {
    for (std::uint32_t j = r.first_row; j < r.first_row + r.rows; ++j)
      for (std::uint32_t k = 0; k < r.columns; ++k) {
        const std::uint32_t i =
            grid.periodic() ? (r.first_column + k) % columns : r.first_column + k;
        visit(std::size_t(j) * columns + i);
      }
  };
  std::vector<std::uint32_t> first(std::size_t(columns) * grid.rows() + 1, 0);
  for (const BucketRange& r : ranges) for_each_bucket(r, [&](std::size_t b) { ++first[b + 1]; });
  for (std::size_t b = 1; b < first.size(); ++b) first[b] += first[b - 1];
  std::vector<std::uint32_t> listed(first.back());
  std::vector<std::uint32_t> next(first.begin(), first.end() - 1);
  for (std::uint32_t p = 0; p < pieces.size(); ++p)
    for_each_bucket(ranges[p], [&](std::size_t b) { listed[next[b]++] = p; });
  words[9] = std::uint32_t(words.size());
  words.insert(words.end(), first.begin(), first.end());
  words[10] = std::uint32_t(words.size());
  words.insert(words.end(), listed.begin(), listed.end());
  // The bucket ranges and the pyramid corners start on a texel of the grid's RGBA32UI view
  // (texture_unit::grid_vec4): one fetch a range, three a piece's corners.
  const auto align_to_texel = [&] { words.resize((words.size() + 3) / 4 * 4, 0u); };
  align_to_texel();
  words[11] = std::uint32_t(words.size());
  for (const BucketRange& r : ranges) {
    words.insert(words.end(), {r.first_column, r.first_row, r.columns, r.rows});
  }
  align_to_texel();
  words[21] = std::uint32_t(words.size());
  for (const auto& corners : pieces.corners)
    for (const glm::dvec3& c : corners)
      words.insert(words.end(), {bits(c.x), bits(c.y), bits(c.z)});
  words[22] = std::uint32_t(words.size());
  words.insert(words.end(), pieces.piece_of_facet.begin(), pieces.piece_of_facet.end());
  if (grid.cell_buckets()) {
    // Pads grown by the float rounding of the breaks and of the shader's arithmetic on them.
    double largest = 0;
    for (const auto* breaks : {&grid.p_breaks(), &grid.q_breaks()})
      for (const double x : *breaks) largest = std::max(largest, std::abs(x));
    const double slack = 1e-5 + 1e-6 * largest;
    words[23] = std::uint32_t(words.size());
    words.insert(words.end(), {bits(grid.pad_p() + slack), bits(grid.pad_q() + slack)});
    for (const double x : grid.p_breaks()) words.push_back(bits(x));
    for (const double x : grid.q_breaks()) words.push_back(bits(x));
  }
  return words;
}

namespace {

// make_records (clusters false) and make_cluster_records (true).
std::vector<GpuRecord> records_of(const Scene& scene, bool clusters) {
  std::vector<GpuRecord> records;
  std::uint32_t next_id = 1;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
      const Primitive& p = scene.primitives[object.first_primitive + k];
      const std::uint32_t triangles = p.index_count / 3;
      const auto unit_normal = [&](std::uint32_t t) {
        const std::uint32_t* i = &scene.indices[p.first_index + 3 * t];
        const glm::vec3 n = glm::cross(scene.positions[i[1]] - scene.positions[i[0]],
                                       scene.positions[i[2]] - scene.positions[i[0]]);
        const float length = glm::length(n);
        return length > 0 ? n / length : glm::vec3(0.0f);
      };
      // The length of the run from triangle `first`.
      const auto run = [&](std::uint32_t first) {
        if (!clusters) return triangles - first;
        const glm::vec3 n0 = unit_normal(first);
        std::uint32_t count = 1;
        while (count < kClusterTriangles && first + count < triangles) {
          if (count >= kClusterMinTriangles && glm::dot(unit_normal(first + count), n0) < 0.5f)
            break;
          ++count;
        }
        return count;
      };
      for (std::uint32_t first = 0; first < triangles;) {
        GpuRecord record{};
        record.first_index = p.first_index + 3 * first;
        record.triangle_count = run(first);
        record.object = o;
        record.material = p.material;
        record.first_id = next_id + first;
        records.push_back(record);
        first += record.triangle_count;
      }
      next_id += triangles;
    }
  }
  return records;
}

}  // namespace

std::vector<GpuRecord> make_records(const Scene& scene) { return records_of(scene, false); }

std::vector<GpuRecord> make_cluster_records(const Scene& scene) { return records_of(scene, true); }

ClusterBounds cluster_bounds(const Scene& scene, const GpuRecord& record) {
  FACET_ASSERT(record.triangle_count <= kClusterTriangles);
  ClusterBounds bounds;
  if (record.triangle_count == 0) return bounds;
  std::array<glm::dvec3, 3 * kClusterTriangles> corners;
  std::array<glm::dvec3, kClusterTriangles> normals;
  Aabb box;
  glm::dvec3 normal_sum(0.0);
  bool every_normal = true;
  for (std::uint32_t t = 0; t < record.triangle_count; ++t) {
    glm::dvec3* p = &corners[3 * t];
    for (int c = 0; c < 3; ++c) {
      const glm::vec3& position = scene.positions[scene.indices[record.first_index + 3 * t + c]];
      box.extend(position);
      p[c] = glm::dvec3(position);
    }
    // A normal shorter than 1e-6 of its edges' squared lengths is a sliver's, which the float
    // rounding of pass 1 may turn either way: then the cluster has no cone.
    const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0], n = glm::cross(e1, e2);
    const double length = glm::length(n);
    if (length > 1e-6 * (glm::dot(e1, e1) + glm::dot(e2, e2))) {
      normals[t] = n / length;
      normal_sum += normals[t];
    } else {
      every_normal = false;
    }
  }
  bounds.centre = 0.5 * (glm::dvec3(box.p_min) + glm::dvec3(box.p_max));
  double radius2 = 0;
  for (std::uint32_t k = 0; k < 3 * record.triangle_count; ++k) {
    const glm::dvec3 d = corners[k] - bounds.centre;
    radius2 = std::max(radius2, glm::dot(d, d));
  }
  bounds.radius = std::sqrt(radius2);
  if (!every_normal || !(glm::length(normal_sum) > 0)) return bounds;
  bounds.normal_axis = glm::normalize(normal_sum);
  double min_cos = 1;
  for (std::uint32_t t = 0; t < record.triangle_count; ++t)
    min_cos = std::min(min_cos, glm::dot(normals[t], bounds.normal_axis));
  if (min_cos > 0) bounds.normal_spread_sin = std::sqrt(std::max(0.0, 1 - min_cos * min_cos));
  return bounds;
}

bool cluster_faces_away(const glm::dvec3& centre, double radius, const glm::dvec3& normal_axis,
                        double normal_spread_sin) {
  if (!(normal_spread_sin <= 1) || !(radius >= 0)) return false;
  const double distance = glm::length(centre);
  if (!(distance > radius)) return false;
  // Every corner p lies within beta of the centre's direction and every normal n within alpha of
  // the axis, so the angle between n and p is at most alpha + beta + gamma (gamma: between the
  // axis and the centre); below a right angle, dot(n, p) > 0.
  const double alpha = std::asin(normal_spread_sin);
  const double beta = std::asin(radius / distance);
  const double gamma = std::acos(std::clamp(glm::dot(normal_axis, centre) / distance, -1.0, 1.0));
  return alpha + beta + gamma < 0.5 * std::numbers::pi - kFacingAwayMargin;
}

FacetSet FacetSet::build(const Warp& warp, const FacetBuildOptions& options, double z_near,
                         bool merge_coplanar) {
  FacetMesh mesh = build_facets(warp, options);
  CoverageIndex index(mesh);
  CoverageGrid grid(mesh, warp.base, warp.R_eye_base);
  FacetPieces pieces = make_facet_pieces(mesh, merge_coplanar);
  FacetSet set{std::move(mesh),
               std::move(index),
               std::move(grid),
               std::move(pieces),
               {},
               {},
               {},
               {},
               {},
               {},
               {},
               {},
               {}};
  const std::vector<GpuFacet> gpu_facets = pack_facets(set.mesh, set.pieces, z_near);
  const auto nodes = pack_coverage_nodes(set.index);
  // Empty buffers cannot be bound; keep one dummy element so that every binding is valid.
  const GpuFacet no_facet{};
  const GpuCoverageNode no_node{};
  const std::uint32_t no_order = 0;
  set.facets = gpu_facets.empty() ? Buffer::create(sizeof no_facet, &no_facet)
                                  : Buffer::create_from(gpu_facets);
  set.facet_texels = Texture::create_buffer_view(set.facets, GL_RGBA32F, 4 * sizeof(float));
  set.nodes = nodes.empty() ? Buffer::create(sizeof no_node, &no_node) : Buffer::create_from(nodes);
  set.node_texels = Texture::create_buffer_view(set.nodes, GL_RGBA32UI, 4 * sizeof(std::uint32_t));
  set.grid_words = Buffer::create_from(pack_coverage_grid(set.grid, set.pieces));
  set.grid_texels = Texture::create_buffer_view(set.grid_words, GL_R32UI, sizeof(std::uint32_t));
  set.grid_vec4_texels =
      Texture::create_buffer_view(set.grid_words, GL_RGBA32UI, 4 * sizeof(std::uint32_t));
  set.order = set.index.order().empty() ? Buffer::create(sizeof no_order, &no_order)
                                        : Buffer::create_from(set.index.order());
  set.order_texels = Texture::create_buffer_view(set.order, GL_R32UI, sizeof(std::uint32_t));
  return set;
}

void FacetSet::bind() const {
  facet_texels.bind_unit(texture_unit::facets);
  node_texels.bind_unit(texture_unit::nodes);
  order_texels.bind_unit(texture_unit::order);
  grid_texels.bind_unit(texture_unit::grid);
  grid_vec4_texels.bind_unit(texture_unit::grid_vec4);
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

std::uint32_t sole_piece_of_sphere(const FacetSet& set, const glm::dvec3& centre, double radius) {
  const CoverageGrid& grid = set.grid;
  const FacetPieces& pieces = set.pieces;
  if (!grid.cell_buckets() || !grid.pads_under_a_cell() || !(radius >= 0) ||
      glm::length(centre) <= radius)
    return kNoPiece;
  const auto near = grid.buckets(grid.chart_point_box(centre));
  if (!near) return kNoPiece;
  // The cells within two of those about the centre. A piece listed in several cells is tested
  // again; the answer cannot change.
  const std::uint32_t columns = grid.columns(), rows = grid.rows();
  const std::uint32_t row_lo = near->first_row >= 2 ? near->first_row - 2 : 0;
  const std::uint32_t row_hi = std::min(near->first_row + near->rows + 1, rows - 1);
  if (grid.periodic() && std::int64_t(near->columns) + 4 > std::int64_t(columns)) return kNoPiece;
  std::uint32_t sole = kNoPiece;
  for (std::uint32_t j = row_lo; j <= row_hi; ++j) {
    for (std::int64_t k = -2; k < std::int64_t(near->columns) + 2; ++k) {
      std::int64_t i = std::int64_t(near->first_column) + k;
      if (grid.periodic()) {
        i = (i % std::int64_t(columns) + columns) % columns;
      } else if (i < 0 || i >= std::int64_t(columns)) {
        continue;
      }
      const std::size_t b = std::size_t(j) * columns + std::size_t(i);
      for (std::uint32_t m = grid.bucket_first()[b]; m < grid.bucket_first()[b + 1]; ++m) {
        const std::uint32_t p = pieces.piece_of_facet[grid.bucket_facets()[m]];
        if (p == sole) continue;
        // Signed distances of the centre from the piece's four planes through the eye: the
        // sphere may meet the piece unless it lies wholly outside one plane, and lies inside the
        // piece when it is inside all four.
        bool may_meet = true, inside = true;
        for (const glm::dvec3& plane : pieces.planes[p]) {
          const double length = glm::length(plane);
          if (!(length > 0)) {
            inside = false;
            continue;
          }
          const double d = glm::dot(plane, centre) / length;
          may_meet = may_meet && !(d < -radius);
          inside = inside && d >= radius * (1 + 1e-9) + 1e-12;
        }
        if (!may_meet) continue;
        if (sole != kNoPiece || !inside) return kNoPiece;  // two may meet it, or it spills over
        sole = p;
      }
    }
  }
  return sole;
}

bool sphere_may_meet_facets(const FacetSet& set, const glm::dvec3& centre, double radius) {
  const auto& nodes = set.index.nodes();
  if (nodes.empty()) return false;
  const double distance = glm::length(centre);
  if (distance <= radius) return true;  // the eye is inside: every direction
  // The sphere's cone about the eye: axis v_centre, half-angle s with sin s = radius / distance.
  const glm::dvec3 v_centre = centre / distance;
  const double sin_sphere = std::min(1.0, radius / distance);
  const double cos_sphere = std::sqrt(std::max(0.0, 1.0 - sin_sphere * sin_sphere));
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const CoverageIndex::Node& node = nodes[stack[--top]];
    if (node.cos_half_angle > -1) {
      // The cones miss when the angle between their axes exceeds the sum n + s of their
      // half-angles, i.e. when its cosine is below cos(n + s) (n + s < pi). A margin of 1e-9 in
      // the cosine keeps the test conservative against rounding.
      const double sin_sum = node.sin_half_angle * cos_sphere + node.cos_half_angle * sin_sphere;
      const double cos_sum = node.cos_half_angle * cos_sphere - node.sin_half_angle * sin_sphere;
      const bool sum_below_pi = sin_sum > 0 || cos_sum > 0;
      if (sum_below_pi && glm::dot(node.axis, v_centre) < cos_sum - 1e-9) continue;
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
