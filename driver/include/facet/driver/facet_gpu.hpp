#pragma once
// GPU layout of facet data, shared by the naive multi-pass baseline and both replication
// pipelines (DESIGN.md, "The replication pipeline"). Everything is built in double on the CPU
// (projection/facets.hpp, projection/coverage.hpp) and uploaded as float.
//
// Shader storage bindings used by shaders/replication/** (one table so that every program sees
// the same buffers at the same points):
//   3 indices (GpuScene)   10 counts / exclusive scan
//   11 pairs (modern: GpuReplica; seed: triangle, replica)   12 stats
//   13 material ranges of the triangle list   14 indirect draw arguments   15 scan block sums
//   16 pass 1's wide queue   17 staged facets of pass 1   18 their offsets
//   19 draw commands used per material (pass 3's glMultiDrawArraysIndirectCountARB)
//   20, 21 pass 1's walk and grid queues (16 the wide pass's): each pass's indirect dispatch,
//   then the triangles it takes
// Read-only tables are buffer textures (samplerBuffer, texelFetch): the scene
// (GpuScene::bind_for_pulling, units 8-10), and at texture_unit:: the object frames (RGBA32F, 8
// texels per GpuObjectFrame, per frame), the pieces (RGBA32F, 8 texels per GpuFacet, per output),
// the coverage hierarchy (RGBA32UI, 7 texels per GpuCoverageNode) and its order (R32UI), per
// output, the records (RGBA32UI, 2 texels per GpuRecord), the frame's triangle list (RGBA32UI, a
// texel per ListEntry, per output) and the coverage grid (R32UI, pack_coverage_grid, per output).
#include <epoxy/gl.h>

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "facet/driver/gl_objects.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/driver/scene.hpp"
#include "facet/projection/coverage.hpp"
#include "facet/projection/coverage_grid.hpp"
#include "facet/projection/facets.hpp"

namespace facet::driver {

// Read-only tables are buffer textures (texelFetch), as the scene is (gpu_scene.hpp, pulling::).
namespace texture_unit {
inline constexpr GLuint object_frames = 11, facets = 12, records = 13, list = 14, grid = 15;
// The coverage grid again, as RGBA32UI: its per-piece bucket ranges and pyramid corners, which
// pack_coverage_grid starts on a texel.
inline constexpr GLuint grid_vec4 = 19;
// The coverage hierarchy (RGBA32UI, 7 texels per GpuCoverageNode) and its facet order (R32UI).
inline constexpr GLuint nodes = 20, order = 21;
// The scatter's reads of pass 1's results (R32UI views of binding::scan, staged, stage_offsets).
inline constexpr GLuint scan = 16, staged = 17, stage_offsets = 18;
}  // namespace texture_unit

namespace binding {
inline constexpr GLuint indices = pulling::indices_binding, scan = 10, pairs = 11, stats = 12,
                        material_ranges = 13, draw_args = 14, block_sums = 15, staged = 17,
                        stage_offsets = 18, draw_counts = 19, walk_queue = 20, grid_queue = 21,
                        wide_queue = 16;
// The triangle list built on the GPU (replication/list_build.comp): the list buffer written as
// storage, the objects' eye-frame spheres and which may meet a facet, the list's indirect
// arguments, and the static record of every entry and first entry of every material.
inline constexpr GLuint list_out = 22, object_spheres = 23, object_visible = 24, list_args = 25,
                        entry_records = 26, material_first_entries = 27;
// The clusters' eye-frame spheres, and each entry's state (culled, or its sole piece or none).
inline constexpr GLuint cluster_spheres = 28, entry_states = 29;
}  // namespace binding

// What pass 3 draws: pieces. Piece f < F is facet f of the mesh (F facets); piece F + k, a quad,
// is the two facets of a tensor cell that share one projection (the same chord plane and M_q_eye
// up to rounding, as every cell of an ideal cylinder or a flat wall does) and form a convex quad. A
// triangle that crosses such a cell's diagonal is then one replica instead of two, and nothing is
// clipped along the diagonal. The coverage grid lists pieces; the hierarchy walk finds facets
// (as the CPU reference, CoverageIndex, does) and writes their pieces, a quad once per facet.
struct FacetPieces {
  std::uint32_t facet_count = 0;
  std::vector<std::uint32_t> piece_of_facet;        // the piece that draws facet f
  std::vector<std::array<std::uint32_t, 2>> quads;  // the facets of piece facet_count + k
  // Per piece: unit normals of its guarded clip planes (X is inside when planes[k]·X >= 0, the
  // facets' FacetMesh::clip_planes) and the unit corner directions of its guarded pyramid, where
  // adjacent planes meet. A triangle repeats its first plane and its first corner.
  std::vector<std::array<glm::dvec3, 4>> planes, corners;

