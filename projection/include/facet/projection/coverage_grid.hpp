#pragma once
// Which facets an eye-frame triangle may cover, without a hierarchy walk: a uniform bucket grid
// over a chart of the base's directions (driver/README.md, "The coverage grid"). Pass 1 on the
// GPU runs the same arithmetic in float (shaders/replication/replication_lib.comp); this is its
// reference.
//
// Chart. Directions b (base frame) are measured about the base's axis A: polar angle θ from A
// and azimuth φ about it.
//   cylindrical, equirectangular: A = +y, φ = atan2(b.x, -b.z) (the base's azimuth, periodic);
//     chart (p, q) = (φ, cot θ) or (φ, π/2 − θ): s is affine in p, t affine in q.
//   fisheye, perspective: A = −z, φ = atan2(b.y, b.x); chart (p, q) = ρ(θ)·(cos φ, sin φ) with
//     ρ = θ (fisheye: st is affine in it) or ρ = tan θ (perspective: st is affine in it).
// A spherical triangle's (θ, φ) box is exact up to padding: θ and φ have no critical point away
// from the poles, so their extremes lie at the corners, at the one interior extreme of θ along
// each great-circle arc, or at a pole inside the triangle (then φ spans everything).
//
// Buckets. For a tensor layout (strips, grids, tensor tolerance builds), st is affine in the
// chart, so the cells' breaks are lines of the chart: bucket (i, j) is cell (i, j) and lists that
// cell's facets only, and a triangle's box is grown by the furthest any facet's guarded pyramid
// reaches beyond its cell (its boundary arcs sampled in the chart, each sample grown by the
// largest step between samples). Otherwise (bisection layouts, a periodic chart's cells that do
// not go once round) buckets are uniform, about the size of the median facet box: each facet's
// guarded pyramid is itself a spherical triangle (its corners are where adjacent clip planes
// meet), so it gets a chart box by the same function and is listed in every bucket that box
// touches. A triangle's candidates are the facets of the buckets its box touches, each taken
// once: from the first bucket, in visiting order, that both boxes share. Here
// candidates are tested exactly (triangle_meets_cone), so the result equals CoverageIndex::query;
// the GPU rejects them by separating planes instead (the pyramid's three, the triangle's three),
// which keeps a few more facets and no clipping loop.
// Triangles whose box touches more than kMaxBuckets buckets or kMaxCandidates listed facets, or
// whose corners are nearly opposite seen from the eye, take the hierarchy walk instead.
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "facet/projection/base_projection.hpp"
#include "facet/projection/coverage.hpp"
#include "facet/projection/facets.hpp"

namespace facet {

// Chart kinds; the values are shared with replication_lib.comp (kChart*).
enum class CoverageChart : std::uint32_t {
  cylindrical = 0,      // (φ, cot θ) about +y, periodic in φ
  equirectangular = 1,  // (φ, π/2 − θ) about +y, periodic in φ
  fisheye = 2,          // θ·(cos φ, sin φ) about −z
  perspective = 3,      // tan θ·(cos φ, sin φ) about −z
};

// A box in (θ, φ) about the chart's axis. φ_lo <= φ_hi; full_phi: every azimuth.
struct DirectionBox {
  bool walk = false;  // the arithmetic cannot bound it well: corners nearly opposite
  double theta_lo = 0, theta_hi = 0;
  double phi_lo = 0, phi_hi = 0;
  bool full_phi = false;
};

// A box in chart coordinates (p, q); `empty` when nothing of it can be seen (a perspective
// chart's directions at 90° or more from its axis).
struct ChartBox {
  bool empty = false;
  double p_lo = 0, p_hi = 0, q_lo = 0, q_hi = 0;
  bool full_p = false;  // periodic charts: every azimuth
};

// Bucket ranges: columns first_column, ..., first_column + columns − 1 (modulo the grid's
// columns when it is periodic), rows first_row, ..., first_row + rows − 1.
struct BucketRange {
  std::uint32_t first_column = 0, first_row = 0, columns = 0, rows = 0;
};

class CoverageGrid {
 public:
  static constexpr std::uint32_t kMaxBuckets = 256;     // shared with replication_lib.comp
  static constexpr std::uint32_t kMaxCandidates = 512;  // shared with replication_lib.comp
  // gnomonic_box: the least −b.z of a corner in front, and the padding per unit of 1 + |c|².
  static constexpr double kGnomonicMinDepth = 0.05;  // shared with replication_lib.comp
  static constexpr double kGnomonicPad = 1e-5;       // shared with replication_lib.comp

  // Lists the guarded pyramids of `mesh` (the facets of a warp with base `base` and rotation
  // R_eye_base) in cell buckets or uniform ones (above).
  CoverageGrid(const FacetMesh& mesh, const BaseProjection& base, const glm::dmat3& R_eye_base,
               double guard_px = kDefaultGuardPx);

  // The facets the triangle (eye frame) may cover, sorted; equal to CoverageIndex::query of the
  // same mesh and guard. `walk` is that index, used for the triangles the grid leaves to it.
  // Returns whether the grid answered (false: the walk did).
  bool query(const std::array<glm::dvec3, 3>& triangle, const CoverageIndex& walk,
             std::vector<std::uint32_t>& facets, bool cull_back_faces = false) const;

