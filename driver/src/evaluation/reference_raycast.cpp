#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>

#include "facet/driver/reference.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

// Rows handed out one at a time to every hardware thread: rows cost very different amounts
// (sky against dense city), so a shared counter balances better than a static split.
template <typename Body>
void for_each_row(int rows, Body&& body) {
  const int threads =
      std::max(1, std::min<int>(int(std::thread::hardware_concurrency()), std::max(rows, 1)));
  std::atomic<int> next{0};
  std::vector<std::exception_ptr> failures(threads);
  auto work = [&](int worker) {
    try {
      for (int row = next++; row < rows; row = next++) body(row);
    } catch (...) {
      failures[worker] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int worker = 1; worker < threads; ++worker) pool.emplace_back(work, worker);
  work(0);
  for (auto& thread : pool) thread.join();
  for (auto& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

// The pixels where `tested` differs from `reference` (both size.x · size.y, row-major), after
// the checks every edge displacement makes of its input.
std::vector<glm::ivec2> differing_pixels(glm::ivec2 size,
                                         const std::vector<std::uint32_t>& reference,
                                         const std::vector<std::uint32_t>& tested,
                                         const EdgeDisplacementOptions& options) {
  const std::size_t pixels = std::size_t(size.x) * std::size_t(size.y);
  for (const auto* image : {&reference, &tested}) {
    if (image->size() != pixels) {
      throw InputError(image == &reference ? "reference ID image" : "tested ID image", "size",
                       "expected " + std::to_string(size.x) + "×" + std::to_string(size.y) +
                           " pixels, got " + std::to_string(image->size()));
    }
  }
  if (options.subsamples < 1 || options.coarse_subsamples < 1 || !(options.window_px > 0)) {
    throw InputError("edge displacement", "options",
                     "expected subsamples and coarse_subsamples >= 1 and window_px > 0");
  }
  std::vector<glm::ivec2> differing;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const std::size_t i = std::size_t(y) * size.x + x;
      if (tested[i] != reference[i]) differing.push_back({x, y});
    }
  }
  return differing;
}

// At most `limit` of `differing` (0: all), evenly strided over the row-major order.
std::vector<glm::ivec2> searched_sample(const std::vector<glm::ivec2>& differing,
                                        std::size_t limit) {
  if (limit == 0 || differing.size() <= limit) return differing;
  std::vector<glm::ivec2> sample(limit);
  for (std::size_t k = 0; k < limit; ++k) sample[k] = differing[k * differing.size() / limit];
  return sample;
}

// The distance from `centre` to the nearest point of a lattice of 1/subsamples px where
// `marks_the_edge` holds, searched ring by ring out to radius_px; nullopt when none is that near.
// Every lattice point on Chebyshev ring r is at least r steps away, so a search ends once r²
// passes the best squared distance found.
template <typename Marks>
std::optional<double> lattice_distance(glm::dvec2 centre, int subsamples, double radius_px,
                                       Marks&& marks_the_edge) {
  const double lattice_step = 1.0 / subsamples;
  const int rings = int(std::ceil(radius_px * subsamples));
  long best = std::numeric_limits<long>::max();
  for (int r = 1; r <= rings && long(r) * r <= best; ++r) {
    for (int dy = -r; dy <= r; ++dy) {
      const int stride = (dy == -r || dy == r) ? 1 : 2 * r;
      for (int dx = -r; dx <= r; dx += stride) {
        const long d2 = long(dx) * dx + long(dy) * dy;
        if (d2 >= best || d2 > long(rings) * rings) continue;
        if (marks_the_edge(centre + lattice_step * glm::dvec2(dx, dy))) best = d2;
      }
    }
  }
  if (best > long(rings) * rings) return std::nullopt;
  return lattice_step * std::sqrt(double(best));
}

// A differing pixel's edge displacement: the lattice search (options.subsamples out to
// fine_radius_px, coarse_subsamples beyond) for a point nearer than `limit_px`, a distance known
// to bound it from above (window_px when none is known). Negative: nothing within the window.
template <typename Marks>
double searched_distance(glm::dvec2 centre, double limit_px, const EdgeDisplacementOptions& options,
                         Marks&& marks_the_edge) {
  auto found = lattice_distance(centre, options.subsamples,
                                std::min(limit_px, options.fine_radius_px), marks_the_edge);
  if (!found && limit_px > options.fine_radius_px) {
    found = lattice_distance(centre, options.coarse_subsamples, limit_px, marks_the_edge);
  }
  if (found) return std::min(limit_px, *found);
  return limit_px < options.window_px ? limit_px : -1.0;
}

// The summary of the differing pixels' distances (negative: none within the window; NaN: a depth
// tie), those drawn outside the display (`outside`) kept apart.
EdgeDisplacement summarize_edges(std::size_t differing_pixels,
                                 const std::vector<glm::ivec2>& differing,
                                 const std::vector<double>& distance,
                                 const std::vector<char>& outside,
                                 const EdgeDisplacementOptions& options) {
  EdgeDisplacement result;
  result.differing_pixels = differing_pixels;
  result.searched_pixels = differing.size();
  std::vector<double> measured;
  for (std::size_t k = 0; k < distance.size(); ++k) {
    const double d = distance[k];
    if (std::isnan(d)) {
      ++result.depth_ties;
    } else if (outside[k]) {
      ++result.outside_display;
      result.outside_display_max_px =
          std::max(result.outside_display_max_px, d < 0 ? options.window_px : d);
    } else if (d < 0) {
      ++result.beyond_window;
    } else {
      measured.push_back(d);
      if (d > result.max_px || result.worst_pixel.x < 0) {
        result.max_px = d;
        result.worst_pixel = differing[k];
      }
    }
  }
  result.measured_pixels = measured.size();
  if (!measured.empty()) {
    const std::size_t k =
        std::min(measured.size() - 1, std::size_t(0.99 * double(measured.size())));
    std::nth_element(measured.begin(), measured.begin() + std::ptrdiff_t(k), measured.end());
    result.p99_px = measured[k];
  }
  return result;
}

[[noreturn]] void throw_embree_error(RTCDevice device, const char* what) {
  throw std::runtime_error(std::string("Embree: ") + what + " failed (error " +
                           std::to_string(int(rtcGetDeviceError(device))) + ")");
}

}  // namespace

