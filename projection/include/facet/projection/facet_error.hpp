#pragma once
// How far facets are from the exact warp, in output pixels.
#include <cstddef>
#include <glm/glm.hpp>

#include "facet/projection/facets.hpp"
#include "facet/projection/warp.hpp"

namespace facet {

struct FacetErrorOptions {
  // Samples on a regular grid in st, this many per output pixel along each axis, capped so the
  // whole grid holds at most max_grid_samples; plus a barycentric lattice of this many
  // subdivisions inside every facet.
  double grid_samples_per_px = 0.5;
  std::size_t max_grid_samples = 4'000'000;
  int facet_subdivisions = 12;
};

struct FacetError {
  double max_px = 0;          // worst case over all samples, double-precision facets
  double rms_px = 0;          // RMS over the st grid (uniform in output pixels)
  double float32_max_px = 0;  // worst extra distance that float32 matrices and points add
  double float32_rms_px = 0;
  std::size_t samples = 0;
  std::size_t missed_samples = 0;  // covered directions that no facet contains (holes)
  glm::dvec2 worst_q{0.0};         // exact output pixel of the worst sample
};

// Compares, over dense samples of covered directions, the exact P with the facet containing each
// direction. The float32 figure emulates the GPU: float eye-space point, float clip matrix, float
// perspective divide, float viewport transform.
FacetError evaluate_facet_error(const Warp& warp, const FacetMesh& mesh,
                                const FacetErrorOptions& options = {});

// Largest distance between P and the facet over a barycentric lattice of `subdivisions` inside
// facet f (used by the builder).
double facet_max_error(const Warp& warp, const FacetMesh& mesh, std::uint32_t f, int subdivisions);

}  // namespace facet
