#pragma once
// SCISS `.sgc` warp meshes (Uniview dome calibrations; also written by SimCAD exporters), as SGCT
// reads them. Binary, little-endian:
// - "SGC", a uint8 version (1 or 2), a uint32 mapping type (0: planar; 1: cube, not supported);
// - the view: a rotation quaternion (x, y, z, w), a position (x, y, z), then the frustum's edge
//   angles up, down, left, right in degrees, each signed as a direction (down and left are
//   negative below and left of the axis);
// - two uint32: version 1 `nx ny` (nx·ny vertices); version 2 an unused value and the vertex
//   count (a first value of 4 means a triangle list, anything else a triangle strip);
// - vertices of 6 floats `x y z tx ty tz`: (x, y) the output position in [0,1]² (x right, y
//   down: SGCT draws it at NDC (2x − 1, 1 − 2y)), (tx, ty) the position in the frustum's image
//   it shows (OpenGL texture convention, ty up); z and tz are unused;
// - a uint32 index count and that many uint32 indices.
//
// The frustum is a perspective image: in its own frame (x right, y up, looking down −z) its edges
// are the planes x = tan(left)·|z|, ..., and the quaternion turns that frame into the display's
// world frame, which for SGCT is facet's eye frame (x right, y up, −z forward). That is
// R = Ry(−heading)·Rx(pitch)·Rz(−roll) of the SGCT configs that sit next to such meshes.
//
// The mesh is drawn as triangles, so the map from output position to frustum image is piecewise
// linear over them. facet's warp is bilinear over a regular grid (FORMATS.md §2); the import
// builds that grid from whichever side of the mesh is regular (see import_sgc).
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "facet/interop/display_folder.hpp"
#include "facet/projection/base_projection.hpp"

namespace facet::interop {

struct SgcVertex {
  glm::dvec2 q_norm{0.0};  // output position / output size, x right, y down
  glm::dvec2 st{0.0};      // frustum-image position, facet's base st: (tx, 1 − ty), t down
};

struct SgcMesh {
  int version = 1;                         // of a .sgc file; 0 for a mesh read from a SimCAD file
  glm::dquat q_world_frustum{1, 0, 0, 0};  // normalised on parse
  glm::dvec3 position{0.0};                // the view's position; facet keeps it as a note
  // Signed edge angles, degrees: a direction at angle a right of (or above) the axis has
  // tangent tan(a).
  double up_deg = 0, down_deg = 0, left_deg = 0, right_deg = 0;
  std::vector<SgcVertex> vertices;
  std::vector<glm::uvec3> triangles;  // non-degenerate triangles of the strip or list
  // A SimCAD grid: its nodes are the data, bilinear between them as facet's warp is; the
  // triangles only serve the checks.
  bool bilinear_grid = false;
};

// Throws InputError(source, field, expected) for a wrong magic, version or mapping type, a
// truncated or over-long file, counts over 2^24, non-finite values or vertex coordinates beyond
// ±100, a zero quaternion, a frustum whose edges are not ordered within (−89°, 89°), or an index
// out of range.
SgcMesh parse_sgc(std::string_view bytes, const std::string& source);

// SimCAD `.simcad` warps (XML): <GeometryFile><GeometryDefinition> with <X-FlatParameters
// range="RX"> and <Y-FlatParameters range="RY">, each n² numbers, row-major over an n×n grid
// over the frustum image: node (c, r) shows st = (c, r)/(n − 1) (t down) at the output position
// (c/(n − 1) + X/RX, r/(n − 1) + Y/RY) (x right, y down, normalised). The file holds no frustum;
// it comes from the SGCT viewport that names the file (sgct_cluster.hpp). The frustum fields of
// `frustum` are copied; the result is a bilinear grid (two triangles per cell for the checks),
// which import_sgc takes node for node.
// Throws InputError naming the element for malformed XML, missing or non-positive ranges,
// counts that differ or are not a square of at least 2², and non-finite numbers.
SgcMesh parse_simcad(std::string_view xml, const SgcMesh& frustum, const std::string& source);

// A version-1 file of a grid mesh: `mesh`'s header and its vertices, row-major over `grid`
// (nx·ny of them, mesh.triangles unused), drawn as one serpentine triangle strip (rows joined by
// a repeated index), the layout of the SCISS files SGCT reads; SGCT draws every file as a strip.
// parse_sgc reads it back (floats).
std::string format_sgc(const SgcMesh& mesh, glm::ivec2 grid);

// The frustum's image as a base projection (perspective, tan_extent = tan of the edge angles).
BaseProjection sgc_frustum_base(const SgcMesh& mesh);
// Frustum-frame directions into the display's world (eye) frame.
glm::dmat3 sgc_R_eye_frustum(const SgcMesh& mesh);

// How the import read the mesh.
enum class SgcGridSide {
  texture,  // vertices on a regular grid over the frustum image: a forward warp node for node
  output,   // vertices on a regular grid over the output: an inverse grid node for node
  neither,  // an arbitrary triangulation, sampled onto an inverse grid
};

struct SgcImportOptions {
  glm::ivec2 output_size{1920, 1200};
  // 0: automatic: the mesh's node counts where one side is regular (else one node per 8 output
  // pixels), doubled (up to 1025 per side) while the mesh is followed worse than
  // `follow_bound_px` (worst over a barycentric lattice of sevenths in every triangle). A
  // bilinear grid (SimCAD) is taken node for node whatever this says.
  glm::ivec2 warp_grid{0, 0};
  double follow_bound_px = 0.25;
};

struct SgcImport {
  ImportedProjector projector;  // no blend: SGCT keeps masks apart (see sgct_cluster.hpp)
  SgcGridSide side = SgcGridSide::neither;
  // Worst distance, output px, between the imported warp and the mesh's piecewise-linear map
  // over a barycentric lattice of sevenths in every triangle (points in the frustum image).
  double worst_follow_px = 0;
};

// One projector whose warp reproduces the mesh. Throws InputError naming `source` when the mesh
// folds (a triangle turned over relative to the rest) or covers nothing.
SgcImport import_sgc(const SgcMesh& mesh, const SgcImportOptions& options,
                     const std::string& source, const std::string& name);

}  // namespace facet::interop
