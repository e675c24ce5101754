#pragma once
// MPCDI (VESA Multiple Projector Common Data Interchange) containers: a zip holding an XML
// description (`mpcdi.xml`; files made by other tools may name it differently, so any single
// `.xml` at the top level is accepted), one PFM geometry warp per region and optional PNG alpha
// and beta maps. interop/README.md documents every convention this code relies on; in short:
//
// - A buffer is one frame buffer; its regions are projectors, placed by normalised extents
//   (x, y, xSize, ySize in [0,1] of the buffer, origin top-left) with their own pixel resolution.
// - Profile "3d": each region has a frustum: yaw, pitch, roll and the four edge angles in degrees.
//   R_eye_frustum = Ry(−yaw)·Rx(pitch)·Rz(−roll) in facet's eye frame (x right, y up, looking
//   down −z): positive yaw turns right, positive pitch up, positive roll turns the image
//   clockwise. The frustum image is a perspective base with tan_extent
//   [tan(left), tan(right), tan(up), tan(down)].
// - Profile "2d": no frustum; warp values are normalised positions in the buffer's content image,
//   which facet models as a flat perspective base [−a, a, 1, −1] with a = buffer width / height.
// - Geometry warp (PFM, first stored row at the top): a grid over the region, node (i, j) at the
//   region's normalised position (i/(W−1), j/(H−1)). The standard ("absolute") form stores the
//   normalised source-image position (x right, y down) each node shows; NaN marks unused nodes.
//   Some tools (SGCT) store instead, on a grid over the source image, the offset (dx, dy) from
//   the node's own normalised position to its output position, with y up ("offset" form).
// - Profile "a3" (advanced 3D): the PFM holds, per node, the 3D point on the screen that the
//   node lights, in the file's frame: right-handed, x left, y up, z into the screen (towards what
//   the audience faces), in `geometricUnit`, with its origin at `originOf3DData`. The renderer
//   supplies the eye point; facet turns each point into the direction from that eye, so
//   v_eye = (−(x − ex), y − ey, −(z − ez)). NaN or exactly (0, 0, 0) marks an unused node.
// - Alpha maps may carry gammaEmbedded g: linear α = value^g. Beta maps are linear.
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "facet/interop/display_folder.hpp"
#include "facet/projection/base_projection.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::interop {

enum class MpcdiProfile { two_d, three_d, advanced_3d };
enum class MpcdiWarpValues { automatic, absolute, offset };

struct MpcdiFrustum {
  double yaw_deg = 0, pitch_deg = 0, roll_deg = 0;
  double left_deg = -45, right_deg = 45, up_deg = 45, down_deg = -45;
};

// The rotation taking frustum-frame directions into the eye frame (see the file comment).
glm::dmat3 R_eye_frustum(const MpcdiFrustum& frustum);
// The perspective base of a frustum's image.
BaseProjection frustum_base(const MpcdiFrustum& frustum);
// The frustum of a perspective base and its rotation (the inverse of the two functions above).
MpcdiFrustum frustum_from_base(const BaseProjection& perspective, const glm::dmat3& R_eye_base);
// A perspective frustum that holds everything the warp shows: the warp's own base when it is
// perspective, else one around the directions of its covered output (exact inversion). Throws
// InputError naming `source` when it covers nothing or reaches more than 80° from its centre.
MpcdiFrustum covering_frustum(const Warp& warp, const std::string& source);

struct MpcdiMap {
  std::string path;
  double gamma_embedded = 1.0;
  int components = 1;  // written as componentDepth: 1 (grey) or 3 (RGB)
};

// a3 geometry warps: the unit and origin of the 3D points (children of <geometryWarpFile>).
enum class MpcdiUnit { mm, cm, dm, m, in, ft, yd, unknown };
enum class MpcdiOrigin { center_of_mass, ideal_eye_point, floor_center, unknown };
// Metres per unit; nullopt for `unknown`.
std::optional<double> metres_per_unit(MpcdiUnit unit);
const char* to_string(MpcdiUnit unit);
const char* to_string(MpcdiOrigin origin);

// The rotation taking the a3 file's axes (x left, y up, z into the screen) into facet's eye frame
// (x right, y up, looking down −z): a half turn about y.
glm::dmat3 R_eye_mpcdi3d();

