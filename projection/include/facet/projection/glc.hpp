#pragma once
// General linear cameras (GLC, Yu & McMillan 2004) and cameras made of many of them (piecewise
// GLCs, Yu, Yu & McMillan's multi-perspective rasterization): facet's cameras that have no single
// centre of projection.
//
// A GLC lives in an orthonormal frame of the eye frame (x right, y up, looking down -z, metres).
// In that frame a ray is given by two planes: (s, t) where it meets z = 0 and (u, v) where it meets
// z = 1, so it runs from (s, t, 0) along (u - s, v - t, 1). Rays are half-lines: a GLC sees the
// points with frame depth z > 0 only (the z = 0 plane is its image plane, where its rays start).
// Three generator rays r0, r1, r2 span the camera: image point (α, β) has the ray
//   r(α, β) = (1 - α - β)·r0 + α·r1 + β·r2        (componentwise in s, t, u, v),
// and output pixels map to (α, β) affinely: three image points, one per generator, are sent to
// (0, 0), (1, 0) and (0, 1). Pixel coordinates are continuous, (0, 0) the top-left corner of the
// image, pixel (i, j) centred at (i + 0.5, j + 0.5), rows counted downwards.
//
// Projection. At frame depth z the rays meet the plane in the points
//   P(α, β; z) = P0(z) + α·(P1(z) - P0(z)) + β·(P2(z) - P0(z)),  Pk(z) = (1 - z)(sk, tk) + z(uk,
//   vk),
// affine in (α, β): a point (x, y, z) projects by one 2×2 solve. Its determinant,
//   D(z) = det[P1(z) - P0(z), P2(z) - P0(z)] = A z² + B z + C,
// is the GLC characteristic equation (twice the signed area of the generators' triangle at depth
// z). Where D(z) = 0 the three rays meet one line (or point): the camera's slits. Projection is
// singular there: a point at a slit depth has no image point or a line of them, and points near
// a slit depth project far out. D ≡ 0 is the epipolar (EPI) camera, whose rays lie in one plane
// and which has no image at all; it is refused.
//
// Classification (Yu & McMillan 2004, table 1): by the number of real roots of D and whether the
// generators' triangles keep parallel edges at every depth (the edge-parallel condition):
//   A ≠ 0: two roots: cross-slit (XSlit; the two-slit camera is the same class), one double root:
//          pinhole (edge-parallel) or pencil, no real root: bilinear.
//   A = 0: one root: pushbroom; none: orthographic (edge-parallel) or twisted orthographic.
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace facet {

// A GLC ray in the two-plane parameterisation of its camera's frame.
struct GlcRay {
  glm::dvec2 st{0.0};  // on z = 0
  glm::dvec2 uv{0.0};  // on z = 1
};

// An orthonormal right-handed frame in the eye frame: frame point q is origin + axes·q.
struct GlcFrame {
  glm::dvec3 origin{0.0};
  glm::dmat3 axes{1.0};  // columns: the frame's x, y and z axes in the eye frame
};

enum class GlcType {
  pinhole,
  orthographic,
  pushbroom,
  cross_slit,
  pencil,
  twisted_orthographic,
  bilinear
};
std::string_view glc_type_name(GlcType type);  // "pinhole", "cross-slit", ...

// A ray in the eye frame: origin on the GLC's image plane, direction of frame-z component 1 (not
// unit length: the ray parameter is the frame depth).
struct EyeRay {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0};
};

// Where a point projects: its pixel, and its frame depth z (the point is seen only where z > 0).
struct GlcProjection {
  glm::dvec2 pixel{0.0};
  double depth = 0;
};

// Pixel bounds [min, max] (continuous coordinates) of what a triangle may cover.
struct PixelBounds {
  glm::dvec2 min{0.0}, max{0.0};
};

class Glc {
 public:
  // Throws InputError(source, FIELD...) naming the offending entry under `field` ("generators"
  // gives "generators[1].uv"): a non-finite number, a frame whose axes are not orthonormal and
  // right-handed, two identical generators, image points on one line, or generators that lie in
  // one plane (EPI, D ≡ 0).
  static Glc from_generators(const GlcFrame& frame, const std::array<GlcRay, 3>& generators,
                             const std::array<glm::dvec2, 3>& image_points,
                             const std::string& source, const std::string& field = "generators");

