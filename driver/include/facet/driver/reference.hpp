#pragma once
// The accuracy oracle: a CPU ray cast (Embree 3) of the exact ray through every output pixel
// centre, writing the triangle-ID image that every RenderMethod writes too (numbering in
// render_method.hpp), and the comparison of a tested ID image against it.
//
// The exact ray of output pixel (x, y) (row 0 at the top) leaves the eye along
// v_eye = WarpInverse::invert((x + 0.5, y + 0.5)).v_eye: the direction whose exact image under the
// warp is that pixel centre. Pixels without a covered preimage get ID 0.
//
// Precision: triangles are the scene's float vertices mapped to the world frame by the float
// T_world_object in float arithmetic, as a vertex shader does; Embree intersects in float in the
// world frame (robust, watertight mode). Rays start at the eye, rounded to float, with the
// direction R_world_eye · v_eye computed in double and rounded to float. At 100 m a float
// direction is good to about 1e-5 m, far below a pixel of any display this project drives.
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "facet/driver/scene.hpp"
#include "facet/projection/glc.hpp"
#include "facet/projection/warp.hpp"
#include "facet/projection/warp_inverse.hpp"

namespace facet::driver {

struct ReferenceOptions {
  // Ignore hits on triangles seen from the back or edge-on (clockwise as seen from the eye), as
  // RenderSettings::cull_back_faces (on by default there too). Off: the nearest triangle of
  // either side.
  bool cull_back_faces = true;
  // Hits nearer than this distance from the eye (metres, along the ray) are ignored.
  double near_m = 0.0;
};

// An Embree scene of one Scene's triangles, built once and cast against from any eye and warp.
// Casting is thread-safe; ids() uses every hardware thread.
struct EdgeDisplacementOptions;
struct EdgeDisplacement;

class ReferenceRaycaster {
 public:
  explicit ReferenceRaycaster(const Scene& scene, const ReferenceOptions& options = {});
  ~ReferenceRaycaster();
  ReferenceRaycaster(ReferenceRaycaster&&) noexcept;
  ReferenceRaycaster& operator=(ReferenceRaycaster&&) noexcept;

  // Triangle ID of the nearest hit along the ray from p_world (metres) in direction v_world
  // (any length > 0), world frame; 0 where the ray hits nothing.
  std::uint32_t id_along(const glm::dvec3& p_world, const glm::dvec3& v_world) const;

  // The reference ID image of `inverse`'s warp seen from T_eye_world (maps world points into the
  // eye frame): output-sized, row 0 at the top, as OutputTarget::read_ids.
  std::vector<std::uint32_t> ids(const WarpInverse& inverse, const glm::dmat4& T_eye_world) const;

  // The reference ID image of a (piecewise) GLC camera seen from T_eye_world: pixel (x, y)
  // (row 0 at the top) casts its centre's GLC ray (PiecewiseGlc::ray: from its image plane, its
  // direction's frame-z component 1), hits at frame depth z_near or beyond; 0 where no piece
  // covers the pixel. The SCOP warp inverse does not apply to such a camera.
  std::vector<std::uint32_t> ids(const PiecewiseGlc& camera, const glm::dmat4& T_eye_world,
                                 double z_near) const;
  // Triangles in the Embree scene (every object's instance counted).
  std::size_t triangle_count() const;

  // How far the edges of a tested ID image lie from the exact geometry (see EdgeDisplacement).
  // `reference` is ids(inverse, T_eye_world); both images output-sized, row 0 at the top.
  // InputError when either image has the wrong size.
  EdgeDisplacement edge_displacement(const WarpInverse& inverse, const glm::dmat4& T_eye_world,
                                     const std::vector<std::uint32_t>& reference,
                                     const std::vector<std::uint32_t>& tested,
                                     const EdgeDisplacementOptions& options) const;
  // The same for a (piecewise) GLC camera, whose pixels have no common centre: `reference` is
  // ids(camera, T_eye_world, z_near). The camera's ray through any image point (its pixel's
  // piece) says what is seen there, so every differing pixel is measured by the lattice search
  // alone, out to window_px; a pixel drawn where no piece covers its centre is outside the
  // display. InputError when either image is not camera.size.
  EdgeDisplacement edge_displacement(const PiecewiseGlc& camera, const glm::dmat4& T_eye_world,
                                     double z_near, const std::vector<std::uint32_t>& reference,
                                     const std::vector<std::uint32_t>& tested,
                                     const EdgeDisplacementOptions& options) const;

