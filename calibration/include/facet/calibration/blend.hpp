#pragma once
// Blend weights (FORMATS.md §3) from fitted warps: per output pixel of every projector, a weight
// α in linear light, feathered by the angular distance to each projector's edge in the common
// direction domain and normalised so that the projectors lighting a direction sum to 1.
#include <cstddef>
#include <glm/glm.hpp>
#include <optional>
#include <span>
#include <vector>

#include "facet/projection/warp.hpp"
#include "facet/projection_io/blend_file.hpp"

namespace facet::calibration {

struct BlendOptions {
  // Angle from a projector's edge over which its raw weight rises from 0 to 1 (a smoothstep of
  // the distance, so weights have no kink where another projector's edge crosses), radians.
  double feather_rad = 0.35;
  // With a value, black-level maps are made too: every projector's black emits this fraction of
  // its white (linear light), and β lifts the black where fewer projectors overlap up to the
  // darkest black the whole display can reach (the most overlapped part).
  std::optional<double> black_level;
};

struct BlendResult {
  std::vector<projection_io::BlendMap> alpha;  // one per warp, output size, channel Y
  std::vector<projection_io::BlendMap> black;  // one per warp when black_level is set
};

// Weights for the projectors of one display. Each warp's output pixel centre is turned into an
// eye direction with WarpInverse; pixels no direction maps to get α = 0. The raw weight of
// projector k at direction v is smoothstep(d_k(v) / feather_rad): d_k is the distance in output
// pixels from k's position of v to the edges of k's covered region that another projector covers
// (each edge point raised by 4× how far short of max(10 px, 1.25 node spacings) inside the other
// projector it lies, so an edge that projector barely reaches hardly counts), lightly smoothed
// (Gaussian, σ = 3 px), times k's local angle per pixel; 0 where k's warp does not cover v
// (covered means Warp::project's `covered`, also where that reaches a fraction of a pixel past
// the image edge). Edges no other projector covers beyond (the display's outer edge) need no
// fading. α is the raw weight over the sum of raw weights, so the weights sum to 1 at every pixel
// centre. In the sums of the other projectors, k's raw weight is carried on 1.5 px past its
// covered pixel centres and fades out over the next 2.5 px, so that their α has no step where k
// ends without having faded out; there, where one projector lights alone, its α is below 1.
BlendResult compute_blend(std::span<const Warp> warps, const BlendOptions& options = {});

struct BlendCheck {
  double sum_max_err = 0;              // max |Σ α − 1| over sampled directions in overlaps
  std::size_t overlap_directions = 0;  // directions sampled where two or more projectors cover
  std::size_t worst_projector = 0;     // the sampled direction with the largest error: whose
  glm::dvec2 worst_q{0.0};             // output pixel centre it came from
  // Directions sampled where one projector lights alone, how many of them have α below
  // 1 − 0.005, and the least α among them.
  std::size_t single_directions = 0;
  std::size_t single_dim_directions = 0;
  double single_min_sum = 1;
};

// Measures the blend independently of how it was made: directions at every `stride`-th output
// pixel centre of every projector, and at each one every covering projector's α, interpolated
// bilinearly at its own position of the direction, summed. Directions that some covering
// projector places within `border_px` of the edge of its covered region (the image edge, or where
// its warp stops covering) are left out: there α meets the 0 beyond the edge between two pixels.
// Directions lit by one projector alone are counted apart, with how many have α below 0.995.
BlendCheck check_blend(std::span<const Warp> warps, std::span<const projection_io::BlendMap> alpha,
                       int stride = 3, double border_px = 1.0);

}  // namespace facet::calibration