struct ReferenceRaycaster::Impl {
  ReferenceOptions options;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<glm::vec3> p_world;  // 3 per triangle, in triangle-ID order (ID = index + 1)

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  // Distance along the world ray (origin, unit v) to triangle `id`, in its plane and within its
  // edges up to a relative 1e-6; empty when the ray misses it.
  std::optional<double> ray_distance(const glm::dvec3& origin, const glm::dvec3& v,
                                     std::uint32_t id) const {
    const glm::dvec3 a(p_world[3 * std::size_t(id - 1)]);
    const glm::dvec3 b(p_world[3 * std::size_t(id - 1) + 1]);
    const glm::dvec3 c(p_world[3 * std::size_t(id - 1) + 2]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double along = glm::dot(n, v);
    if (!(std::abs(along) > 1e-12 * glm::length(n))) return std::nullopt;
    const double d = glm::dot(n, a - origin) / along;
    if (!(d > 0)) return std::nullopt;
    const glm::dvec3 x = origin + d * v;
    const double slack = -1e-6 * glm::dot(n, n);
    if (glm::dot(glm::cross(b - a, x - a), n) < slack ||
        glm::dot(glm::cross(c - b, x - b), n) < slack ||
        glm::dot(glm::cross(a - c, x - c), n) < slack) {
      return std::nullopt;
    }
    return d;
  }
  // Both triangles (IDs, 0 for none) on the world ray at the same distance: surfaces that
  // coincide there, where either ID is right.
  bool depth_tie(const glm::dvec3& origin, const glm::dvec3& v, std::uint32_t a,
                 std::uint32_t b) const {
    if (a == 0 || b == 0) return false;
    const auto da = ray_distance(origin, v, a), db = ray_distance(origin, v, b);
    return da && db && std::abs(*da - *db) <= 1e-5 * std::max(*da, *db);
  }

  // Rejects hits on back faces: the triangle's counter-clockwise normal points along the ray.
  static void cull_back_faces(const RTCFilterFunctionNArguments* args) {
    const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] == 0) continue;
      const unsigned triangle = RTCHitN_primID(args->hit, args->N, i);
      const glm::vec3& p0 = self->p_world[3 * std::size_t(triangle)];
      const glm::vec3 n = glm::cross(self->p_world[3 * std::size_t(triangle) + 1] - p0,
                                     self->p_world[3 * std::size_t(triangle) + 2] - p0);
      const glm::vec3 v(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                        RTCRayN_dir_z(args->ray, args->N, i));
      if (!(glm::dot(n, v) < 0)) args->valid[i] = 0;
    }
  }
};

