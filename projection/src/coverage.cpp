#include "facet/projection/coverage.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "facet/projection/errors.hpp"
#include "facets_internal.hpp"

namespace facet {
namespace {

constexpr std::uint32_t kLeafSize = 4;
// Cones wider than this are not worth bounding with a pyramid.
const double kMaxBoundedCos = std::cos(80.0 * 3.14159265358979323846 / 180.0);

// Clips a convex polygon against plane·X >= 0 (Sutherland–Hodgman). Returns the new vertex count.
int clip_polygon(const glm::dvec3* in, int count, glm::dvec3 plane, glm::dvec3* out) {
  int written = 0;
  for (int k = 0; k < count; ++k) {
    const glm::dvec3& a = in[k];
    const glm::dvec3& b = in[(k + 1) % count];
    const double da = glm::dot(plane, a), db = glm::dot(plane, b);
    if (da >= 0) out[written++] = a;
    if ((da >= 0) != (db >= 0)) out[written++] = a + (b - a) * (da / (da - db));
  }
  return written;
}

// Sorting key for splitting facets: their centroid directions.
glm::dvec3 centroid_direction(const FacetMesh& mesh, std::uint32_t f) {
  const auto p = mesh.corners(f);
  return glm::normalize(glm::normalize(p[0]) + glm::normalize(p[1]) + glm::normalize(p[2]));
}

}  // namespace

bool triangle_meets_cone(const std::array<glm::dvec3, 3>& triangle, const glm::dvec3* planes,
                         int plane_count) {
  double scale = 0;
  for (const auto& p : triangle) scale = std::max(scale, glm::length(p));
  // Most tests end here, with the answer clipping would give. Every corner outside one plane:
  // so is the whole triangle. A corner inside every plane: clipping keeps it as it is, and the
  // eye test below is then decided by its length.
  std::array<bool, 3> corner_inside{true, true, true};
  for (int k = 0; k < plane_count; ++k) {
    bool any_inside = false;
    for (int c = 0; c < 3; ++c) {
      const bool inside = glm::dot(planes[k], triangle[c]) >= 0;
      any_inside = any_inside || inside;
      corner_inside[c] = corner_inside[c] && inside;
    }
    if (!any_inside) return false;
  }
  for (int c = 0; c < 3; ++c) {
    if (corner_inside[c] && glm::length(triangle[c]) > 1e-12 * scale) return true;
  }
  // A triangle clipped by k planes has at most 3 + k vertices.
  glm::dvec3 buffer_a[12], buffer_b[12];
  std::copy(triangle.begin(), triangle.end(), buffer_a);
  int count = 3;
  glm::dvec3* current = buffer_a;
  glm::dvec3* next = buffer_b;
  for (int k = 0; k < plane_count && count > 0; ++k) {
    count = clip_polygon(current, count, planes[k], next);
    std::swap(current, next);
  }
  if (count == 0) return false;
  // The eye itself lies in every cone; a triangle that meets the cone only there is seen edge-on
  // through the eye and covers nothing. Anything else left after clipping lies strictly inside.
  for (int k = 0; k < count; ++k) {
    if (glm::length(current[k]) > 1e-12 * scale) return true;
  }
  return false;
}

CoverageIndex::CoverageIndex(const FacetMesh& mesh, double guard_px) {
  const std::uint32_t facet_count = std::uint32_t(mesh.facets.size());
  planes_.resize(facet_count);
  edges_.resize(facet_count);
  std::vector<std::array<glm::dvec3, 3>> guarded(facet_count);
  std::vector<glm::dvec3> centroid(facet_count);
  for (std::uint32_t f = 0; f < facet_count; ++f) {
    planes_[f] = mesh.clip_planes(f, guard_px);
    edges_[f] = mesh.facets[f].edge_normal;
    guarded[f] = detail::guarded_corners(mesh, f, guard_px);
    for (auto& p : guarded[f]) p = glm::normalize(p);
    centroid[f] = centroid_direction(mesh, f);
  }
  order_.resize(facet_count);
  std::iota(order_.begin(), order_.end(), 0u);
  if (facet_count == 0) return;

  // Recursive median split on the axis along which the centroids spread most.
  struct Task {
    std::uint32_t node, first, count;
  };
  nodes_.push_back({});
  std::vector<Task> tasks{{0, 0, facet_count}};
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    glm::dvec3 axis(0.0), lo(1e30), hi(-1e30);
    for (std::uint32_t k = task.first; k < task.first + task.count; ++k) {
      for (const auto& p : guarded[order_[k]]) axis += p;
      lo = glm::min(lo, centroid[order_[k]]);
      hi = glm::max(hi, centroid[order_[k]]);
    }
    Node node;
    const double axis_length = glm::length(axis);
    node.axis = axis_length > 0 ? axis / axis_length : glm::dvec3(0, 0, -1);
    double cos_half = 1;
    for (std::uint32_t k = task.first; k < task.first + task.count; ++k) {
      for (const auto& p : guarded[order_[k]])
        cos_half = std::min(cos_half, glm::dot(node.axis, p));
    }
    // A bounding cone of corners holds the whole geodesic triangles only while it is convex.
    if (axis_length > 0 && cos_half > kMaxBoundedCos) {
      node.cos_half_angle = cos_half;
      node.sin_half_angle = std::sqrt(std::max(0.0, 1 - cos_half * cos_half));
    } else {
      node.cos_half_angle = -1;
      node.sin_half_angle = 1;
    }
    if (task.count <= kLeafSize) {
      node.first = task.first;
      node.count = task.count;
      nodes_[task.node] = node;
      continue;
    }
    const glm::dvec3 spread = hi - lo;
    const int split_axis = spread.x >= spread.y && spread.x >= spread.z ? 0
                           : spread.y >= spread.z                       ? 1
                                                                        : 2;
    const std::uint32_t half = task.count / 2;
    std::nth_element(order_.begin() + task.first, order_.begin() + task.first + half,
                     order_.begin() + task.first + task.count,
                     [&](std::uint32_t a, std::uint32_t b) {
                       return centroid[a][split_axis] < centroid[b][split_axis];
                     });
    node.first = std::uint32_t(nodes_.size());
    node.count = 0;
    nodes_[task.node] = node;
    nodes_.push_back({});
    nodes_.push_back({});
    tasks.push_back({node.first, task.first, half});
    tasks.push_back({node.first + 1, task.first + half, task.count - half});
  }
}