  std::uint32_t size() const { return std::uint32_t(planes.size()); }
  // True when the piece is drawn: a quad, or a facet no quad holds.
  bool drawn(std::uint32_t piece) const {
    return piece >= facet_count || piece_of_facet[piece] == piece;
  }
  // The facet whose projection the piece uses.
  std::uint32_t facet(std::uint32_t piece) const {
    return piece < facet_count ? piece : quads[piece - facet_count][0];
  }
};
// merge_coplanar = false: one piece per facet.
FacetPieces make_facet_pieces(const FacetMesh& mesh, bool merge_coplanar,
                              double guard_px = kDefaultGuardPx);

// std430, one per piece. Eye-frame X is inside the piece's guarded pyramid when
// dot(clip_planes[k].xyz, X) >= 0 for k = 0..3; these are also its gl_ClipDistance values.
struct GpuFacet {
  float clip_from_eye[16];  // column-major Facet::clip_from_eye(output_size, z_near): GL clip
                            // coordinates with the y flip and reversed-Z depth z_near / (n·X)
  float clip_planes[4][4];  // FacetPieces::planes: unit normals, w = 0
};
static_assert(sizeof(GpuFacet) == 128);

// std430, one per node of CoverageIndex::nodes(), in the same order. A bounded node holds the
// four planes through the eye of the pyramid around its cone (as CoverageIndex::query uses them);
// an unbounded node (bounded = 0) admits everything. Leaves (count > 0) hold facets
// order[first, first + count); inner nodes have children first and first + 1.
struct GpuCoverageNode {
  float pyramid[4][4];
  float cone[4];  // bounded nodes: the unit axis, then the sine of the half-angle
  std::uint32_t first, count, bounded, padding;
  // Every facet below the node: order[range_first, range_first + range_count).
  std::uint32_t range_first, range_count, padding1, padding2;
};
static_assert(sizeof(GpuCoverageNode) == 112);

// std430: one run of triangles that share an object and a material (an object's primitive).
struct GpuRecord {
  std::uint32_t first_index;     // into Scene::indices
  std::uint32_t triangle_count;  // index_count / 3
  std::uint32_t object;          // into Scene::objects
  std::uint32_t material;        // into Scene::materials
  std::uint32_t first_id;        // triangle ID (render_method.hpp) of the run's first triangle
  std::uint32_t padding[3];
};
static_assert(sizeof(GpuRecord) == 32);

// std430: one (triangle, piece) pair of the `facets` pipeline (binding::pairs, written by
// replication/scatter.comp), with what pass 3 needs of the triangle, so that its vertices need no
// search of the triangle list.
struct GpuReplica {
  std::uint32_t first_index;  // of the triangle's first corner, into Scene::indices
  std::uint32_t piece;        // FacetPieces
  std::uint32_t object;       // into Scene::objects
  std::uint32_t id;           // triangle ID (render_method.hpp)
};
static_assert(sizeof(GpuReplica) == 16);

// std430, per object, per frame.
struct GpuObjectFrame {
  float T_eye_object[16];  // column-major, metres
  float T_world_object[16];
};
static_assert(sizeof(GpuObjectFrame) == 128);

std::vector<GpuFacet> pack_facets(const FacetMesh& mesh, const FacetPieces& pieces, double z_near);
std::vector<GpuCoverageNode> pack_coverage_nodes(const CoverageIndex& index);

// The coverage grid as one uint array, the layout replication_lib.comp reads: a header of
// kGridHeaderWords words (chart, periodic, columns, rows, then as float bits p0, q0, dp, dq,
// radius_cap, then the offsets of bucket_first, bucket_pieces and the per-piece bucket ranges,
// then R_base_eye column-major, then the offsets of the pyramid corners, of piece_of_facet and of
// the cell breaks, 0 for uniform buckets), then those arrays, the pieces' guarded pyramid corners
// (4 × 3 floats per piece; the ranges and the corners each start on a multiple of four words, a
// texel of texture_unit::grid_vec4), FacetPieces::piece_of_facet and, for cell buckets, pad_p and
// pad_q (grown by the float rounding), then p_breaks and q_breaks as floats. Buckets list pieces: a
// quad in every bucket of the smallest range holding both its facets' ranges (its guarded pyramid
// lies in the union of theirs), a facet no quad holds where the grid lists it.
inline constexpr std::uint32_t kGridHeaderWords = 24;
std::vector<std::uint32_t> pack_coverage_grid(const CoverageGrid& grid, const FacetPieces& pieces);
// Pass 1 of `facets` stages every facet it finds (binding::staged; replication/count.comp, kKept
// and kChained there), so that the scatter copies them: a triangle with at most
// kStagedChunkFacets facets as one run, one with more as a chain of chunks of kStagedChunkFacets
// facets and the offset of the next chunk. binding::stage_offsets holds each triangle's offset,
// with kStagedChained set for a chain.
inline constexpr std::uint32_t kStagedChunkFacets = 8;
inline constexpr std::uint32_t kStagedChained = 0x80000000u;
// Triangles per block of a frame list's block table (replication_lib.comp's entry_of_triangle;
// the table is made by FacetMethodBase::update_view).
inline constexpr std::uint32_t kListBlockTriangles = 64;
// Staging words that hold the facets of `pairs` pairs: one word per facet in runs, and for a chain
// of c > kStagedChunkFacets facets ceil(c / 8) chunks of 9 words, at most 2c.
constexpr std::uint64_t staged_words(std::uint64_t pairs) { return 2 * pairs + 16; }

// Records of every object's primitives, in Scene::objects order, then primitive order.
std::vector<GpuRecord> make_records(const Scene& scene);
// The same triangles in clusters, which the facet pipelines cull one by one (ClusterBounds): each
// primitive cut into runs of consecutive triangles that end at kClusterTriangles or, once they
// hold kClusterMinTriangles, before a triangle whose normal turns more than 60 degrees from the
// run's first (a mesh made wall by wall then has clusters that each face one way). The triangle
// IDs stay first_id + k.
std::vector<GpuRecord> make_cluster_records(const Scene& scene);
inline constexpr std::uint32_t kClusterTriangles = 64, kClusterMinTriangles = 8;
// The w of a cluster's sphere in the GPU list build (binding::cluster_spheres) where its own
// sphere is not tested: culled always (it faces away, or holds no triangle), or as its object.
inline constexpr float kClusterCulledAlways = -1.0f, kClusterAsObject = -2.0f;

// What culls a record as a whole, in its object's frame (metres): a sphere holding its corners,
// and the cone of its triangles' winding normals (cross(p1 - p0, p2 - p0)): a unit axis and the
// sine of the half-angle, or a sine above 1 where there is no such cone below a right angle (a
// spread of 90 degrees or more, or a triangle too thin for its normal to be trusted).
struct ClusterBounds {
  glm::dvec3 centre{0.0};
  double radius = -1;  // < 0: no triangle
  glm::dvec3 normal_axis{0.0};
  double normal_spread_sin = 2;
};
ClusterBounds cluster_bounds(const Scene& scene, const GpuRecord& record);

// True when every triangle inside the sphere (centre, radius) whose winding normal lies within
// the cone (unit axis, sine of the half-angle) faces away from the eye at the origin, by at least
// kFacingAwayMargin radians: each corner p then has dot(normal, p) > 0, so pass 1's back-face test
// culls each triangle. Frame: any with the eye at its origin.
inline constexpr double kFacingAwayMargin = 1e-4;
bool cluster_faces_away(const glm::dvec3& centre, double radius, const glm::dvec3& normal_axis,
                        double normal_spread_sin);

// The facets of one output on the CPU (double) and on the GPU (float).
struct FacetSet {
  FacetMesh mesh;
  CoverageIndex index;
  CoverageGrid grid;
  FacetPieces pieces;
  Buffer facets, nodes, order, grid_words;  // one GpuFacet per piece
  // Buffer textures: texture_unit::facets, grid, grid_vec4, nodes and order.
  Texture facet_texels, grid_texels, grid_vec4_texels, node_texels, order_texels;