ReferenceRaycaster::ReferenceRaycaster(const Scene& scene, const ReferenceOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  // Same order as the triangle-ID numbering: objects in order, their primitives in order.
  for (const Object& object : scene.objects) {
    for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
      const Primitive& primitive = scene.primitives.at(object.first_primitive + k);
      for (std::uint32_t i = 0; i < primitive.index_count; ++i) {
        const glm::vec3& p = scene.positions.at(scene.indices.at(primitive.first_index + i));
        impl_->p_world.push_back(glm::vec3(object.T_world_object * glm::vec4(p, 1.0f)));
      }
    }
  }
  RTCDevice device = impl_->device = rtcNewDevice(nullptr);
  if (!device) throw std::runtime_error("Embree: rtcNewDevice failed");
  impl_->scene = rtcNewScene(device);
  if (!impl_->scene) throw_embree_error(device, "rtcNewScene");
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  const std::size_t triangles = impl_->p_world.size() / 3;
  if (triangles > 0) {
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!geometry) throw_embree_error(device, "rtcNewGeometry");
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(float) * 3, triangles * 3));
    auto* indices = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                sizeof(std::uint32_t) * 3, triangles));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geometry);
      throw_embree_error(device, "rtcSetNewGeometryBuffer");
    }
    for (std::size_t k = 0; k < impl_->p_world.size(); ++k) {
      vertices[3 * k] = impl_->p_world[k].x;
      vertices[3 * k + 1] = impl_->p_world[k].y;
      vertices[3 * k + 2] = impl_->p_world[k].z;
      indices[k] = std::uint32_t(k);
    }
    if (options.cull_back_faces) {
      rtcSetGeometryUserData(geometry, impl_.get());
      rtcSetGeometryIntersectFilterFunction(geometry, &Impl::cull_back_faces);
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(impl_->scene, geometry);
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(impl_->scene);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) throw_embree_error(device, "building the scene");
}

ReferenceRaycaster::~ReferenceRaycaster() = default;
ReferenceRaycaster::ReferenceRaycaster(ReferenceRaycaster&&) noexcept = default;
ReferenceRaycaster& ReferenceRaycaster::operator=(ReferenceRaycaster&&) noexcept = default;

std::size_t ReferenceRaycaster::triangle_count() const { return impl_->p_world.size() / 3; }

std::uint32_t ReferenceRaycaster::id_along(const glm::dvec3& p_world,
                                           const glm::dvec3& v_world) const {
  return id_between(p_world, glm::normalize(v_world), impl_->options.near_m);
}

std::uint32_t ReferenceRaycaster::id_between(const glm::dvec3& p_world, const glm::dvec3& v_world,
                                             double t_near) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rayhit{};
  rayhit.ray.org_x = float(p_world.x);
  rayhit.ray.org_y = float(p_world.y);
  rayhit.ray.org_z = float(p_world.z);
  rayhit.ray.dir_x = float(v_world.x);
  rayhit.ray.dir_y = float(v_world.y);
  rayhit.ray.dir_z = float(v_world.z);
  rayhit.ray.tnear = float(t_near);
  rayhit.ray.tfar = std::numeric_limits<float>::infinity();
  rayhit.ray.mask = 0xFFFFFFFFu;
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rayhit);
  return rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 0 : rayhit.hit.primID + 1;
}