namespace {

// Four planes through the eye whose pyramid holds the cone (axis, half-angle).
std::array<glm::dvec3, 4> bounding_pyramid(const CoverageIndex::Node& node) {
  const glm::dvec3 a = node.axis;
  const glm::dvec3 helper = std::abs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 u = glm::normalize(glm::cross(a, helper));
  const glm::dvec3 w = glm::cross(a, u);
  const double s = node.sin_half_angle, c = node.cos_half_angle;
  // Plane tangent to the cone on the side of direction e: sin·a − cos·e.
  return {s * a - c * u, s * a + c * u, s * a - c * w, s * a + c * w};
}

}  // namespace

void CoverageIndex::query(const std::array<glm::dvec3, 3>& triangle,
                          std::vector<std::uint32_t>& facets, bool cull_back_faces) const {
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3& p = triangle[k];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      throw InputError("triangle", "vertex " + std::to_string(k),
                       "expected finite eye-frame coordinates");
    }
  }
  if (cull_back_faces) {
    // Counter-clockwise as seen from the eye is front-facing; edge-on counts as back.
    const glm::dvec3 normal = glm::cross(triangle[1] - triangle[0], triangle[2] - triangle[0]);
    if (!(glm::dot(normal, triangle[0]) < 0)) return;
  }
  if (nodes_.empty()) return;
  const std::size_t first_output = facets.size();
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.cos_half_angle > -1) {
      const auto pyramid = bounding_pyramid(node);
      if (!triangle_meets_cone(triangle, pyramid.data(), 4)) continue;
    }
    if (node.count > 0) {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        const std::uint32_t f = order_[k];
        if (triangle_meets_cone(triangle, planes_[f].data(), 3)) facets.push_back(f);
      }
    } else {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
    }
  }
  std::sort(facets.begin() + std::ptrdiff_t(first_output), facets.end());
}

std::optional<std::uint32_t> CoverageIndex::locate(glm::dvec3 v) const {
  if (nodes_.empty() || !(glm::length(v) > 0)) return std::nullopt;
  v = glm::normalize(v);
  std::optional<std::uint32_t> best;
  double best_margin = -1e-12;
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.cos_half_angle > -1 && glm::dot(node.axis, v) < node.cos_half_angle - 1e-12) continue;
    if (node.count > 0) {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        const std::uint32_t f = order_[k];
        const double margin = std::min(
            {glm::dot(edges_[f][0], v), glm::dot(edges_[f][1], v), glm::dot(edges_[f][2], v)});
        if (margin > best_margin) {
          best_margin = margin;
          best = f;
        }
      }
    } else {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
    }
  }
  return best;
}

}  // namespace facet
