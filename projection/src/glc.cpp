#include "facet/projection/glc.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

constexpr double kPi = 3.14159265358979323846;

double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

bool finite(double x) { return std::isfinite(x); }
bool finite(glm::dvec2 v) { return finite(v.x) && finite(v.y); }
bool finite(glm::dvec3 v) { return finite(v.x) && finite(v.y) && finite(v.z); }

std::string indexed(const std::string& field, std::size_t k) {
  return field + "[" + std::to_string(k) + "]";
}

// The generators' points at frame depth z: Pk(z) = (1 - z)·stk + z·uvk.
glm::dvec2 at_depth(const GlcRay& r, double z) { return (1.0 - z) * r.st + z * r.uv; }

void check_frame(const GlcFrame& frame, const std::string& source, const std::string& field) {
  const glm::dmat3& m = frame.axes;
  if (!finite(frame.origin) || !finite(m[0]) || !finite(m[1]) || !finite(m[2])) {
    throw InputError(source, field + ".frame", "expected finite numbers");
  }
  const glm::dmat3 gram = glm::transpose(m) * m;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (std::abs(gram[i][j] - (i == j ? 1.0 : 0.0)) > 1e-9) {
        throw InputError(source, field + ".frame",
                         "expected orthonormal axes (unit length, at right angles)");
      }
    }
  }
  if (glm::determinant(m) <= 0) {
    throw InputError(source, field + ".frame", "expected a right-handed frame (x × y = z)");
  }
}

}  // namespace

std::string_view glc_type_name(GlcType type) {
  switch (type) {
    case GlcType::pinhole:
      return "pinhole";
    case GlcType::orthographic:
      return "orthographic";
    case GlcType::pushbroom:
      return "pushbroom";
    case GlcType::cross_slit:
      return "cross-slit";
    case GlcType::pencil:
      return "pencil";
    case GlcType::twisted_orthographic:
      return "twisted-orthographic";
    case GlcType::bilinear:
      return "bilinear";
  }
  return "?";
}