 private:
  // The nearest hit along p_world + t·v_world (v_world as given, not normalised) for t >= t_near.
  std::uint32_t id_between(const glm::dvec3& p_world, const glm::dvec3& v_world,
                           double t_near) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One-shot convenience: builds the ray caster and the warp inverse, then casts.
std::vector<std::uint32_t> reference_ids(const Scene& scene, const Warp& warp,
                                         const glm::dmat4& T_eye_world,
                                         const ReferenceOptions& options = {});

// How far a tested ID image is from the reference (both row-major, same size, any row order as
// long as both share it).
//
// - A pixel is "near an edge" when one of its 8 neighbours in the reference has a different ID.
//   id_mismatch = mismatched_pixels / compared_pixels over the pixels NOT near an edge: the
//   fraction of pixels whose triangle is wrong where a correct renderer has no excuse.
// - For every tested pixel whose ID differs from the reference (edge pixels included), its edge
//   distance is the Euclidean distance, centre to centre in output pixels, to the nearest
//   reference pixel showing the tested ID. A perfect image has none; an edge drawn one pixel off
//   gives 1. max_edge_px is the largest, p99_edge_px the 99th percentile (nearest rank).
// - Only well-sampled triangles take part in the edge distance: a triangle that holds fewer than
//   IdCompareOptions::min_reference_pixels pixel centres in the reference (a sliver, or a small
//   or distant triangle) is hit at a few scattered centres, and the distance to the nearest of
//   them says how sparse the sampling is, not how far an edge moved: a sliver shifted by a tenth
//   of a pixel lights centres tens of pixels away from the reference's ones. Such pixels are
//   counted in sparse_id_pixels; tested IDs that appear nowhere in the reference (a triangle the
//   reference hits at no pixel centre, or a wrong ID) in absent_id_pixels. Both are left out of
//   max_edge_px and p99_edge_px but not out of id_mismatch: read the three together.
// - wrap_x: the image's left and right columns are neighbours (a 360° panorama, see
//   BaseProjection::wraps_horizontally), for the edge test and for distances.
struct IdCompareOptions {
  bool wrap_x = false;
  std::size_t min_reference_pixels = 16;
};

struct IdComparison {
  double id_mismatch = 0;
  double max_edge_px = 0;
  double p99_edge_px = 0;
  std::size_t compared_pixels = 0;    // pixels not near a reference edge
  std::size_t mismatched_pixels = 0;  // of those, the ones whose ID differs
  std::size_t differing_pixels = 0;   // every pixel whose ID differs, edges included
  std::size_t absent_id_pixels = 0;   // differing pixels whose ID is nowhere in the reference
  std::size_t sparse_id_pixels = 0;   // differing pixels whose ID has too few reference pixels
};

// Edge displacement measured against the exact geometry rather than the reference image. A pixel
// whose tested ID t differs from the reference ID r at its centre q shows an edge moved by at
// least
// - for a triangle t: the distance from q to the nearest point of the output whose exact ray
//   (WarpInverse::invert) sees t: how far t was drawn past where it is seen;
// - for t = 0 (nothing drawn): the distance from q to the nearest point that does not see r:
//   how far r, and what lies around it, was pulled back from q,
// in output pixels: that is the pixel's edge displacement. It is first computed from the
// triangle's geometry (t's triangle from outside, or r's edge from inside): a triangle's
// directions, projected gnomonically onto the tangent plane at a point's direction, are a
// straight-edged triangle there, which the warp's local linear map (from its inverse at ±1/64 px)
// takes into the output; the nearest point is found again in the map at the point found, until
// it settles to 1e-4 px, and for t a ray cast just inside it checks that t is seen there. Other
// surfaces can hide or uncover the triangle nearer than its own edges (their edges, or a line
// where two surfaces cross), so points within that distance are then searched on a lattice of
// 1/subsamples px, ring by ring, and the nearer of the two is kept; where the computation does
// not apply (t hidden at the point found, a triangle reaching 90° from a point's direction, no
// preimage) the lattice search goes out to window_px. The lattice has `subsamples` points per
// pixel out to fine_radius_px and `coarse_subsamples` beyond (a search's cost grows with the
// square of its radius); a lattice distance overstates by at most √2 lattice steps (0.044 px
// within 1 px by default) and misses regions thinner than the lattice: with 8 subsamples a
// sliver on the city put a cube-map pixel 2.4 px from its triangle, 0.19 px with 32.
// With wrap_x the output wraps round its left and right edges.
//
// Unlike compare_ids' image-based edge distance, a sliver that holds few pixel centres is
// measured where it truly lies: a diagonal between two triangles of a quad, moved by a tenth of
// a pixel, gives a tenth of a pixel here, and can give tens of pixels from the reference image.
// Pixels drawn where the display covers nothing (no direction maps to the centre: the facets'
// guard band, or the part of a facet that straddles the coverage's edge, which the blend map
// hides) are counted in outside_display with their distance to what the display covers. Pixels
// whose two triangles coincide along the pixel's ray are depth ties (either is right), and
// pixels whose displacement exceeds window_px (a wrong triangle) are counted in beyond_window;
// all three are left out of max_px and p99_px.
//
// A pixel with nothing within the window costs the whole coarse lattice, (2·window_px·
// coarse_subsamples)² ray casts: about 1.3 ms on one core here. Where more than
// max_searched_pixels pixels differ (a method off by pixels over much of the image, as the
// vertex method is over 43% of the cylinder), an evenly strided sample of max_searched_pixels of
// them is searched, and every count and figure but differing_pixels is over that sample.
struct EdgeDisplacementOptions {
  bool wrap_x = false;
  int subsamples = 32;
  double fine_radius_px = 1.0;
  int coarse_subsamples = 8;
  double window_px = 4.0;
  std::size_t max_searched_pixels = 20000;  // 0: every differing pixel
};

struct EdgeDisplacement {
  double max_px = 0;  // over the measured pixels
  double p99_px = 0;  // 99th percentile (nearest rank) of the same
  std::size_t differing_pixels = 0;
  std::size_t searched_pixels = 0;  // the differing pixels searched: all, or the strided sample
  std::size_t measured_pixels = 0;  // searched pixels with a point within window_px
  std::size_t beyond_window = 0;    // searched pixels without one
  // Differing pixels whose centre ray meets both triangles at the same distance (within 1e-5 of
  // it): coinciding surfaces, where either ID is right and depth rounding picks one. Not measured.
  std::size_t depth_ties = 0;
  // Pixels drawn where the display covers nothing (no direction maps to the centre), and the
  // largest distance from such a centre to what the display covers (window_px when farther).
  std::size_t outside_display = 0;
  double outside_display_max_px = 0;
  glm::ivec2 worst_pixel{-1, -1};  // the pixel of max_px
};

// InputError when either image is not size.x · size.y pixels.
IdComparison compare_ids(const std::vector<std::uint32_t>& reference,
                         const std::vector<std::uint32_t>& tested, glm::ivec2 size,
                         const IdCompareOptions& options = {});

}  // namespace facet::driver