std::vector<std::uint32_t> ReferenceRaycaster::ids(const WarpInverse& inverse,
                                                   const glm::dmat4& T_eye_world) const {
  const glm::ivec2 size = inverse.warp().output_size;
  const glm::dmat4 T_world_eye = glm::inverse(T_eye_world);
  const glm::dvec3 p_eye_world(T_world_eye[3]);
  const glm::dmat3 R_world_eye(T_world_eye);
  std::vector<std::uint32_t> ids(std::size_t(size.x) * size.y, 0);
  for_each_row(size.y, [&](int y) {
    for (int x = 0; x < size.x; ++x) {
      const auto found = inverse.invert(glm::dvec2(x + 0.5, y + 0.5));
      if (!found) continue;
      ids[std::size_t(y) * size.x + x] = id_along(p_eye_world, R_world_eye * found->v_eye);
    }
  });
  return ids;
}

std::vector<std::uint32_t> ReferenceRaycaster::ids(const PiecewiseGlc& camera,
                                                   const glm::dmat4& T_eye_world,
                                                   double z_near) const {
  const glm::dmat4 T_world_eye = glm::inverse(T_eye_world);
  const glm::dmat3 R_world_eye(T_world_eye);
  std::vector<std::uint32_t> ids(std::size_t(camera.size.x) * camera.size.y, 0);
  for_each_row(camera.size.y, [&](int y) {
    for (int x = 0; x < camera.size.x; ++x) {
      const auto ray = camera.ray(x, y);
      if (!ray) continue;
      ids[std::size_t(y) * camera.size.x + x] =
          id_between(glm::dvec3(T_world_eye * glm::dvec4(ray->origin, 1.0)),
                     R_world_eye * ray->direction, z_near);
    }
  });
  return ids;
}

std::vector<std::uint32_t> reference_ids(const Scene& scene, const Warp& warp,
                                         const glm::dmat4& T_eye_world,
                                         const ReferenceOptions& options) {
  const ReferenceRaycaster raycaster(scene, options);
  return raycaster.ids(WarpInverse(warp), T_eye_world);
}