Glc Glc::from_generators(const GlcFrame& frame, const std::array<GlcRay, 3>& generators,
                         const std::array<glm::dvec2, 3>& image_points, const std::string& source,
                         const std::string& field) {
  check_frame(frame, source, field);
  for (std::size_t k = 0; k < 3; ++k) {
    if (!finite(generators[k].st) || !finite(generators[k].uv)) {
      throw InputError(source, indexed(field, k), "expected finite numbers");
    }
    if (!finite(image_points[k])) {
      throw InputError(source, indexed(field, k) + ".pixel", "expected finite numbers");
    }
  }
  double scale = 0;
  for (const GlcRay& r : generators) {
    scale = std::max({scale, glm::length(r.st), glm::length(r.uv)});
  }
  scale = std::max(scale, 1e-300);
  for (std::size_t j = 1; j < 3; ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const double d = std::max(glm::length(generators[j].st - generators[i].st),
                                glm::length(generators[j].uv - generators[i].uv));
      if (d <= 1e-12 * scale) {
        throw InputError(source, indexed(field, j),
                         "expected a ray other than " + indexed(field, i) + "; it is the same ray");
      }
    }
  }
  const glm::dvec2 p1 = image_points[1] - image_points[0];
  const glm::dvec2 p2 = image_points[2] - image_points[0];
  if (std::abs(cross2(p1, p2)) <= 1e-9 * glm::length(p1) * glm::length(p2) ||
      std::abs(cross2(p1, p2)) < 1e-12) {
    throw InputError(source, field,
                     "expected the generators' pixels at the corners of a triangle; they lie on "
                     "one line");
  }

  Glc glc;
  glc.frame_ = frame;
  glc.generators_ = generators;
  glc.pixel_from_ab_ =
      glm::dmat3(glm::dvec3(p1, 0.0), glm::dvec3(p2, 0.0), glm::dvec3(image_points[0], 1.0));
  glc.ab_from_pixel_ = glm::inverse(glc.pixel_from_ab_);

  // D(z) = cross(E1 + z F1, E2 + z F2).
  const glm::dvec2 e1 = generators[1].st - generators[0].st;
  const glm::dvec2 e2 = generators[2].st - generators[0].st;
  const glm::dvec2 f1 =
      (generators[1].uv - generators[1].st) - (generators[0].uv - generators[0].st);
  const glm::dvec2 f2 =
      (generators[2].uv - generators[2].st) - (generators[0].uv - generators[0].st);
  glc.a_ = cross2(f1, f2);
  glc.b_ = cross2(e1, f2) + cross2(f1, e2);
  glc.c_ = cross2(e1, e2);
  const double size =
      std::max({glm::length(e1), glm::length(e2), glm::length(f1), glm::length(f2), 1e-300});
  const double eps = 1e-12 * size * size;
  const bool a_zero = std::abs(glc.a_) <= eps;
  const bool b_zero = std::abs(glc.b_) <= eps;
  if (a_zero && b_zero && std::abs(glc.c_) <= eps) {
    throw InputError(source, field,
                     "expected generators that do not lie in one plane; these make an "
                     "epipolar-plane camera, which has no image");
  }
  // Edge-parallel: the triangle's edges keep their directions at every depth.
  auto parallel = [&](glm::dvec2 e, glm::dvec2 f) {
    return std::abs(cross2(e, f)) <= 1e-9 * glm::length(e) * glm::length(f) + eps;
  };
  const bool edge_parallel = parallel(e1, f1) && parallel(e2, f2) && parallel(e2 - e1, f2 - f1);
  if (!a_zero) {
    const double disc = glc.b_ * glc.b_ - 4 * glc.a_ * glc.c_;
    const double disc_scale = glc.b_ * glc.b_ + std::abs(4 * glc.a_ * glc.c_);
    if (std::abs(disc) <= 1e-9 * disc_scale) {
      glc.slit_depths_ = {-glc.b_ / (2 * glc.a_)};
      glc.type_ = edge_parallel ? GlcType::pinhole : GlcType::pencil;
    } else if (disc > 0) {
      // The root without cancellation, then the other from the product c / a.
      const double q = -0.5 * (glc.b_ + std::copysign(std::sqrt(disc), glc.b_));
      double r1 = q / glc.a_, r2 = glc.c_ / q;
      if (r1 > r2) std::swap(r1, r2);
      glc.slit_depths_ = {r1, r2};
      glc.type_ = GlcType::cross_slit;
    } else {
      glc.type_ = GlcType::bilinear;
    }
  } else if (!b_zero) {
    glc.slit_depths_ = {-glc.c_ / glc.b_};
    glc.type_ = GlcType::pushbroom;
  } else {
    glc.type_ = edge_parallel ? GlcType::orthographic : GlcType::twisted_orthographic;
  }
  return glc;
}

Glc Glc::from_frame_rays(const GlcFrame& frame, const std::array<EyeRay, 3>& frame_rays,
                         const std::array<glm::dvec2, 3>& image_points, const std::string& source,
                         const std::string& field) {
  std::array<GlcRay, 3> generators;
  for (std::size_t k = 0; k < 3; ++k) {
    const EyeRay& r = frame_rays[k];
    if (!finite(r.origin)) {
      throw InputError(source, indexed(field, k) + ".origin", "expected finite numbers");
    }
    if (!finite(r.direction)) {
      throw InputError(source, indexed(field, k) + ".direction", "expected finite numbers");
    }
    const double length = glm::length(r.direction);
    if (!(std::abs(r.direction.z) > 1e-9 * length)) {
      throw InputError(source, indexed(field, k) + ".direction",
                       length == 0 ? "expected a direction, not the zero vector"
                                   : "expected a direction that leaves the image plane z = 0; "
                                     "this one is parallel to it");
    }
    const glm::dvec3 d = r.direction / r.direction.z;
    const glm::dvec3 at0 = r.origin - r.origin.z * d;
    generators[k] = {glm::dvec2(at0), glm::dvec2(at0 + d)};
  }
  return from_generators(frame, generators, image_points, source, field);
}