  // Builds the facets of `warp` (InputError when the layout cannot be met) and their pieces, and
  // uploads them. Needs a current context.
  static FacetSet build(const Warp& warp, const FacetBuildOptions& options, double z_near,
                        bool merge_coplanar = true);
  void bind() const;
};

// The one piece whose guarded pyramid holds the sphere (eye frame, metres) while no other
// piece's may meet it, else kNoPiece: then every triangle inside the sphere covers that piece
// alone, and pass 1 takes it without the grid. Needs cell buckets (CoverageGrid) whose pads are
// under a cell: the pieces that may meet such a sphere lie within two cells of its centre's.
inline constexpr std::uint32_t kNoPiece = 0xffffffffu;
std::uint32_t sole_piece_of_sphere(const FacetSet& set, const glm::dvec3& centre, double radius);

// True when a sphere (eye frame, metres) may meet the cone {X : plane_k·X >= 0}; conservative.
bool sphere_may_meet_cone(const glm::dvec3& centre, double radius, const glm::dvec3* planes,
                          int plane_count);
// True when a sphere may meet any facet's guarded pyramid (walks the coverage hierarchy).
bool sphere_may_meet_facets(const FacetSet& set, const glm::dvec3& centre, double radius);

// Pass 1's queues (replication/count.comp): the triangles the cull pass left to the grid pass, and
// those the grid pass left to the wide pass and to the walk.
struct GpuCoverageRoutes {
  std::uint32_t grid = 0, wide = 0, walk = 0;
};
// Passes 1 and 2 of the "facets" pipeline on eye-frame triangles (metres, T_eye_world = identity),
// read back: for each triangle, the pieces (sorted; FacetPieces) it is replicated into, and, given
// `routes`, the passes that took them. For tests against CoverageIndex::query. Needs a current
// context.
std::vector<std::vector<std::uint32_t>> gpu_triangle_coverage(
    const Warp& warp, const RenderSettings& settings,
    const std::vector<std::array<glm::vec3, 3>>& triangles_eye,
    GpuCoverageRoutes* routes = nullptr);

}  // namespace facet::driver
