#pragma once
// Paul Bourke warp meshes (`.data`), as used for spherical-mirror and dome projection.
//
// Line 1: the mesh type (2: rectangular). Line 2: "nx ny". Then nx·ny lines "x y u v i", x
// varying fastest, rows from the bottom of the output image to its top:
// - (x, y): the node's output position, x in [−aspect, aspect] left to right, y in [−1, 1]
//   bottom to top, on a regular grid;
// - (u, v): the source-image position the node shows, in [0,1], v upwards (OpenGL texture
//   convention); a negative u or v marks a node that shows nothing;
// - i: an intensity multiplier in [0,1], applied to the encoded output value.
//
// facet reads this as an inverse map (interop/inverse_grid.hpp) over a base projection chosen for
// the source image: for a dome or a spherical mirror, a fisheye master whose image is the (u, v)
// square (st = (u, 1 − v)). By default the master lies on the dome as a dome master does: its
// centre overhead (eye +y), its bottom edge to the front (−z), its right edge +x
// (R_dome_fisheye(FisheyeZenith::centre), dome_orientation.hpp).
#include <glm/glm.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "facet/interop/display_folder.hpp"
#include "facet/projection/base_projection.hpp"
#include "facet/projection/dome_orientation.hpp"

namespace facet::interop {

struct BourkeNode {
  double x = 0, y = 0, u = 0, v = 0, intensity = 1;
};

struct BourkeMesh {
  int mesh_type = 2;
  glm::ivec2 grid_size{0, 0};     // nx, ny
  std::vector<BourkeNode> nodes;  // file order: x fastest, bottom row first
  double aspect = 1;              // the largest |x|
};

// Throws InputError(source, "line N", expected) for a bad header, a wrong node count, a node
// with too few or non-numeric columns, non-finite values, nodes off the regular grid, or more
// than 4096 nodes on a side.
BourkeMesh parse_bourke(std::string_view text, const std::string& source);

struct BourkeImportOptions {
  glm::ivec2 output_size{1920, 1080};  // must match the mesh's aspect within 1%
  BaseProjection base = BaseProjection::fisheye(180);
  // The master's base frame into the eye frame: the default puts its centre overhead; identity
  // puts it straight ahead (FisheyeZenith::front).
  glm::dmat3 R_eye_base = R_dome_fisheye(FisheyeZenith::centre);
  // 0: automatic: the mesh's own node counts, doubled (up to 1025 per side) while an interior mesh
  // node is reproduced worse than 1 px.
  glm::ivec2 warp_grid{0, 0};
  // The intensity multiplies encoded values; linear α = intensity^gamma.
  double intensity_gamma = 2.2;
};

// Nodes that fold the mesh: mesh cells (all four nodes used) whose source quadrilateral turns over
// or collapses show the same source positions as their neighbours, so no forward warp holds them.
// Node by node, the one of a folded cell that strays furthest from the straight continuation of
// its neighbours is taken as unused, until no cell folds. Returns the nodes taken, in file
// numbering (i from the left, j from the bottom row).
std::vector<glm::ivec2> unfold_bourke(BourkeMesh& mesh);

// One projector: the warp and the blend map (linear α from the intensity column, bilinear between
// nodes, 0 where the mesh shows nothing). Folding nodes are masked first (unfold_bourke); the
// projector's notes say which, and where they are in the output.
ImportedProjector import_bourke(const BourkeMesh& mesh, const BourkeImportOptions& options,
                                const std::string& source, const std::string& name);

}  // namespace facet::interop