GlcRay Glc::ray_at_ab(glm::dvec2 ab) const {
  const double w0 = 1.0 - ab.x - ab.y;
  return {w0 * generators_[0].st + ab.x * generators_[1].st + ab.y * generators_[2].st,
          w0 * generators_[0].uv + ab.x * generators_[1].uv + ab.y * generators_[2].uv};
}

EyeRay Glc::ray(glm::dvec2 pixel) const {
  const glm::dvec3 ab = ab_from_pixel_ * glm::dvec3(pixel, 1.0);
  const GlcRay r = ray_at_ab(glm::dvec2(ab));
  return {frame_.origin + frame_.axes * glm::dvec3(r.st, 0.0),
          frame_.axes * glm::dvec3(r.uv - r.st, 1.0)};
}

std::optional<GlcProjection> Glc::project(const glm::dvec3& p_eye) const {
  if (!finite(p_eye)) return std::nullopt;
  const glm::dvec3 q = glm::transpose(frame_.axes) * (p_eye - frame_.origin);
  const double z = q.z;
  const glm::dvec2 p0 = at_depth(generators_[0], z);
  const glm::dvec2 e1 = at_depth(generators_[1], z) - p0;
  const glm::dvec2 e2 = at_depth(generators_[2], z) - p0;
  const double d = cross2(e1, e2);
  const double scale = std::max(glm::dot(e1, e1), glm::dot(e2, e2));
  if (!(std::abs(d) > 1e-12 * scale) || !std::isfinite(d)) {
    return std::nullopt;
  }
  const glm::dvec2 rhs = glm::dvec2(q) - p0;
  const glm::dvec2 ab{cross2(rhs, e2) / d, cross2(e1, rhs) / d};
  return GlcProjection{glm::dvec2(pixel_from_ab_ * glm::dvec3(ab, 1.0)), z};
}