EdgeDisplacement ReferenceRaycaster::edge_displacement(
    const WarpInverse& inverse, const glm::dmat4& T_eye_world,
    const std::vector<std::uint32_t>& reference, const std::vector<std::uint32_t>& tested,
    const EdgeDisplacementOptions& options) const {
  const glm::ivec2 size = inverse.warp().output_size;
  const std::vector<glm::ivec2> all_differing = differing_pixels(size, reference, tested, options);
  const std::vector<glm::ivec2> differing =
      searched_sample(all_differing, options.max_searched_pixels);
  const glm::dmat4 T_world_eye = glm::inverse(T_eye_world);
  const glm::dvec3 p_eye_world(T_world_eye[3]);
  const glm::dmat3 R_world_eye(T_world_eye);
  auto covered = [&](glm::dvec2 q) {
    if (options.wrap_x) q.x -= std::floor(q.x / size.x) * size.x;
    return inverse.invert(q).has_value();
  };
  // Where edges lie is the warp's map, which goes on past its coverage (the offsets are defined
  // there, and facets straddling the coverage's edge follow it). Searching covered positions only
  // measured a pixel on the coverage's edge (dome4 at 1 px, output 1, (88, 0)) as 1.74 px from
  // where its triangle is seen, which lay just outside the coverage; with the map continued the
  // worst pixel of that run is 0.90 px, within its facet error of 0.97 px.
  const WarpInverse continued = continued_inverse(inverse.warp());
  auto id_at = [&](glm::dvec2 q) -> std::uint32_t {
    if (options.wrap_x) q.x -= std::floor(q.x / size.x) * size.x;
    const auto found = continued.invert(q);
    return found ? id_along(p_eye_world, R_world_eye * found->v_eye) : 0u;
  };

  const glm::dmat3 R_eye_world(T_eye_world);
  const glm::dvec3 p_world_eye(T_eye_world[3]);

  // Corners of triangle `id` as pixel offsets from `anchor`, through the local linear map of the
  // warp there: the directions that meet a triangle form a spherical triangle, which the
  // gnomonic projection onto the tangent plane at the anchor's direction keeps a straight-edged
  // triangle, and the warp inverse at anchor ± 1/64 px gives the map of that plane to output
  // pixels. Empty without a preimage or with a corner 90° or more from the anchor's direction.
  auto corners_around = [&](glm::dvec2 anchor,
                            std::uint32_t id) -> std::optional<std::array<glm::dvec2, 3>> {
    const auto at_anchor = continued.invert(anchor);
    if (!at_anchor) return std::nullopt;
    const glm::dvec3 v = glm::normalize(at_anchor->v_eye);
    constexpr double kEpsPx = 1.0 / 64;
    glm::dvec3 dv_dq[2];
    for (int axis = 0; axis < 2; ++axis) {
      glm::dvec2 offset(0.0);
      offset[axis] = kEpsPx;
      const auto plus = continued.invert(anchor + offset),
                 minus = continued.invert(anchor - offset);
      if (!plus || !minus) return std::nullopt;
      dv_dq[axis] =
          (plus->v_eye / glm::dot(plus->v_eye, v) - minus->v_eye / glm::dot(minus->v_eye, v)) /
          (2 * kEpsPx);
    }
    // Tangent-plane point w ↦ pixel offset: least squares on the basis dv_dq.
    const glm::dmat2 gram(glm::dot(dv_dq[0], dv_dq[0]), glm::dot(dv_dq[0], dv_dq[1]),
                          glm::dot(dv_dq[1], dv_dq[0]), glm::dot(dv_dq[1], dv_dq[1]));
    if (!(std::abs(glm::determinant(gram)) > 0)) return std::nullopt;
    const glm::dmat2 gram_inverse = glm::inverse(gram);
    std::array<glm::dvec2, 3> corner;
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 X =
          R_eye_world * glm::dvec3(impl_->p_world[3 * std::size_t(id - 1) + k]) + p_world_eye;
      const double along = glm::dot(X, v);
      if (!(along > 1e-9 * glm::length(X))) return std::nullopt;
      const glm::dvec3 w = X / along - v;
      corner[k] = gram_inverse * glm::dvec2(glm::dot(w, dv_dq[0]), glm::dot(w, dv_dq[1]));
    }
    return corner;
  };
  // Nearest point on a triangle's edges to `target`, and whether `target` is inside.
  struct Nearest {
    glm::dvec2 point;
    bool target_inside;
  };
  auto nearest_on_edges = [](const std::array<glm::dvec2, 3>& corner, glm::dvec2 target) {
    const double area = (corner[1].x - corner[0].x) * (corner[2].y - corner[0].y) -
                        (corner[1].y - corner[0].y) * (corner[2].x - corner[0].x);
    Nearest result{glm::dvec2(0.0), area != 0};
    for (int k = 0; k < 3 && result.target_inside; ++k) {
      const glm::dvec2 a = corner[k], b = corner[(k + 1) % 3];
      result.target_inside =
          ((b.x - a.x) * (target.y - a.y) - (b.y - a.y) * (target.x - a.x)) * area >= 0;
    }
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 a = corner[k], ab = corner[(k + 1) % 3] - a;
      const double length2 = glm::dot(ab, ab);
      const double u = length2 > 0 ? std::clamp(glm::dot(target - a, ab) / length2, 0.0, 1.0) : 0.0;
      const glm::dvec2 p = a + u * ab;
      if (glm::length(p - target) < best) {
        best = glm::length(p - target);
        result.point = p;
      }
    }
    return result;
  };
  // The nearest point to q on the edge of triangle `id`'s image, seen from outside (q outside the
  // triangle) or from inside: found in the linear map at q, then again in the map at that point,
  // until it moves less than 1e-4 px, so it is exact up to that and the warp inverse. Empty where
  // the maps do not apply or q is not on the side asked for. Also returns the direction into the
  // triangle there (towards its centroid).
  auto edge_point = [&](glm::dvec2 q, std::uint32_t id,
                        bool q_inside) -> std::optional<std::pair<glm::dvec2, glm::dvec2>> {
    glm::dvec2 point = q, inward(0.0);
    for (int iteration = 0; iteration < 8; ++iteration) {
      const auto corner = corners_around(point, id);
      if (!corner) return std::nullopt;
      const Nearest nearest = nearest_on_edges(*corner, q - point);
      if (nearest.target_inside != q_inside) return std::nullopt;
      const glm::dvec2 moved = point + nearest.point;
      inward = point + ((*corner)[0] + (*corner)[1] + (*corner)[2]) / 3.0 - moved;
      const bool settled = glm::length(moved - point) < 1e-4;
      point = moved;
      if (settled && iteration > 0) break;
    }
    return std::pair{point, inward};
  };
  // Distance from q, outside triangle `id`'s image, to where the triangle is seen. Empty where
  // edge_point is, or where the triangle is hidden at the point found (a ray cast 0.01 px inside
  // it); the lattice search then decides.
  auto distance_to_triangle = [&](glm::dvec2 q, std::uint32_t id) -> std::optional<double> {
    const auto found = edge_point(q, id, false);
    if (!found) return std::nullopt;
    const auto [point, inward] = *found;
    if (glm::length(inward) == 0) return std::nullopt;
    const glm::dvec2 probe = point + std::min(0.01, glm::length(inward)) * glm::normalize(inward);
    if (id_at(probe) != id) return std::nullopt;
    return glm::length(point - q);
  };

  // Both triangles on the pixel centre's ray at the same distance: surfaces that coincide there.
  auto depth_tie = [&](glm::dvec2 q, std::uint32_t a, std::uint32_t b) {
    const auto found = inverse.invert(q);
    return found && impl_->depth_tie(p_eye_world, glm::normalize(R_world_eye * found->v_eye), a, b);
  };

  // Negative: nothing within the window; NaN: a depth tie.
  std::vector<double> distance(differing.size(), -1.0);
  std::vector<char> outside(differing.size(), 0);
  for_each_row(int(differing.size()), [&](int k) {
    const glm::ivec2 pixel = differing[std::size_t(k)];
    const std::uint32_t id = tested[std::size_t(pixel.y) * size.x + pixel.x];
    const glm::dvec2 centre = glm::dvec2(pixel) + 0.5;
    if (depth_tie(centre, id, reference[std::size_t(pixel.y) * size.x + pixel.x])) {
      distance[std::size_t(k)] = std::numeric_limits<double>::quiet_NaN();
      return;
    }
    // A triangle drawn too far: how far it reaches past where it is seen. Nothing drawn (ID 0):
    // how far the reference's triangle, and what lies around it, was pulled back from q. The
    // computed distance bounds the true one from above (another surface may hide or uncover the
    // triangle nearer, along an edge of its own or where two surfaces cross), so the lattice
    // search below looks for nearer points within it.
    const std::uint32_t expected = reference[std::size_t(pixel.y) * size.x + pixel.x];
    // Drawn where the display shows nothing (no direction maps to the centre): the facets' guard
    // band, or the part of a facet beyond the coverage's edge (a facet straddling it is kept
    // whole), which the blend map hides. Measured apart: how far the centre lies outside what the
    // display covers.
    const bool outside_display = id != 0 && !covered(centre);
    outside[std::size_t(k)] = outside_display;
    double limit = options.window_px;
    if (id != 0 && !outside_display) {
      if (const auto exact = distance_to_triangle(centre, id)) limit = std::min(limit, *exact);
    } else if (id == 0) {
      if (const auto found = edge_point(centre, expected, true)) {
        limit = std::min(limit, glm::length(found->first - centre));
      }
    }
    auto marks_the_edge = [&](glm::dvec2 q) {
      if (outside_display) return covered(q);
      const std::uint32_t seen = id_at(q);
      return id != 0 ? seen == id : seen != expected;
    };
    distance[std::size_t(k)] = searched_distance(centre, limit, options, marks_the_edge);
  });

  return summarize_edges(all_differing.size(), differing, distance, outside, options);
}

