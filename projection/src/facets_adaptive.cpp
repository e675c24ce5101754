// The adaptive tolerance layout: newest-vertex bisection of a triangulated grid over the base
// image. Each triangle is bisected across its refinement edge, and the neighbour sharing that
// edge is bisected with it (first refined itself until the edge is its refinement edge too), so
// the mesh stays conforming: every edge belongs to at most two facets and no vertex lies inside
// another facet's edge. Unlike a tensor-product grid, a warp that is hard to follow in one corner
// (a spherical mirror's crowded rim) refines only that corner.
#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include "facet/projection/errors.hpp"
#include "facet/projection/parallel.hpp"
#include "facets_internal.hpp"

namespace facet::detail {
namespace {

// Starting triangles span at most this angle along each axis of the base image.
constexpr double kStartAngle = 30.0 * kPi / 180.0;
// Triangles narrower than this in st cannot be bisected further.
constexpr double kMinimumExtent = 1e-7;
constexpr std::uint32_t kNone = UINT32_MAX;

struct Triangle {
  // Corner 0 is the apex; corners 1 and 2 span the refinement edge.
  std::array<std::uint32_t, 3> id{};  // canonical vertex ids: topology
  std::array<glm::dvec2, 3> st{};     // this triangle's own base positions: geometry
  bool leaf = true;
  bool evaluated = false;
  bool covered = false;
  double error = 0;
  std::optional<Facet> facet;  // Facet::vertex holds offsets into st
};

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t(a) << 32) | b;
}

// Inside the st triangle, its edges included.
bool inside_st_triangle(const std::array<glm::dvec2, 3>& c, glm::dvec2 p) {
  const auto cross = [](glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; };
  const double area = cross(c[1] - c[0], c[2] - c[0]);
  const double eps = 1e-12 * std::abs(area);
  const double w0 = cross(c[2] - c[1], p - c[1]), w1 = cross(c[0] - c[2], p - c[2]),
               w2 = cross(c[1] - c[0], p - c[0]);
  return area > 0 ? (w0 >= -eps && w1 >= -eps && w2 >= -eps)
                  : (w0 <= eps && w1 <= eps && w2 <= eps);
}

class Bisection {
 public:
  Bisection(const Warp& warp, double limit_px, int max_facets)
      : warp_(warp), limit_px_(limit_px), max_facets_(max_facets) {}