std::optional<PixelBounds> Glc::triangle_bounds(const glm::dvec3& a, const glm::dvec3& b,
                                                const glm::dvec3& c, double z_near,
                                                double pad_px) const {
  const glm::dmat3 to_frame = glm::transpose(frame_.axes);
  const std::array<glm::dvec3, 3> in = {to_frame * (a - frame_.origin),
                                        to_frame * (b - frame_.origin),
                                        to_frame * (c - frame_.origin)};
  // Clip to z >= z_near (one plane of Sutherland-Hodgman).
  // At most 4 corners: one plane cuts a triangle into a triangle or a quadrilateral.
  std::array<glm::dvec3, 4> poly{};
  std::size_t corners = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    const glm::dvec3& p = in[k];
    const glm::dvec3& q = in[(k + 1) % 3];
    const bool p_in = p.z >= z_near, q_in = q.z >= z_near;
    if (p_in) poly[corners++] = p;
    if (p_in != q_in) {
      const double t = (z_near - p.z) / (q.z - p.z);
      glm::dvec3 x = p + t * (q - p);
      x.z = z_near;
      poly[corners++] = x;
    }
  }
  if (corners == 0) return std::nullopt;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const PixelBounds unbounded{{-kInf, -kInf}, {kInf, kInf}};
  double z_min = kInf, z_max = -kInf;
  for (std::size_t k = 0; k < corners; ++k) {
    const glm::dvec3& p = poly[k];
    if (!finite(p)) return unbounded;
    z_min = std::min(z_min, p.z);
    z_max = std::max(z_max, p.z);
  }
  // A slit depth within the polygon's depths: points beside it project arbitrarily far.
  const double z_margin = 1e-9 * std::max({1.0, std::abs(z_min), std::abs(z_max)});
  for (double z : slit_depths_) {
    if (z >= z_min - z_margin && z <= z_max + z_margin) return unbounded;
  }
  PixelBounds bounds{{kInf, kInf}, {-kInf, -kInf}};
  auto add = [&](const glm::dvec3& q_frame) {
    const auto p = project(frame_.origin + frame_.axes * q_frame);
    if (!p) return false;
    bounds.min = glm::min(bounds.min, p->pixel);
    bounds.max = glm::max(bounds.max, p->pixel);
    return true;
  };
  // Per edge: pixel coordinate = N(t) / D(t), N and D quadratics in the edge parameter t, found
  // from three samples; the extremes are at the ends or where N'D - ND' = 0.
  auto denominator = [&](double z) { return (a_ * z + b_) * z + c_; };
  for (std::size_t k = 0; k < corners; ++k) {
    const glm::dvec3 p = poly[k], q = poly[(k + 1) % corners];
    if (!add(p)) return unbounded;
    const std::array<double, 3> ts = {0.0, 0.5, 1.0};
    std::array<double, 3> dv{};
    std::array<glm::dvec2, 3> nv{};
    bool ok = true;
    for (std::size_t i = 0; i < 3; ++i) {
      const glm::dvec3 x = p + ts[i] * (q - p);
      const auto proj = project(frame_.origin + frame_.axes * x);
      if (!proj) {
        ok = false;
        break;
      }
      dv[i] = denominator(x.z);
      nv[i] = proj->pixel * dv[i];
    }
    if (!ok) return unbounded;
    const double d2 = 2 * dv[2] - 4 * dv[1] + 2 * dv[0], d1 = dv[2] - dv[0] - d2, d0 = dv[0];
    for (int axis = 0; axis < 2; ++axis) {
      const double n2 = 2 * nv[2][axis] - 4 * nv[1][axis] + 2 * nv[0][axis];
      const double n1 = nv[2][axis] - nv[0][axis] - n2, n0 = nv[0][axis];
      const double qa = n2 * d1 - n1 * d2, qb = 2 * (n2 * d0 - n0 * d2), qc = n1 * d0 - n0 * d1;
      std::array<double, 2> roots{-1.0, -1.0};  // outside (0, 1): none
      const double qscale = std::max({std::abs(qa), std::abs(qb), std::abs(qc), 1e-300});
      if (std::abs(qa) > 1e-12 * qscale) {
        const double disc = qb * qb - 4 * qa * qc;
        if (disc >= 0) {
          const double s = std::sqrt(disc);
          roots = {(-qb - s) / (2 * qa), (-qb + s) / (2 * qa)};
        }
      } else if (std::abs(qb) > 1e-12 * qscale) {
        roots = {-qc / qb, -1.0};
      }
      for (double t : roots) {
        if (t > 0 && t < 1 && !add(p + t * (q - p))) return unbounded;
      }
    }
  }
  const double pad = pad_px + 1e-9 * std::max({1.0, std::abs(bounds.min.x), std::abs(bounds.min.y),
                                               std::abs(bounds.max.x), std::abs(bounds.max.y)});
  bounds.min -= pad;
  bounds.max += pad;
  return bounds;
}

std::optional<double> Glc::intersect(const EyeRay& ray, const glm::dvec3& a, const glm::dvec3& b,
                                     const glm::dvec3& c, double z_near) {
  // Möller-Trumbore; the ray parameter is the frame depth (direction has frame-z component 1).
  const glm::dvec3 e1 = b - a, e2 = c - a;
  const glm::dvec3 p = glm::cross(ray.direction, e2);
  const double det = glm::dot(e1, p);
  if (det == 0 || !std::isfinite(det)) return std::nullopt;
  const glm::dvec3 s = ray.origin - a;
  const double u = glm::dot(s, p) / det;
  if (u < 0 || u > 1) return std::nullopt;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(ray.direction, q) / det;
  if (v < 0 || u + v > 1) return std::nullopt;
  const double t = glm::dot(e2, q) / det;
  if (!(t >= z_near)) return std::nullopt;
  return t;
}

