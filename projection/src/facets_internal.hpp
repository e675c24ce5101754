#pragma once
// Internal pieces shared by the facet builder, the error evaluation and coverage.
#include <array>
#include <cstdint>
#include <limits>
#include <optional>

#include "facet/projection/facets.hpp"

namespace facet::detail {

// The facet through three vertices; Facet::vertex holds the chosen corner order as offsets 0..2
// into (a, b, c). nullopt when the chord plane passes through (or nearly through) the eye.
std::optional<Facet> make_facet(const FacetVertex& a, const FacetVertex& b, const FacetVertex& c);

// Corners of facet f scaled about their centroid on the chord plane so that each edge moves
// outwards by at most guard_px output pixels.
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
