#pragma once
// Warps given the other way round. facet's offset maps (FORMATS.md §2) are forward maps: a grid
// over the base image says where each base position lands in the output. MPCDI geometry warps
// and Paul Bourke meshes are inverse maps: a grid over the output says which source-image
// position each output position shows. This file converts between the two.
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/projection/warp.hpp"

namespace facet::interop {

// A regular grid over the output image: node (i, j) sits at the output pixel position
// q = (i/(Gw−1)·W, j/(Gh−1)·H) (its first and last nodes on the image's outer edges, row 0 at
// the top) and holds the normalised base-image position st it shows (t downwards), or NaN where
// the output shows nothing.
struct InverseGrid {
  glm::ivec2 grid_size{0, 0};  // Gw, Gh, each >= 2
  std::vector<glm::dvec2> st;  // row-major, j·Gw + i
  // Empty, or a flag per node: false marks a node that continues the map a little past what the
  // output shows (facet's own export writes such nodes next to the coverage's edge, so that the
  // forward cells across that edge are pinned): its value is trusted, but it shows nothing.
  std::vector<bool> shown;
};

// Replaces every NaN node of a row-major grid by extrapolating from its valid neighbours, front
// by front (linearly where two valid nodes line up, else their mean), so that bilinear
// interpolation next to the edge of the valid area stays smooth. Returns the mask of nodes that
// were valid before. Throws InputError(source, "nodes", ...) when no node is valid.
std::vector<bool> fill_missing(std::vector<glm::dvec2>& values, glm::ivec2 grid_size,
                               const std::string& source);

// The forward warp of an inverse grid: a Warp with the given base, rotation and output size whose
// node (i, j) of `warp_grid` (each >= 2) maps base position st to the output position q at
// which the bilinearly interpolated inverse grid takes the value st. Base nodes that no valid
// output position shows get coverage 0 and extrapolated offsets. The inverse grid is inverted
// cell by cell in double precision (WarpInverse), so the forward warp reproduces the inverse
// grid to about 1e-9 px at its nodes. Throws InputError naming `source` when the grid has no
// valid node, a node whose value lies beyond ±1e6 (a million base images away), or the result
// folds.
Warp warp_from_inverse_grid(const InverseGrid& grid, const BaseProjection& base,
                            const glm::dmat3& R_eye_base, glm::ivec2 output_size,
                            glm::ivec2 warp_grid, const std::string& source);

// The eye direction at each node of a grid of `grid_size` nodes over the warp's output, by exact
// inversion (WarpInverse); nullopt where the warp covers nothing. With `continued_rings` > 0, a
// node the warp does not cover but that lies within that many nodes (in both directions) of one
// it covers gets the direction of the warp's map continued past its coverage, the offsets being
// defined there too, and shown = false; nullopt where even that map does not reach.
struct NodeDirections {
  std::vector<std::optional<glm::dvec3>> v_eye;  // row-major, j·Gw + i
  std::vector<bool> shown;
};
NodeDirections node_directions(const Warp& warp, glm::ivec2 grid_size, int continued_rings = 0);

// Samples a forward warp into an inverse grid of `grid_size` nodes: node_directions, each turned
// by `st_of_direction` into the position in the target image (nullopt: NaN). With
// `continued_rings` > 0 the grid's `shown` flags mark the continued nodes.
InverseGrid inverse_grid_from_warp(
    const Warp& warp, glm::ivec2 grid_size,
    const std::function<std::optional<glm::dvec2>(const glm::dvec3& v_eye)>& st_of_direction,
    int continued_rings = 0);

}  // namespace facet::interop