struct MpcdiRegion {
  std::string id;
  int buffer_index = 0;                   // which <buffer> holds it, in document order
  glm::ivec2 buffer_resolution{0, 0};     // that buffer's pixel size
  glm::dvec4 extent{0.0, 0.0, 1.0, 1.0};  // x, y, xSize, ySize: normalised in the buffer
  glm::ivec2 resolution{0, 0};            // the region's pixel size
  std::optional<MpcdiFrustum> frustum;    // profile 3d
  std::string warp_path;                  // PFM inside the container
  // a3 only (ignored by the other profiles): from <geometricUnit> and <originOf3DData>; a missing
  // element reads as unknown.
  MpcdiUnit unit = MpcdiUnit::unknown;
  MpcdiOrigin origin = MpcdiOrigin::unknown;
  std::optional<MpcdiMap> alpha, beta;  // PNG inside the container
};

struct MpcdiDocument {
  MpcdiProfile profile = MpcdiProfile::three_d;
  std::string version = "2.0";
  std::vector<MpcdiRegion> regions;
};

// Parses the XML. Throws InputError(source, field, expected) naming the element or attribute
// (for example "display/buffer[0]/region[1]@xSize") for malformed XML, an unknown profile,
// missing or non-numeric attributes, extents outside [0,1], a 3d region without a frustum, edge
// angles not inside (−90°, 90°) in the right order, a region without a geometry warp file, or
// (a3) a geometricUnit or originOf3DData that is not one of the standard's names. Unknown
// elements are ignored.
MpcdiDocument parse_mpcdi_xml(std::string_view xml, const std::string& source);
std::string format_mpcdi_xml(const MpcdiDocument& document);

// The container's files by name. Largest accepted member: 256 MiB.
using MpcdiFiles = std::map<std::string, std::string>;
MpcdiFiles read_zip(std::string_view bytes, const std::string& source);
MpcdiFiles read_zip_file(const std::filesystem::path& path);
// Writes a zip (deflate) atomically.
void write_zip_file(const std::filesystem::path& path, const MpcdiFiles& files);

struct MpcdiImportOptions {
  MpcdiWarpValues values = MpcdiWarpValues::automatic;
  // Node count of the imported facet warps; default: the size recorded by facet's export
  // (facet.json in the container), else the PFM's own size.
  std::optional<glm::ivec2> warp_grid;
  // a3: the eye point in the file's frame and geometricUnit; default its origin (exact when
  // originOf3DData is idealEyePoint, a guess otherwise, which the import notes).
  std::optional<glm::dvec3> eye;
};

// Builds the display of a container: one projector per region, its output a window at the
// region's pixel rectangle (buffers placed left to right). Throws InputError naming
// "<source>:<member>" and the field for every problem in the XML, PFM or PNG members.
//
// a3: each node's direction from the eye is mapped into a base projection (the one facet's export
// recorded in facet.json, else cover_directions() over the region's directions) and the result
// inverted like a 3d warp. The display's eye is the eye point in metres (facet's axes; an unknown
// unit reads as metres). Regions whose points lie within 1e−9 of the eye everywhere throw.
ImportedDisplay import_mpcdi(const MpcdiFiles& files, const std::string& source,
                             const MpcdiImportOptions& options = {});

struct MpcdiExportOptions {
  // Spacing of the exported PFM nodes in output pixels (the grid spans the region edge to edge).
  double node_spacing_px = 4.0;
  // three_d (default) or advanced_3d; two_d is not written.
  MpcdiProfile profile = MpcdiProfile::three_d;
};

// The container of a display, profile 3d, one buffer per projector: each region's frustum is
// the warp's perspective base (or, for other bases, a perspective frustum that covers what the
// projector shows); its PFM holds the standard absolute form, computed by exact inversion of the
// warp at each node; blend and black maps become 16-bit PNG alpha and beta maps. Throws
// InputError when a warp cannot be read or its footprint is too wide for one frustum.
//
// Profile a3: each region's PFM holds, per node, the point where the node's eye direction meets
// the display's screen (display.json `screen`, seen from its eye), else the point on the unit
// sphere around the eye; relative to the eye (originOf3DData idealEyePoint), in metres, in the
// file's axes. Nodes the warp does not cover, or whose ray misses the screen, are NaN. No
// frustum is written; any base (fisheye, cylindrical, ...) goes through as it is, and facet.json
// records it so that facet's import reproduces the warp on its own base and grid.
MpcdiFiles export_mpcdi(const projection_io::DisplayConfig& display,
                        const MpcdiExportOptions& options = {});

}  // namespace facet::interop