std::optional<EyeRay> PiecewiseGlc::ray(int x, int y) const { return ray_at({x + 0.5, y + 0.5}); }

std::optional<EyeRay> PiecewiseGlc::ray_at(glm::dvec2 q) const {
  if (!(q.x >= 0 && q.y >= 0 && q.x < size.x && q.y < size.y)) return std::nullopt;
  const std::size_t x = std::size_t(q.x), y = std::size_t(q.y);
  const std::int32_t piece = piece_of_pixel[y * std::size_t(size.x) + x];
  if (piece < 0) return std::nullopt;
  return pieces[std::size_t(piece)].ray(q);
}

void PiecewiseGlc::update_boxes() {
  piece_boxes.assign(pieces.size(), glm::ivec4(size.x, size.y, 0, 0));
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const std::int32_t piece = piece_of_pixel[std::size_t(y) * std::size_t(size.x) + x];
      if (piece < 0) continue;
      glm::ivec4& box = piece_boxes[std::size_t(piece)];
      box = {std::min(box.x, x), std::min(box.y, y), std::max(box.z, x + 1),
             std::max(box.w, y + 1)};
    }
  }
}

void check_glc_size(glm::ivec2 size, const std::string& source, const std::string& field) {
  if (size.x < 1 || size.y < 1 || size.x > 16384 || size.y > 16384 ||
      std::int64_t(size.x) * size.y > (std::int64_t(1) << 26)) {
    throw InputError(source, field,
                     "expected an output of 1 to 16384 pixels a side and at most 64 Mpixel; got " +
                         std::to_string(size.x) + "x" + std::to_string(size.y));
  }
}

PiecewiseGlc single_glc(const Glc& glc, glm::ivec2 size) {
  PiecewiseGlc camera;
  camera.size = size;
  camera.pieces = {glc};
  camera.piece_of_pixel.assign(std::size_t(size.x) * std::size_t(size.y), 0);
  camera.piece_boxes = {{0, 0, size.x, size.y}};
  return camera;
}

namespace {

// The image-plane point of pixel corner (x, y) (see the constructors' comment).
glm::dvec3 plane_point(glm::dvec2 pixel, glm::dvec2 plane_size, glm::ivec2 size) {
  return {(pixel.x / size.x - 0.5) * plane_size.x, (pixel.y / size.y - 0.5) * plane_size.y, 0.0};
}

void check_plane(glm::dvec2 plane_size, glm::ivec2 size, const std::string& source,
                 const std::string& field) {
  check_glc_size(size, source, field + ".size");
  if (!(plane_size.x > 0 && plane_size.y > 0 && finite(plane_size))) {
    throw InputError(source, field + ".plane_size", "expected two finite lengths > 0 (metres)");
  }
}

void check_line(const SlitLine& line, const std::string& source, const std::string& field) {
  if (!finite(line.point) || !finite(line.direction)) {
    throw InputError(source, field, "expected finite numbers");
  }
  if (!(glm::length(line.direction) > 0)) {
    throw InputError(source, field + ".direction", "expected a direction, not the zero vector");
  }
}

// A GLC over the whole image from the rays (in the frame) through three corners of the image
// plane, each given by `direction_at`(corner point) or an error naming `field`.
template <typename DirectionAt>
Glc corner_glc(const GlcFrame& frame, glm::dvec2 plane_size, glm::ivec2 size,
               const std::string& source, const std::string& field, DirectionAt direction_at) {
  const std::array<glm::dvec2, 3> pixels = {glm::dvec2(0, 0), glm::dvec2(size.x, 0),
                                            glm::dvec2(0, size.y)};
  std::array<EyeRay, 3> rays;
  for (std::size_t k = 0; k < 3; ++k) {
    const glm::dvec3 p = plane_point(pixels[k], plane_size, size);
    rays[k] = {p, direction_at(p)};
  }
  return Glc::from_frame_rays(frame, rays, pixels, source, field);
}

}  // namespace

