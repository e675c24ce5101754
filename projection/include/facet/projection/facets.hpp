#pragma once
// Facets: continuous piecewise perspective projections (DESIGN.md, "Facets").
//
// A facet is a triangle of three corner points p_i on the base's natural surface (eye frame,
// metres at unit distance). Its projection maps an eye-frame point X onto the chord plane through
// the p_i (unit normal n, n·p_i = h > 0) along X's ray, then by the affine map that sends each p_i
// to its exact output pixel q_i. As one homogeneous matrix:  (q·w, w) = M_q_eye · X  with
// w = n·X. Neighbours share corners, so shared edges map identically: no cracks, no T-junctions.
#include <array>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "facet/projection/errors.hpp"
#include "facet/projection/warp.hpp"

namespace facet {

// Every facet reaches this far (output pixels) past each of its edges, so that no pixel on a seam
// is lost to rounding; DESIGN.md allows at most 0.05 px.
inline constexpr double kDefaultGuardPx = 0.03;

struct FacetVertex {
  glm::dvec3 p_eye;  // corner on the base's natural surface, eye frame
  glm::dvec2 st;     // base-image coordinates
  glm::dvec2 q;      // exact output pixel P(p_eye)
};

struct Facet {
  std::array<std::uint32_t, 3> vertex{};  // into FacetMesh::vertices, counter-clockwise in q
  glm::dmat3 M_q_eye{1.0};                // (q·w, w) = M_q_eye · X, w = n·X
  glm::dvec3 n{0.0};                      // unit chord-plane normal, n·p_i = h > 0
  double h = 0.0;
  // Inward unit normals of the planes through the eye and edges (p0,p1), (p1,p2), (p2,p0):
  // X lies in the facet's pyramid when edge_normal[k]·X >= 0 for every k.
  std::array<glm::dvec3, 3> edge_normal{};

  // Output pixel of an eye-frame point with n·X > 0.
  glm::dvec2 project(glm::dvec3 X) const;
  // Eye → clip for OpenGL with glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) and reversed-Z:
  // x_ndc = 2qx/W − 1, y_ndc = 1 − 2qy/H, depth = z_near / (n·X) (1 at n·X = z_near, → 0 far).
  glm::dmat4 clip_from_eye(glm::ivec2 output_size, double z_near) const;
};

// A tolerance build that kept facets whose worst error exceeds the tolerance by at most
// FacetBuildOptions::near_miss (see build_facets).
struct FacetToleranceMiss {
  double tolerance_px = 0;  // the tolerance asked for
  double max_px = 0;        // the worst error of the facets kept (evaluate_facet_error)
  glm::dvec2 worst_q{0.0};  // the output pixel where it is reached
};

struct FacetMesh {
  glm::ivec2 output_size{0, 0};
  // Set when a tolerance build kept facets that miss the tolerance by a near miss.
  std::optional<FacetToleranceMiss> tolerance_miss;
  std::vector<FacetVertex> vertices;
  std::vector<Facet> facets;
  // The tensor-product layout the facets came from (empty for any other layout): cell (c, r) spans
  // [s_breaks[c], s_breaks[c+1]] × [t_breaks[r], t_breaks[r+1]] and holds facets 2·(r·C + c) and
  // 2·(r·C + c) + 1, where C = s_breaks.size() − 1. Cells outside the coverage hold none and
  // cell_first_facet marks them with UINT32_MAX.
  std::vector<double> s_breaks, t_breaks;
  std::vector<std::uint32_t> cell_first_facet;

  // Guarded clip planes of facet f for gl_ClipDistance: the edge planes of the facet's corners
  // scaled about its incentre on the chord plane so that every edge moves outwards by exactly
  // guard_px output pixels (the facet's projection is affine on its chord plane, so the move is
  // the same all along each edge). X is inside when plane[k]·X >= 0.
  std::array<glm::dvec3, 3> clip_planes(std::uint32_t f, double guard_px = kDefaultGuardPx) const;
  // The three corner points of facet f.
  std::array<glm::dvec3, 3> corners(std::uint32_t f) const;
};

struct FacetStrips {  // N vertical strips over the whole base image, one row (the seed's cylinder)
  int count = 0;
};
struct FacetGrid {  // a uniform Gx × Gy grid of cells, two facets per cell (the seed's textures)
  int columns = 0, rows = 0;
};
struct FacetTolerance {  // as few facets as the builder can find with max error <= px
  double px = 0.25;
  enum class Builder {
    fewest,     // both below, keeping the one with fewer facets
    tensor,     // a tensor-product grid whose rows and columns are spaced to fit
    bisection,  // newest-vertex bisection, refined only where the warp needs it
  };
  Builder builder = Builder::fewest;
};
using FacetLayout = std::variant<FacetStrips, FacetGrid, FacetTolerance>;

// The near miss a running show accepts (facet run, facet render): facets whose worst error is at
// most 10% above the tolerance render with a warning instead of stopping the show.
inline constexpr double kRunNearMiss = 0.10;

// Where a tolerance was set and what the facets are for, so that the errors and warnings of a
// tolerance build name them: InputError(source, field, ...) and "<source>: field '<field>': ...".
struct FacetToleranceOrigin {
  std::string source;              // a display.json's path, "command line"; empty: "input"
  InputField field = "tolerance";  // "render.tolerance_px", OptionName{"tolerance_px"}
  std::string output;              // the projector the facets are for; empty: not named
};

struct FacetBuildOptions {
  FacetLayout layout = FacetTolerance{};
  // Upper bound on cells a tolerance build may use before it gives up with InputError.
  int max_cells = 1 << 20;
  // A tolerance build whose best try still misses the tolerance is kept when its worst error is
  // at most (1 + near_miss) × the tolerance: FacetMesh::tolerance_miss records it and `warn`, when
  // set, gets one line naming origin's field and the figure reached. Beyond it, or at 0 (the
  // default), the build throws InputError.
  double near_miss = 0;
  FacetToleranceOrigin origin{};
  std::function<void(const std::string& line)> warn{};
};

// Builds facets over the covered part of the warp. A tolerance layout is checked as a whole with
// evaluate_facet_error before it is returned: its max_px is at most the tolerance, or at most
// (1 + near_miss) × the tolerance with tolerance_miss set. Throws InputError for a layout that
// cannot be met (a facet spanning 180° or more, a tolerance that needs more than max_cells, or one
// the builder misses three times by more than near_miss, naming the worst pixel and the tolerance
// that would be met); the errors of a tolerance layout name options.origin's source and field.
FacetMesh build_facets(const Warp& warp, const FacetBuildOptions& options);

}  // namespace facet