IdComparison compare_ids(const std::vector<std::uint32_t>& reference,
                         const std::vector<std::uint32_t>& tested, glm::ivec2 size,
                         const IdCompareOptions& options) {
  const std::size_t pixels = std::size_t(std::max(size.x, 0)) * std::max(size.y, 0);
  if (reference.size() != pixels) {
    throw InputError("reference ID image", "size",
                     "expected " + std::to_string(size.x) + "×" + std::to_string(size.y) +
                         " pixels, got " + std::to_string(reference.size()));
  }
  if (tested.size() != pixels) {
    throw InputError("tested ID image", "size",
                     "expected " + std::to_string(size.x) + "×" + std::to_string(size.y) +
                         " pixels, got " + std::to_string(tested.size()));
  }
  auto at = [&](const std::vector<std::uint32_t>& image, int x, int y) {
    return image[std::size_t(y) * size.x + x];
  };
  // Column x on the image, or -1 beyond its edge; with wrap_x every column is on it.
  auto column = [&](int x) {
    if (options.wrap_x) return ((x % size.x) + size.x) % size.x;
    return x < 0 || x >= size.x ? -1 : x;
  };
  // Horizontal distance, the short way round with wrap_x.
  auto x_distance = [&](long dx) {
    dx = std::abs(dx);
    return options.wrap_x ? std::min(dx, long(size.x) - dx) : dx;
  };

  // Where each ID lies in the reference, for the edge distances.
  std::unordered_map<std::uint32_t, std::vector<glm::ivec2>> pixels_of_id;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) pixels_of_id[at(reference, x, y)].push_back({x, y});
  }
  // The squared distance from (x, y) to the nearest of `id_pixels` (row-major order, so each row's
  // pixels are a run sorted by x), row by row outwards from y until the rows are farther than
  // the best found: a few binary searches however far the pixel is (a scan of the whole list for
  // every far pixel took 97% of a 138 s `render --reference` of the vertex method at 1600×1200).
  auto nearest_in_rows = [&](const std::vector<glm::ivec2>& id_pixels, int x, int y) {
    const auto by_y = [](const glm::ivec2& a, const glm::ivec2& b) { return a.y < b.y; };
    const auto by_x = [](const glm::ivec2& a, int value) { return a.x < value; };
    long best = std::numeric_limits<long>::max();
    auto try_row = [&](int row) {
      const auto [first, last] =
          std::equal_range(id_pixels.begin(), id_pixels.end(), glm::ivec2(0, row), by_y);
      if (first == last) return;
      const auto at_x = std::lower_bound(first, last, x, by_x);
      const long dy = row - y;
      auto try_pixel = [&](const glm::ivec2& p) {
        const long dx = x_distance(p.x - x);
        best = std::min(best, dx * dx + dy * dy);
      };
      // The nearest in x is beside x's place in the run; with wrap_x it may be either end.
      if (at_x != last) try_pixel(*at_x);
      if (at_x != first) try_pixel(*(at_x - 1));
      if (options.wrap_x) {
        try_pixel(*first);
        try_pixel(*(last - 1));
      }
    };
    const int first_row = id_pixels.front().y, last_row = id_pixels.back().y;
    for (long dy = 0; dy * dy < best && (y - dy >= first_row || y + dy <= last_row); ++dy) {
      try_row(int(y - dy));
      if (dy > 0) try_row(int(y + dy));
    }
    return best;
  };

  IdComparison result;
  std::vector<double> edge_px;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const std::uint32_t expected = at(reference, x, y), id = at(tested, x, y);
      bool near_edge = false;
      for (int dy = -1; dy <= 1 && !near_edge; ++dy) {
        for (int dx = -1; dx <= 1 && !near_edge; ++dx) {
          const int nx = column(x + dx), ny = y + dy;
          if (nx < 0 || ny < 0 || ny >= size.y) continue;
          near_edge = at(reference, nx, ny) != expected;
        }
      }
      if (!near_edge) {
        ++result.compared_pixels;
        if (id != expected) ++result.mismatched_pixels;
      }
      if (id == expected) continue;
      ++result.differing_pixels;
      const auto list = pixels_of_id.find(id);
      if (list == pixels_of_id.end()) {
        ++result.absent_id_pixels;
        continue;
      }
      if (list->second.size() < options.min_reference_pixels) {
        ++result.sparse_id_pixels;
        continue;
      }
      edge_px.push_back(std::sqrt(double(nearest_in_rows(list->second, x, y))));
    }
  }
  result.id_mismatch = result.compared_pixels == 0
                           ? 0.0
                           : double(result.mismatched_pixels) / double(result.compared_pixels);
  if (!edge_px.empty()) {
    result.max_edge_px = *std::max_element(edge_px.begin(), edge_px.end());
    const std::size_t k = std::min(edge_px.size() - 1, std::size_t(0.99 * double(edge_px.size())));
    std::nth_element(edge_px.begin(), edge_px.begin() + std::ptrdiff_t(k), edge_px.end());
    result.p99_edge_px = edge_px[k];
  }
  return result;
}