  // Generators given as frame rays (origin, direction) instead; a direction parallel to the image
  // plane (frame z component 0) cannot be written in two-plane form and is refused, naming
  // FIELD[k].direction.
  static Glc from_frame_rays(const GlcFrame& frame, const std::array<EyeRay, 3>& frame_rays,
                             const std::array<glm::dvec2, 3>& image_points,
                             const std::string& source, const std::string& field = "generators");

  const GlcFrame& frame() const { return frame_; }
  const std::array<GlcRay, 3>& generators() const { return generators_; }
  // (α, β, 1) = ab_from_pixel · (x, y, 1), and its inverse.
  const glm::dmat3& ab_from_pixel() const { return ab_from_pixel_; }
  const glm::dmat3& pixel_from_ab() const { return pixel_from_ab_; }

  GlcRay ray_at_ab(glm::dvec2 ab) const;
  EyeRay ray(glm::dvec2 pixel) const;  // in the eye frame

  // D(z) = a z² + b z + c (see the header comment), its real roots (the slit depths, ascending;
  // one for a double root) and the camera's type.
  glm::dvec3 characteristic() const { return {a_, b_, c_}; }
  const std::vector<double>& slit_depths() const { return slit_depths_; }
  GlcType type() const { return type_; }

  // The image point of p_eye and its frame depth (the point is behind the camera where depth <=
  // 0); nullopt where the 2×2 system is singular (|D(z)| at most 1e-12 of the longer edge
  // squared of the generators' triangle at depth z: on or beside a slit depth), or for non-finite
  // input.
  std::optional<GlcProjection> project(const glm::dvec3& p_eye) const;

  // A conservative bound of the pixels whose rays meet the triangle (eye frame) at frame depth >=
  // z_near, or nullopt when none can (the triangle lies wholly at depth < z_near). Exact in the
  // following sense: on each plane z = const the map from points to image points is affine, so
  // over the triangle (clipped to z >= z_near) every pixel coordinate takes its extremes on the
  // clipped polygon's edges; along an edge it is a ratio of two quadratics, whose extremes are at
  // the edge's ends or at the roots of a quadratic. Where a slit depth lies within the clipped
  // triangle's depths the image is unbounded and the bound is infinite (callers clip it to the
  // image). Pads by `pad_px` on every side.
  std::optional<PixelBounds> triangle_bounds(const glm::dvec3& a, const glm::dvec3& b,
                                             const glm::dvec3& c, double z_near,
                                             double pad_px = 0.5) const;

  // The frame-depth of the hit of `ray` (as ray() returns) with the triangle, or nullopt when it
  // misses or hits below z_near: the exact test the renderer and its oracle both make.
  static std::optional<double> intersect(const EyeRay& ray, const glm::dvec3& a,
                                         const glm::dvec3& b, const glm::dvec3& c, double z_near);

 private:
  GlcFrame frame_;
  std::array<GlcRay, 3> generators_{};
  glm::dmat3 ab_from_pixel_{1.0}, pixel_from_ab_{1.0};
  double a_ = 0, b_ = 0, c_ = 0;
  std::vector<double> slit_depths_;
  GlcType type_ = GlcType::pinhole;
};

// A camera of many GLCs, each over its own region of one output image: a strip of a panorama,
// or the image of one reflector triangle. piece_of_pixel (row-major, top row first) names the
// piece whose ray each pixel centre takes, -1 where none does (nothing is seen there).
struct PiecewiseGlc {
  glm::ivec2 size{0, 0};
  std::vector<Glc> pieces;
  // Each piece's pixel region: the bounding box of the pixels it owns, [min, max) in whole pixels.
  std::vector<glm::ivec4> piece_boxes;  // (x0, y0, x1, y1)
  std::vector<std::int32_t> piece_of_pixel;
  // The image's left and right edges meet (a 360° panorama): neighbours for ID comparisons.
  bool wraps_horizontally = false;