  // The (θ, φ) box of the spherical triangle with unit corners u (base frame) about `chart`'s
  // axis, padded by `pad` radians, plus the padding the GPU's float arithmetic needs (near-pole
  // azimuths, short and long arcs), which the shader adds the same way.
  static DirectionBox direction_box(const std::array<glm::dvec3, 3>& u, CoverageChart chart,
                                    double pad);
  ChartBox chart_box(const DirectionBox& box) const;
  // A perspective chart is gnomonic, (p, q) = (b.x, b.y) / −b.z: arcs of great circles are
  // straight in it, so a triangle whose unit corners u (base frame) all have −b.z above
  // kGnomonicMinDepth has its chart box at its corners c, exact up to a padding of
  // kGnomonicPad·(1 + |c|²) for the GPU's float rounding. nullopt for other charts and triangles
  // (direction_box and chart_box take them).
  std::optional<ChartBox> gnomonic_box(const std::array<glm::dvec3, 3>& u) const;
  // nullopt when the box misses the grid.
  std::optional<BucketRange> buckets(const ChartBox& box) const;

  CoverageChart chart() const { return chart_; }
  bool periodic() const { return periodic_; }
  std::uint32_t columns() const { return columns_; }
  std::uint32_t rows() const { return rows_; }
  double p0() const { return p0_; }
  double q0() const { return q0_; }
  double dp() const { return dp_; }
  double dq() const { return dq_; }
  double radius_cap() const { return radius_cap_; }
  const glm::dmat3& R_base_eye() const { return R_base_eye_; }
  // Cell buckets: for a tensor layout, bucket (i, j) is cell (i, j) of the chart (columns and rows
  // in ascending p and q), bounded by p_breaks and q_breaks, and holds that cell's facets only; a
  // triangle's box is grown by pad_p and pad_q, the furthest any guarded pyramid reaches beyond
  // its cell, instead. Otherwise buckets are uniform, from p0, q0 in steps dp, dq.
  bool cell_buckets() const { return cells_; }
  const std::vector<double>& p_breaks() const { return p_breaks_; }
  const std::vector<double>& q_breaks() const { return q_breaks_; }
  double pad_p() const { return pad_p_; }
  double pad_q() const { return pad_q_; }
  // Cell buckets whose pads are under the narrowest cell in each direction: no guarded pyramid
  // reaches past the cells next to its own.
  bool pads_under_a_cell() const { return pads_under_a_cell_; }
  // Bucket b = row·columns + column holds bucket_facets[bucket_first[b], bucket_first[b + 1]).
  const std::vector<std::uint32_t>& bucket_first() const { return bucket_first_; }
  const std::vector<std::uint32_t>& bucket_facets() const { return bucket_facets_; }
  // Per facet: the bucket range of its guarded pyramid (for taking each candidate once).
  const std::vector<BucketRange>& facet_buckets() const { return facet_buckets_; }
  const std::vector<std::array<glm::dvec3, 3>>& planes() const { return planes_; }
  // Per facet: the unit corner directions of its guarded pyramid (eye frame), where adjacent
  // clip planes meet. A triangle's cone misses the pyramid when they all lie outside one of the
  // triangle's edge planes.
  const std::vector<std::array<glm::dvec3, 3>>& pyramid_corners() const { return corners_; }

  // The chart box of one eye-frame direction (a point; full_p never set).
  ChartBox chart_point_box(const glm::dvec3& v_eye) const;

  // Candidate facets of a triangle box, each once, in the GPU's visiting order; nullopt when the
  // box is too large for the grid (the walk takes it).
  std::optional<std::vector<std::uint32_t>> candidates(const BucketRange& range) const;

 private:
  // Cell buckets when the mesh is a tensor layout whose breaks are lines of the chart (always, up
  // to rounding: st is affine in the chart) and, for a periodic chart, go once round; sets the
  // breaks and pads and each facet's cell (row · columns + column), else returns false.
  bool fit_cells(const FacetMesh& mesh, std::vector<std::uint32_t>& cell_of_facet);

  CoverageChart chart_ = CoverageChart::perspective;
  bool periodic_ = false;
  std::uint32_t columns_ = 1, rows_ = 1;
  double p0_ = 0, q0_ = 0, dp_ = 1, dq_ = 1, radius_cap_ = 1;
  glm::dmat3 R_base_eye_{1.0};
  std::vector<std::uint32_t> bucket_first_, bucket_facets_;
  std::vector<BucketRange> facet_buckets_;
  bool cells_ = false;
  std::vector<double> p_breaks_, q_breaks_;
  double pad_p_ = 0, pad_q_ = 0;
  bool pads_under_a_cell_ = false;
  std::vector<std::array<glm::dvec3, 3>> planes_;
  std::vector<std::array<glm::dvec3, 3>> corners_;
};

// The chart of a base kind.
CoverageChart coverage_chart(BaseKind kind);

}  // namespace facet