Glc cross_slit_glc(const GlcFrame& frame, const SlitLine& slit1, const SlitLine& slit2,
                   glm::dvec2 plane_size, glm::ivec2 size, const std::string& source,
                   const std::string& field) {
  check_plane(plane_size, size, source, field);
  check_line(slit1, source, field + ".slit1");
  check_line(slit2, source, field + ".slit2");
  const glm::dvec3 d1 = glm::normalize(slit1.direction), d2 = glm::normalize(slit2.direction);
  const glm::dvec3 n = glm::cross(d1, d2);
  if (glm::length(n) < 1e-9) {
    throw InputError(source, field + ".slit2", "expected a slit not parallel to slit1");
  }
  const double gap = std::abs(glm::dot(slit2.point - slit1.point, glm::normalize(n)));
  const double scale = std::max({1.0, glm::length(slit1.point), glm::length(slit2.point)});
  if (gap < 1e-9 * scale) {
    throw InputError(source, field + ".slit2",
                     "expected a slit that does not meet slit1; they intersect");
  }
  return corner_glc(frame, plane_size, size, source, field, [&](const glm::dvec3& p) {
    const glm::dvec3 n1 = glm::cross(d1, p - slit1.point);
    const glm::dvec3 n2 = glm::cross(d2, p - slit2.point);
    if (glm::length(n1) < 1e-12 * scale) {
      throw InputError(source, field + ".slit1",
                       "expected a slit that misses the image plane's corners");
    }
    if (glm::length(n2) < 1e-12 * scale) {
      throw InputError(source, field + ".slit2",
                       "expected a slit that misses the image plane's corners");
    }
    glm::dvec3 d = glm::cross(n1, n2);
    if (d.z < 0) d = -d;
    return d;
  });
}

Glc pushbroom_glc(const GlcFrame& frame, const SlitLine& slit, const glm::dvec3& sweep_normal,
                  glm::dvec2 plane_size, glm::ivec2 size, const std::string& source,
                  const std::string& field) {
  check_plane(plane_size, size, source, field);
  check_line(slit, source, field + ".slit");
  if (!finite(sweep_normal) || !(glm::length(sweep_normal) > 0)) {
    throw InputError(source, field + ".sweep_normal", "expected a finite non-zero vector");
  }
  const glm::dvec3 d1 = glm::normalize(slit.direction), m = glm::normalize(sweep_normal);
  if (std::abs(glm::dot(d1, m)) < 1e-9) {
    throw InputError(source, field + ".sweep_normal",
                     "expected a sweep plane the slit crosses; the slit is parallel to it, so "
                     "its rays would never meet it");
  }
  return corner_glc(frame, plane_size, size, source, field, [&](const glm::dvec3& p) {
    const glm::dvec3 n1 = glm::cross(d1, p - slit.point);
    if (glm::length(n1) < 1e-12) {
      throw InputError(source, field + ".slit",
                       "expected a slit that misses the image plane's corners");
    }
    glm::dvec3 d = glm::cross(n1, m);
    if (d.z < 0) d = -d;
    return d;
  });
}

Glc pinhole_glc(const GlcFrame& frame, const glm::dvec3& centre, glm::dvec2 plane_size,
                glm::ivec2 size, const std::string& source, const std::string& field) {
  check_plane(plane_size, size, source, field);
  if (!finite(centre) || centre.z == 0) {
    throw InputError(source, field + ".centre",
                     "expected a finite point off the image plane (z != 0)");
  }
  return corner_glc(frame, plane_size, size, source, field, [&](const glm::dvec3& p) {
    const glm::dvec3 d = p - centre;
    return d.z < 0 ? -d : d;
  });
}