  // The ray of pixel (x, y)'s centre, nullopt where no piece covers it.
  std::optional<EyeRay> ray(int x, int y) const;
  // The ray through image point q (pixels, (0, 0) the top-left corner) of the piece that owns
  // q's pixel, nullopt where none does or q lies outside the image.
  std::optional<EyeRay> ray_at(glm::dvec2 q) const;
  // Recomputes piece_boxes from piece_of_pixel.
  void update_boxes();
};

// Output sizes a GLC camera may have: 1 to 16384 pixels a side, 64 Mpixel in all.
void check_glc_size(glm::ivec2 size, const std::string& source, const std::string& field);

// One GLC over the whole image: the image points of the generators are the image's top-left,
// top-right and bottom-left corners.
PiecewiseGlc single_glc(const Glc& glc, glm::ivec2 size);

// Constructors of the classic GLCs, all over a whole image of `size` pixels. The image plane is
// the plane z = 0 of `frame` (a camera-like frame: x right, y down, z forward), on which pixel
// (x, y) lies at frame point
//   ((x / w - 0.5)·plane_size.x, (y / h - 0.5)·plane_size.y, 0),
// and the generators are the camera's rays through three corners of that rectangle.
// Cross-slit: the rays through both slit lines (frame points and directions). Refused (naming
// slit1/slit2): intersecting or parallel slits, a slit through a generator's image point, or
// a generator parallel to the image plane.
struct SlitLine {
  glm::dvec3 point{0.0}, direction{0.0};  // in the frame
};
Glc cross_slit_glc(const GlcFrame& frame, const SlitLine& slit1, const SlitLine& slit2,
                   glm::dvec2 plane_size, glm::ivec2 size, const std::string& source,
                   const std::string& field);
// Pushbroom: the rays through the slit line that are parallel to the plane of normal
// `sweep_normal` (frame).
Glc pushbroom_glc(const GlcFrame& frame, const SlitLine& slit, const glm::dvec3& sweep_normal,
                  glm::dvec2 plane_size, glm::ivec2 size, const std::string& source,
                  const std::string& field);
// Pinhole: the rays through the frame point `centre` (depth < 0: behind the image plane).
Glc pinhole_glc(const GlcFrame& frame, const glm::dvec3& centre, glm::dvec2 plane_size,
                glm::ivec2 size, const std::string& source, const std::string& field);

// A circular cross-slit panorama over `angle_deg` (0, 360] about the eye frame's y axis, centred
// on -z and turning right (towards +x) as x grows. Its exact rays pass through the vertical axis
// (the eye's y axis) and a horizontal circle of `radius` around it at height 0: the ray of column
// angle φ starts on the circle behind the axis and crosses the axis at a height linear in the
// row, so that the rows span `vertical_fov_deg` at the circle point. The image is cut into
// `strips` vertical strips of equal width, each one GLC whose generators are the exact rays at
// its top-left, top-right and bottom-left pixel corners (each strip a cross-slit: one slit the
// axis, the other close to the circle's chord).
PiecewiseGlc circular_panorama(double angle_deg, double radius, double vertical_fov_deg, int strips,
                               glm::ivec2 size, const std::string& source,
                               const std::string& field);

// The reflection in a mirror sphere of `radius` centred at `centre` (eye frame), seen by a pinhole
// viewer at the eye looking down -z with a horizontal field of `fov_deg`: the sphere is
// tessellated into a latitude-longitude mesh of `rings` × 2·`rings` quads (two triangles each) and
// every triangle the viewer sees (front-facing, all three vertices' reflections leaving the
// triangle's plane outwards) is one GLC: its generators are the reflected rays at its vertices,
// its image points the vertices' pixels, its frame the triangle's plane. Pixels outside the
// sphere's image, or on triangles left out at the silhouette, see nothing. Throws when the
// eye lies inside the sphere.
PiecewiseGlc mirror_sphere(const glm::dvec3& centre, double radius, double fov_deg, int rings,
                           glm::ivec2 size, const std::string& source, const std::string& field);

}  // namespace facet