  void start(int columns, int rows) {
    const auto at = [&](int c, int r) { return glm::dvec2(double(c) / columns, double(r) / rows); };
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < columns; ++c) {
        // Both halves of a cell share its diagonal as their refinement edge; its sides become
        // the refinement edges of their children, as they do on the other side of each side.
        const glm::dvec2 p00 = at(c, r), p10 = at(c + 1, r), p01 = at(c, r + 1),
                         p11 = at(c + 1, r + 1);
        add(make({p10, p00, p11}));
        add(make({p01, p11, p00}));
      }
    }
  }

  void refine() {
    for (;;) {
      std::vector<std::uint32_t> pending;
      for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
        if (triangles_[t].leaf && !triangles_[t].evaluated) pending.push_back(t);
      }
      parallel_for(pending.size(), [&](std::size_t k, std::size_t) { evaluate(pending[k]); });
      std::vector<std::uint32_t> over;
      for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
        const Triangle& tri = triangles_[t];
        if (tri.leaf && tri.covered && !(tri.error <= limit_px_)) over.push_back(t);
      }
      if (over.empty()) return;
      for (std::uint32_t t : over) {
        if (!triangles_[t].leaf) continue;  // bisected already, as a neighbour
        const glm::dvec2 extent = glm::max(glm::abs(triangles_[t].st[1] - triangles_[t].st[0]),
                                           glm::abs(triangles_[t].st[2] - triangles_[t].st[0]));
        if (std::max(extent.x, extent.y) < kMinimumExtent) {
          const glm::dvec2 st = triangles_[t].st[0];
          throw InputError({}, "tolerance",
                           "the warp changes too fast near st = (" + std::to_string(st.x) + ", " +
                               std::to_string(st.y) + ") for facets to meet " +
                               std::to_string(limit_px_ / kBuildMargin) + " px");
        }
        split(t);
      }
      if (leaves_ > 2 * std::size_t(max_facets_)) {
        throw InputError({}, "tolerance",
                         "meeting " + std::to_string(limit_px_ / kBuildMargin) +
                             " px needs more than " + std::to_string(2 * max_facets_) + " facets");
      }
    }
  }

  FacetMesh assemble() const {
    FacetMesh mesh;
    mesh.output_size = warp_.output_size;
    std::map<std::pair<double, double>, std::uint32_t> vertex_of;
    const auto vertex = [&](glm::dvec2 st) {
      const auto [it, inserted] =
          vertex_of.try_emplace({st.x, st.y}, std::uint32_t(mesh.vertices.size()));
      if (inserted) mesh.vertices.push_back(vertex_at(warp_, st));
      return it->second;
    };
    for (const Triangle& tri : triangles_) {
      if (!tri.leaf || !tri.covered) continue;
      FACET_ASSERT(tri.facet.has_value());
      Facet facet = *tri.facet;
      for (int m = 0; m < 3; ++m) facet.vertex[m] = vertex(tri.st[tri.facet->vertex[m]]);
      mesh.facets.push_back(facet);
    }
    return mesh;
  }

 private:
  std::uint32_t canonical(glm::dvec2 st) {
    // On a 360° base, s = 1 and s = 0 are the same directions: the seam's edges are shared.
    if (warp_.base.wraps_horizontally() && st.x >= 1.0) st.x -= 1.0;
    const auto [it, inserted] = ids_.try_emplace({st.x, st.y}, std::uint32_t(ids_.size()));
    return it->second;
  }

  Triangle make(const std::array<glm::dvec2, 3>& st) {
    Triangle tri;
    tri.st = st;
    for (int k = 0; k < 3; ++k) tri.id[k] = canonical(st[k]);
    return tri;
  }

  void add(const Triangle& tri) {
    const std::uint32_t t = std::uint32_t(triangles_.size());
    triangles_.push_back(tri);
    ++leaves_;
    for (int k = 0; k < 3; ++k) {
      auto [it, inserted] =
          edges_.try_emplace(edge_key(tri.id[k], tri.id[(k + 1) % 3]), std::array{kNone, kNone});
      (it->second[0] == kNone ? it->second[0] : it->second[1]) = t;
    }
  }

  void remove_edges(std::uint32_t t) {
    const Triangle& tri = triangles_[t];
    for (int k = 0; k < 3; ++k) {
      auto it = edges_.find(edge_key(tri.id[k], tri.id[(k + 1) % 3]));
      FACET_ASSERT(it != edges_.end());
      for (std::uint32_t& slot : it->second) {
        if (slot == t) slot = kNone;
      }
      if (it->second[0] == kNone && it->second[1] == kNone) edges_.erase(it);
    }
  }

  std::uint32_t across(std::uint32_t t, std::uint64_t key) const {
    const auto it = edges_.find(key);
    if (it == edges_.end()) return kNone;
    return it->second[0] == t ? it->second[1] : it->second[0];
  }

  std::uint64_t refinement_key(std::uint32_t t) const {
    return edge_key(triangles_[t].id[1], triangles_[t].id[2]);
  }

  void split(std::uint32_t t) {
    const std::uint64_t key = refinement_key(t);
    std::uint32_t neighbour = across(t, key);
    if (neighbour != kNone && refinement_key(neighbour) != key) {
      split(neighbour);
      neighbour = across(t, key);
      FACET_ASSERT(neighbour != kNone && refinement_key(neighbour) == key);
    }
    bisect(t);
    if (neighbour != kNone) bisect(neighbour);
  }

  void bisect(std::uint32_t t) {
    remove_edges(t);
    triangles_[t].leaf = false;
    --leaves_;
    const std::array<glm::dvec2, 3> st = triangles_[t].st;  // copied: add() reallocates
    const glm::dvec2 mid = (st[1] + st[2]) / 2.0;
    add(make({mid, st[0], st[1]}));
    add(make({mid, st[2], st[0]}));
  }

  void evaluate(std::uint32_t t) {
    Triangle& tri = triangles_[t];
    tri.evaluated = true;
    const glm::dvec2 lo = glm::min(glm::min(tri.st[0], tri.st[1]), tri.st[2]);
    const glm::dvec2 hi = glm::max(glm::max(tri.st[0], tri.st[1]), tri.st[2]);
    tri.covered = max_coverage(warp_, lo.x, hi.x, lo.y, hi.y) >= 0.5;
    if (!tri.covered) return;
    tri.error = std::numeric_limits<double>::infinity();
    const std::array<FacetVertex, 3> v{vertex_at(warp_, tri.st[0]), vertex_at(warp_, tri.st[1]),
                                       vertex_at(warp_, tri.st[2])};
    for (auto [a, b] : {std::pair{0, 1}, {1, 2}, {2, 0}}) {
      if (angle_between(v[a].p_eye, v[b].p_eye) > kMaxFacetAngle) return;
    }
    tri.facet = make_facet(v[0], v[1], v[2]);
    if (!tri.facet) return;
    const Facet& facet = *tri.facet;
    const std::array<glm::dvec3, 3> p{v[facet.vertex[0]].p_eye, v[facet.vertex[1]].p_eye,
                                      v[facet.vertex[2]].p_eye};
    const double s_hint = (tri.st[0].x + tri.st[1].x + tri.st[2].x) / 3;
    double error = lattice_error(warp_, facet, p, s_hint, kBuildSubdivisions, limit_px_);
    // The base-image triangle too, with the offset map's node lines, where a bilinear warp's error
    // peaks; its curved sides lie a little off the chord triangle's.
    if (error <= limit_px_) {
      auto positions = [](double a, double b, int nodes) {
        std::vector<double> values;
        for (int k = 0; k <= kBuildSubdivisions; ++k) {
          values.push_back(a + (b - a) * k / kBuildSubdivisions);
        }
        append_node_lines(a, b, nodes, values);
        return values;
      };
      const auto s_values = positions(lo.x, hi.x, warp_.grid_size.x);
      const auto t_values = positions(lo.y, hi.y, warp_.grid_size.y);
      for (double s : s_values) {
        for (double t_value : t_values) {
          const glm::dvec2 st{s, t_value};
          if (!inside_st_triangle(tri.st, st) || warp_.coverage_at(st) < 0.5) continue;
          const glm::dvec3 X = warp_.p_eye_surface_from_st(st);
          error = std::max(error, pixel_distance(warp_, facet.project(X), warp_.q_from_st(st)));
          if (error > limit_px_) break;
        }
        if (error > limit_px_) break;
      }
    }
    tri.error = error;
  }

  const Warp& warp_;
  double limit_px_;
  int max_facets_;
  std::vector<Triangle> triangles_;
  std::size_t leaves_ = 0;
  std::map<std::pair<double, double>, std::uint32_t> ids_;
  std::unordered_map<std::uint64_t, std::array<std::uint32_t, 2>> edges_;
};

