#pragma once
// Internal pieces shared by the facet builder, the error evaluation and coverage.
#include <array>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "facet/projection/facets.hpp"

namespace facet::detail {

inline constexpr double kPi = std::numbers::pi;
// Largest angle between two corners of a facet or cell, well short of the 180° at which a chord
// plane passes through the eye and the facet's matrix degenerates.
inline constexpr double kMaxFacetAngle = 150.0 * kPi / 180.0;
// The builders aim below the requested tolerance because the final evaluation samples more
// densely than they do.
inline constexpr double kBuildMargin = 0.97;
inline constexpr int kBuildSubdivisions = 10;

// The facet vertex at base position st: its surface point and exact output pixel.
FacetVertex vertex_at(const Warp& warp, glm::dvec2 st);
// Radians between two directions, accurate at every angle.
double angle_between(glm::dvec3 a, glm::dvec3 b);
// The node lines of an axis with `nodes` nodes that lie in [a, b], appended to `values`.
void append_node_lines(double a, double b, int nodes, std::vector<double>& values);
// Largest coverage inside the st rectangle. Coverage is bilinear between nodes, so its maximum
// over a rectangle lies on a node line crossing or a rectangle corner.
double max_coverage(const Warp& warp, double s0, double s1, double t0, double t1);

// The tolerance layout by newest-vertex bisection (facets_adaptive.cpp): a conforming triangle
// mesh refined only where the warp needs it, every covered facet within `target_px` on the
// builder's own samples. Throws InputError past max_cells facets.
FacetMesh build_adaptive_layout(const Warp& warp, double target_px, int max_cells);

// The facet through three vertices; Facet::vertex holds the chosen corner order as offsets 0..2
// into (a, b, c). nullopt when the chord plane passes through (or nearly through) the eye.
std::optional<Facet> make_facet(const FacetVertex& a, const FacetVertex& b, const FacetVertex& c);

// Corners of facet f scaled about their incentre on the chord plane so that every edge moves
// outwards by exactly guard_px output pixels.
std::array<glm::dvec3, 3> guarded_corners(const FacetMesh& mesh, std::uint32_t f, double guard_px);

// Output-pixel distance between the facet and the exact warp, with s wrapped for 360° bases.
double pixel_distance(const Warp& warp, glm::dvec2 q_facet, glm::dvec2 q_exact);

// How far inside the facet's pyramid direction d lies: the smallest of its edge-plane distances
// (about radians when small); negative outside.
double inside_margin(const Facet& facet, glm::dvec3 d);

// Largest pixel distance over a barycentric lattice of `subdivisions` on the chord triangle p,
// counting covered directions only; it returns early once the distance exceeds stop_above.
double lattice_error(const Warp& warp, const Facet& facet, const std::array<glm::dvec3, 3>& p,
                     double s_hint, int subdivisions,
                     double stop_above = std::numeric_limits<double>::infinity());

}  // namespace facet::detail