EdgeDisplacement ReferenceRaycaster::edge_displacement(
    const PiecewiseGlc& camera, const glm::dmat4& T_eye_world, double z_near,
    const std::vector<std::uint32_t>& reference, const std::vector<std::uint32_t>& tested,
    const EdgeDisplacementOptions& options) const {
  const glm::ivec2 size = camera.size;
  const std::vector<glm::ivec2> all_differing = differing_pixels(size, reference, tested, options);
  const std::vector<glm::ivec2> differing =
      searched_sample(all_differing, options.max_searched_pixels);
  const glm::dmat4 T_world_eye = glm::inverse(T_eye_world);
  const glm::dmat3 R_world_eye(T_world_eye);
  // The camera's ray through q in the world frame; its direction's frame-z component is 1, so
  // the distance along it is the frame depth, as ids() casts.
  auto ray_at = [&](glm::dvec2 q) -> std::optional<EyeRay> {
    if (options.wrap_x) q.x -= std::floor(q.x / size.x) * size.x;
    auto ray = camera.ray_at(q);
    if (!ray) return std::nullopt;
    return EyeRay{glm::dvec3(T_world_eye * glm::dvec4(ray->origin, 1.0)),
                  R_world_eye * ray->direction};
  };
  auto id_at = [&](glm::dvec2 q) -> std::uint32_t {
    const auto ray = ray_at(q);
    return ray ? id_between(ray->origin, ray->direction, z_near) : 0u;
  };

  std::vector<double> distance(differing.size(), -1.0);
  std::vector<char> outside(differing.size(), 0);
  for_each_row(int(differing.size()), [&](int k) {
    const glm::ivec2 pixel = differing[std::size_t(k)];
    const std::size_t i = std::size_t(pixel.y) * size.x + pixel.x;
    const std::uint32_t id = tested[i], expected = reference[i];
    const glm::dvec2 centre = glm::dvec2(pixel) + 0.5;
    const auto ray = ray_at(centre);
    if (ray && impl_->depth_tie(ray->origin, glm::normalize(ray->direction), id, expected)) {
      distance[std::size_t(k)] = std::numeric_limits<double>::quiet_NaN();
      return;
    }
    const bool outside_display = id != 0 && !ray;
    outside[std::size_t(k)] = outside_display;
    distance[std::size_t(k)] =
        searched_distance(centre, options.window_px, options, [&](glm::dvec2 q) {
          if (outside_display) return ray_at(q).has_value();
          const std::uint32_t seen = id_at(q);
          return id != 0 ? seen == id : seen != expected;
        });
  });
  return summarize_edges(all_differing.size(), differing, distance, outside, options);
}

}  // namespace facet::driver