PiecewiseGlc circular_panorama(double angle_deg, double radius, double vertical_fov_deg, int strips,
                               glm::ivec2 size, const std::string& source,
                               const std::string& field) {
  check_glc_size(size, source, field + ".size");
  if (!(angle_deg > 0 && angle_deg <= 360)) {
    throw InputError(source, field + ".angle_deg", "expected degrees in (0, 360]");
  }
  if (!(radius > 0 && radius <= 1e6)) {
    throw InputError(source, field + ".radius", "expected metres in (0, 1e6]");
  }
  if (!(vertical_fov_deg > 0 && vertical_fov_deg < 180)) {
    throw InputError(source, field + ".vertical_fov_deg", "expected degrees in (0, 180)");
  }
  if (strips < 1 || strips > size.x || angle_deg / strips > 90) {
    throw InputError(source, field + ".strips",
                     "expected 1 to " + std::to_string(size.x) +
                         " strips (the output's width), of at most 90 degrees each");
  }
  const double angle = angle_deg * kPi / 180;
  const double half_height = radius * std::tan(vertical_fov_deg * kPi / 360);
  // The exact ray at pixel corner (x, y), in the eye frame.
  auto exact = [&](double x, double y) {
    const double phi = (x / size.x - 0.5) * angle;
    const glm::dvec3 forward{std::sin(phi), 0.0, -std::cos(phi)};
    const glm::dvec3 on_circle = -radius * forward;
    const glm::dvec3 on_axis{0.0, half_height * (1.0 - 2.0 * y / size.y), 0.0};
    return EyeRay{on_circle, on_axis - on_circle};
  };
  PiecewiseGlc camera;
  camera.size = size;
  camera.piece_of_pixel.assign(std::size_t(size.x) * std::size_t(size.y), -1);
  for (int k = 0; k < strips; ++k) {
    const int x0 = int(std::int64_t(k) * size.x / strips);
    const int x1 = int(std::int64_t(k + 1) * size.x / strips);
    const double phi_mid = ((0.5 * (x0 + x1)) / size.x - 0.5) * angle;
    GlcFrame frame;
    const glm::dvec3 z{std::sin(phi_mid), 0.0, -std::cos(phi_mid)}, y{0.0, 1.0, 0.0};
    frame.axes = glm::dmat3(glm::cross(y, z), y, z);
    const glm::dmat3 to_frame = glm::transpose(frame.axes);
    const std::array<glm::dvec2, 3> pixels = {glm::dvec2(x0, 0), glm::dvec2(x1, 0),
                                              glm::dvec2(x0, size.y)};
    std::array<EyeRay, 3> rays;
    for (std::size_t g = 0; g < 3; ++g) {
      const EyeRay r = exact(pixels[g].x, pixels[g].y);
      rays[g] = {to_frame * r.origin, to_frame * r.direction};
    }
    camera.pieces.push_back(Glc::from_frame_rays(frame, rays, pixels, source, field));
    for (int row = 0; row < size.y; ++row) {
      for (int x = x0; x < x1; ++x) {
        camera.piece_of_pixel[std::size_t(row) * std::size_t(size.x) + x] = k;
      }
    }
  }
  camera.update_boxes();
  camera.wraps_horizontally = angle_deg == 360;
  return camera;
}

