#pragma once
// Projection tile screens (Trapp & Döllner): a single-centre-of-projection display authored as
// tile features E = (x, y, φ, θ, s, f) over the output, each saying which eye direction the
// output shows at (x, y). The file format is described in interop/README.md ("Tile screens").
//
// Conventions:
// - (x, y): normalised output position, x right and y down, both in [0, 1].
// - φ: azimuth about the eye's up axis (+y), degrees, 0 straight ahead (−z), positive towards +x
//   (as facet's cylindrical and equirectangular bases count azimuth); θ: polar angle from +y,
//   degrees, 0 up, 90 on the horizon, 180 down.
// - s: the feature's zoom: the angle between its direction and the view axis (−z) is divided by
//   s × the screen's global zoom, about that axis (s > 1 magnifies).
// - f: the feature's weight in the interpolation (> 0; 1 for all features is plain interpolation).
// - The direction of an output position is the normalised sum of feature directions (unit
//   vectors, zoom applied) weighted by interpolation weights times f: interpolation on the
//   sphere, so a tile across a 360° seam (φ = 170° next to −170°) takes the short way. RPTS:
//   Catmull-Rom weights of the 4×4 features around the position's tile (they interpolate the
//   features and keep the field C1 across tile edges; past the grid's edge the features are
//   continued linearly), TPTS: barycentric weights of the triangle's three (each triangle is
//   then a planar perspective map, C0 across its edges). The off-axis vector O is then added and
//   the sum normalised again.
#include <array>
#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/interop/display_folder.hpp"

namespace facet::interop {

struct TileFeature {
  double x = 0, y = 0;                 // normalised output position
  double phi_deg = 0, theta_deg = 90;  // azimuth about +y from −z, polar angle from +y
  double s = 1;                        // zoom, > 0
  double f = 1;                        // interpolation weight, > 0
};

// θ(r) = 1.411269 r − 0.094389 r³ + 0.25674 r⁵ radians from the lens axis at normalised radius r
// (the fisheye lens polynomial of Trapp & Döllner): 1.5736 rad (90.2°) at r = 1.
double fisheye_lens_theta(double r);

// A global lens from which an RPTS grid's features are sampled where the file gives none.
struct TileLens {
  enum class Kind {
    fisheye_polynomial,  // fisheye_lens_theta about the view axis −z
    mixed,               // planar centre, cylindrical sides, blended across a band
  };
  Kind kind = Kind::fisheye_polynomial;
  // fisheye_polynomial: the lens centre (normalised output position) and the radius at which
  // r = 1, as a fraction of the output's height (0.5: the inscribed circle of a landscape
  // output). Output pixels are square.
  glm::dvec2 centre{0.5, 0.5};
  double radius = 0.5;
  // mixed: with u = 2x − 1 across the output and v = (1 − 2y) H/W, the cylindrical projection
  // shows azimuth u × fov/2 and elevation tangent v × fov/2 (radians), the planar one the
  // direction (u, v, −1) scaled alike, (u × fov/2, v × fov/2, −1): the two agree to first order at
  // the centre. The planar one holds for |u| <= planar, the cylindrical one for
  // |u| >= planar + band, smoothstep-blended on the sphere between.
  double fov_deg = 180;
  double planar = 0.4;
  double band = 0.2;
};

// The eye direction (unit) the lens shows at normalised output position xy on an output of the
// given aspect (W/H).
glm::dvec3 lens_direction(const TileLens& lens, glm::dvec2 xy, double aspect);

struct TileScreen {
  std::string name;
  glm::ivec2 size{0, 0};     // the output size the screen is authored for (its aspect counts)
  double zoom = 1;           // global zoom s, > 0
  glm::dvec3 off_axis{0.0};  // O, eye frame, |O| < 1
  std::optional<TileLens> lens;
  enum class Kind { rpts, tpts };
  Kind kind = Kind::rpts;
  // rpts: Gx × Gy features, row-major (j·Gx + i), feature (i, j) at (i/(Gx−1), j/(Gy−1)).
  // tpts: the vertices.
  glm::ivec2 grid{0, 0};
  std::vector<TileFeature> features;
  std::vector<std::array<int, 3>> triangles;  // tpts: vertex indices
};

// Throws InputError(source, field, expected) for malformed JSON, unknown fields, non-finite or
// out-of-range values, grids under 2 or over 1025 nodes a side, triangle indices out of range,
// degenerate triangles, and tiles whose features lie 90° or more apart.
TileScreen parse_tile_screen(const std::string& text, const std::string& source);
TileScreen read_tile_screen(const std::filesystem::path& path);

// A feature's unit eye direction with its zoom and the screen's global zoom applied (before O).
glm::dvec3 feature_direction(const TileFeature& feature, double global_zoom);

// The continuous pieces of a screen: lists of triangle indices (tpts) whose triangles are
// joined through shared edges (both vertices the same, after merging identical vertices); an
// RPTS screen is one piece (empty list).
std::vector<std::vector<int>> tile_pieces(const TileScreen& screen);

// The eye direction of `piece` at normalised output position xy: inside its tiles, or, with
// `continue_past`, continued past its edges (RPTS: the field at the nearest edge point continued
// to first order; TPTS: the nearest triangle's weights). nullopt outside the piece (without
// continue_past).
std::optional<glm::dvec3> tile_direction(const TileScreen& screen,
                                         const std::vector<std::vector<int>>& pieces, int piece,
                                         glm::dvec2 xy, bool continue_past = false);

struct TileDisplay {
  ImportedDisplay display;
  // Per projector: the worst distance, output px, between where the warp sends the screen's
  // direction at a sample output position and that position, over a lattice of samples at
  // pixel centres inside the piece.
  std::vector<double> worst_check_px;
  std::vector<int> checked_samples;
};

// One projector per continuous piece (its name the screen's, with "_piece<k>" when there are
// more), each a warp over a base chosen to hold its directions (a fisheye about their mean
// direction where it reaches, else an equirectangular base) and, for several pieces, a blend
// map that is 1 inside the piece and 0 elsewhere. `output_size` must have the screen's aspect
// within 1%.
TileDisplay build_tile_display(const TileScreen& screen, glm::ivec2 output_size,
                               const std::string& source);

}  // namespace facet::interop