// The largest angle swept along an axis of the base image, over a few lines across the other.
double angular_extent(const Warp& warp, int axis) {
  double largest = 0;
  constexpr int kSamples = 64;
  for (int across = 0; across <= 4; ++across) {
    const double other = across / 4.0;
    const auto st = [&](double x) {
      return axis == 0 ? glm::dvec2(x, other) : glm::dvec2(other, x);
    };
    double total = 0;
    for (int k = 0; k < kSamples; ++k) {
      total += angle_between(warp.v_eye_from_st(st(double(k) / kSamples)),
                             warp.v_eye_from_st(st(double(k + 1) / kSamples)));
    }
    largest = std::max(largest, total);
  }
  return largest;
}

}  // namespace

FacetMesh build_adaptive_layout(const Warp& warp, double target_px, int max_cells) {
  // Start cells about square in output pixels and no wider than kStartAngle.
  int columns = std::max(1, int(std::ceil(angular_extent(warp, 0) / kStartAngle)));
  int rows = std::max(1, int(std::ceil(angular_extent(warp, 1) / kStartAngle)));
  const double cell_px =
      std::max(double(warp.output_size.x) / columns, double(warp.output_size.y) / rows);
  columns = std::max(columns, int(std::ceil(warp.output_size.x / cell_px - 1e-9)));
  rows = std::max(rows, int(std::ceil(warp.output_size.y / cell_px - 1e-9)));
  // A seam needs distinct vertices on either side of every starting cell.
  if (warp.base.wraps_horizontally()) columns = std::max(columns, 3);
  Bisection bisection(warp, target_px * kBuildMargin, max_cells);
  bisection.start(columns, rows);
  bisection.refine();
  return bisection.assemble();
}

}  // namespace facet::detail