PiecewiseGlc mirror_sphere(const glm::dvec3& centre, double radius, double fov_deg, int rings,
                           glm::ivec2 size, const std::string& source, const std::string& field) {
  check_glc_size(size, source, field + ".size");
  if (!finite(centre)) throw InputError(source, field + ".centre", "expected finite numbers");
  if (!(radius > 0 && radius <= 1e6)) {
    throw InputError(source, field + ".radius", "expected metres in (0, 1e6]");
  }
  if (!(-centre.z > radius)) {
    throw InputError(source, field + ".centre",
                     "expected a sphere wholly in front of the eye (centre z < -radius)");
  }
  if (!(fov_deg > 0 && fov_deg < 180)) {
    throw InputError(source, field + ".fov_deg", "expected degrees in (0, 180)");
  }
  if (rings < 2 || rings > 512) {
    throw InputError(source, field + ".rings", "expected 2 to 512 rings");
  }
  const double tan_x = std::tan(fov_deg * kPi / 360);
  const double tan_y = tan_x * size.y / size.x;
  auto pixel_of = [&](const glm::dvec3& p) {
    return glm::dvec2(size.x * (0.5 + (p.x / -p.z) / (2 * tan_x)),
                      size.y * (0.5 - (p.y / -p.z) / (2 * tan_y)));
  };
  auto vertex = [&](int i, int j) {
    const double theta = kPi * i / rings, phi = 2 * kPi * j / (2 * rings);
    return centre + radius * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                        std::sin(theta) * std::sin(phi));
  };
  PiecewiseGlc camera;
  camera.size = size;
  camera.piece_of_pixel.assign(std::size_t(size.x) * std::size_t(size.y), -1);
  auto add_triangle = [&](glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    glm::dvec3 n = glm::cross(b - a, c - a);
    if (glm::length(n) < 1e-12 * radius * radius) return;  // a pole's degenerate triangle
    n = glm::normalize(n);
    if (glm::dot(n, a - centre) < 0) {
      std::swap(b, c);
      n = -n;
    }
    if (glm::dot(n, a) >= 0) return;  // faces away from the eye
    const glm::dvec3 x_axis = glm::normalize(b - a);
    GlcFrame frame{a, glm::dmat3(x_axis, glm::cross(n, x_axis), n)};
    const glm::dmat3 to_frame = glm::transpose(frame.axes);
    const std::array<glm::dvec3, 3> v = {a, b, c};
    std::array<EyeRay, 3> rays;
    std::array<glm::dvec2, 3> pixels;
    for (std::size_t k = 0; k < 3; ++k) {
      const glm::dvec3 d = glm::normalize(v[k]);
      const glm::dvec3 normal = glm::normalize(v[k] - centre);
      const glm::dvec3 reflected = d - 2 * glm::dot(d, normal) * normal;
      rays[k] = {to_frame * (v[k] - a), to_frame * reflected};
      if (!(rays[k].direction.z > 1e-6)) return;  // grazing: leaves the triangle's plane inwards
      pixels[k] = pixel_of(v[k]);
    }
    const glm::dvec2 e1 = pixels[1] - pixels[0], e2 = pixels[2] - pixels[0];
    if (std::abs(cross2(e1, e2)) < 1e-6) return;  // seen edge-on
    const Glc glc = Glc::from_frame_rays(frame, rays, pixels, source, field);
    const auto piece = std::int32_t(camera.pieces.size());
    camera.pieces.push_back(glc);
    // The pixel centres inside the triangle of the vertices' pixels (edges included; the first
    // piece keeps a centre on a shared edge).
    const glm::dvec2 lo = glm::min(pixels[0], glm::min(pixels[1], pixels[2]));
    const glm::dvec2 hi = glm::max(pixels[0], glm::max(pixels[1], pixels[2]));
    const double area = cross2(e1, e2);
    for (int y = std::max(0, int(std::floor(lo.y))); y < std::min(size.y, int(std::ceil(hi.y)));
         ++y) {
      for (int x = std::max(0, int(std::floor(lo.x))); x < std::min(size.x, int(std::ceil(hi.x)));
           ++x) {
        const glm::dvec2 p{x + 0.5, y + 0.5};
        const double w1 = cross2(p - pixels[0], e2) / area;
        const double w2 = cross2(e1, p - pixels[0]) / area;
        if (w1 < 0 || w2 < 0 || w1 + w2 > 1) continue;
        std::int32_t& owner = camera.piece_of_pixel[std::size_t(y) * std::size_t(size.x) + x];
        if (owner < 0) owner = piece;
      }
    }
  };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < 2 * rings; ++j) {
      const glm::dvec3 p00 = vertex(i, j), p10 = vertex(i + 1, j), p11 = vertex(i + 1, j + 1),
                       p01 = vertex(i, j + 1);
      add_triangle(p00, p10, p11);
      add_triangle(p00, p11, p01);
    }
  }
  camera.update_boxes();
  return camera;
}

}  // namespace facet
