#include "facet/projection/facet_error.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "facet/projection/parallel.hpp"
#include "facets_internal.hpp"

namespace facet {
namespace detail {

double pixel_distance(const Warp& warp, glm::dvec2 q_facet, glm::dvec2 q_exact) {
  glm::dvec2 difference = q_facet - q_exact;
  if (warp.base.wraps_horizontally()) {
    const double width = warp.output_size.x;
    difference.x -= width * std::round(difference.x / width);
  }
  return glm::length(difference);
}

double inside_margin(const Facet& facet, glm::dvec3 d) {
  const glm::dvec3 v = glm::normalize(d);
  return std::min({glm::dot(facet.edge_normal[0], v), glm::dot(facet.edge_normal[1], v),
                   glm::dot(facet.edge_normal[2], v)});
}

double lattice_error(const Warp& warp, const Facet& facet, const std::array<glm::dvec3, 3>& p,
                     double s_hint, int subdivisions, double stop_above) {
  double largest = 0;
  for (int i = 0; i <= subdivisions; ++i) {
    for (int j = 0; i + j <= subdivisions; ++j) {
      const int k = subdivisions - i - j;
      if (i == subdivisions || j == subdivisions || k == subdivisions)
        continue;  // corners are exact
      const glm::dvec3 X =
          (double(i) * p[0] + double(j) * p[1] + double(k) * p[2]) / double(subdivisions);
      const auto exact = warp.project(X, s_hint);
      if (!exact || !exact->covered) continue;
      const double distance = pixel_distance(warp, facet.project(X), exact->q);
      largest = std::max(largest, distance);
      if (largest > stop_above) return largest;
    }
  }
  return largest;
}

}  // namespace detail

namespace {

// Index of the interval of `breaks` holding x, clamped to the valid range.
int interval_of(const std::vector<double>& breaks, double x) {
  const auto it = std::upper_bound(breaks.begin(), breaks.end(), x);
  return std::clamp(int(it - breaks.begin()) - 1, 0, int(breaks.size()) - 2);
}

// Finds the facet containing a direction: the candidates near st, then the one whose pyramid
// holds the direction with the largest margin (facet edges are chords, so a direction near an
// edge in st may belong to the neighbour).
class FacetLocator {
 public:
  FacetLocator(const FacetMesh& mesh, bool wraps) : mesh_(mesh), wraps_(wraps) {
    if (!mesh.s_breaks.empty()) return;
    // Any other layout: buckets over st holding every facet whose padded st box meets them.
    const double count = std::max<double>(1, double(mesh.facets.size()) / 2);
    const double aspect = double(mesh.output_size.x) / std::max(1, mesh.output_size.y);
    buckets_ = {std::clamp(int(std::sqrt(count * aspect)), 1, 4096),
                std::clamp(int(std::sqrt(count / aspect)), 1, 4096)};
    bucket_facets_.resize(std::size_t(buckets_.x) * buckets_.y);
    for (std::uint32_t f = 0; f < mesh.facets.size(); ++f) {
      glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-lo);
      for (std::uint32_t v : mesh.facets[f].vertex) {
        lo = glm::min(lo, mesh.vertices[v].st);
        hi = glm::max(hi, mesh.vertices[v].st);
      }
      const glm::dvec2 pad = 0.25 * (hi - lo) + 0.5 / glm::dvec2(buckets_);
      const glm::ivec2 b0 = glm::ivec2(glm::floor((lo - pad) * glm::dvec2(buckets_)));
      const glm::ivec2 b1 = glm::ivec2(glm::floor((hi + pad) * glm::dvec2(buckets_)));
      for (int by = std::max(b0.y, 0); by <= std::min(b1.y, buckets_.y - 1); ++by) {
        for (int bx = b0.x; bx <= b1.x; ++bx) {
          int column = bx;
          if (wraps_) {
            column = ((bx % buckets_.x) + buckets_.x) % buckets_.x;
          } else if (bx < 0 || bx >= buckets_.x) {
            continue;
          }
          auto& list = bucket_facets_[std::size_t(by) * buckets_.x + column];
          if (list.empty() || list.back() != f) list.push_back(f);
        }
      }
    }
  }

  std::optional<std::uint32_t> find(glm::dvec2 st, glm::dvec3 d) const {
    std::optional<std::uint32_t> best;
    double best_margin = -1e-12;
    const auto consider = [&](std::uint32_t f) {
      const double margin = detail::inside_margin(mesh_.facets[f], d);
      if (margin > best_margin) {
        best_margin = margin;
        best = f;
      }
    };
    if (mesh_.s_breaks.empty()) {
      const glm::ivec2 b = glm::clamp(glm::ivec2(glm::floor(st * glm::dvec2(buckets_))),
                                      glm::ivec2(0), buckets_ - 1);
      for (std::uint32_t f : bucket_facets_[std::size_t(b.y) * buckets_.x + b.x]) consider(f);
      return best;
    }
    const int columns = int(mesh_.s_breaks.size()) - 1, rows = int(mesh_.t_breaks.size()) - 1;
    const int c0 = interval_of(mesh_.s_breaks, st.x), r0 = interval_of(mesh_.t_breaks, st.y);
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dc = -1; dc <= 1; ++dc) {
        int c = c0 + dc;
        const int r = r0 + dr;
        if (wraps_) c = (c + columns) % columns;
        if (c < 0 || c >= columns || r < 0 || r >= rows) continue;
        const std::uint32_t first = mesh_.cell_first_facet[std::size_t(r) * columns + c];
        if (first == UINT32_MAX) continue;
        consider(first);
        consider(first + 1);
      }
    }
    return best;
  }

 private:
  const FacetMesh& mesh_;
  bool wraps_;
  glm::ivec2 buckets_{1, 1};
  std::vector<std::vector<std::uint32_t>> bucket_facets_;
};

struct Accumulator {
  double max_px = 0, sum_squares = 0, float_max = 0, float_sum_squares = 0;
  std::size_t samples = 0, float_samples = 0, missed = 0;
  glm::dvec2 worst_q{0.0};

  void add(double distance, glm::dvec2 q) {
    if (distance > max_px) {
      max_px = distance;
      worst_q = q;
    }
    sum_squares += distance * distance;
    ++samples;
  }
  void add_float(double distance) {
    float_max = std::max(float_max, distance);
    float_sum_squares += distance * distance;
    ++float_samples;
  }
};

// What the GPU computes for the facet: float point, float matrix, float divide and viewport.
glm::dvec2 q_float32(const glm::mat4& clip_from_eye, glm::dvec3 X, glm::ivec2 size) {
  const glm::vec4 clip = clip_from_eye * glm::vec4(glm::vec3(X), 1.0f);
  const float x_ndc = clip.x / clip.w, y_ndc = clip.y / clip.w;
  return {(x_ndc + 1.0f) * 0.5f * float(size.x), (1.0f - y_ndc) * 0.5f * float(size.y)};
}

}  // namespace

double facet_max_error(const Warp& warp, const FacetMesh& mesh, std::uint32_t f, int subdivisions) {
  const auto p = mesh.corners(f);
  const double s_hint =
      (mesh.vertices[mesh.facets[f].vertex[0]].st.x + mesh.vertices[mesh.facets[f].vertex[1]].st.x +
       mesh.vertices[mesh.facets[f].vertex[2]].st.x) /
      3;
  return detail::lattice_error(warp, mesh.facets[f], p, s_hint, subdivisions);
}

FacetError evaluate_facet_error(const Warp& warp, const FacetMesh& mesh,
                                const FacetErrorOptions& options) {
  // Depth does not change x and y, so any near plane gives the same pixels.
  constexpr double kZNear = 0.01;
  std::vector<glm::mat4> clip_from_eye(mesh.facets.size());
  for (std::size_t f = 0; f < mesh.facets.size(); ++f) {
    clip_from_eye[f] = glm::mat4(mesh.facets[f].clip_from_eye(mesh.output_size, kZNear));
  }
  const FacetLocator locator(mesh, warp.base.wraps_horizontally());

  double per_axis = options.grid_samples_per_px;
  const double full = double(warp.output_size.x) * warp.output_size.y * per_axis * per_axis;
  if (full > double(options.max_grid_samples))
    per_axis *= std::sqrt(double(options.max_grid_samples) / full);
  const int nx = std::max(2, int(warp.output_size.x * per_axis));
  const int ny = std::max(2, int(warp.output_size.y * per_axis));

  std::vector<Accumulator> workers(detail::parallel_workers());
  detail::parallel_for(std::size_t(ny), [&](std::size_t j, std::size_t worker) {
    Accumulator& total = workers[worker];
    for (int i = 0; i < nx; ++i) {
      // Edges included: that is where coverage ends and errors often peak.
      const glm::dvec2 st{double(i) / (nx - 1), double(j) / (ny - 1)};
      if (warp.coverage_at(st) < 0.5) continue;
      const glm::dvec3 d = warp.p_eye_surface_from_st(st);
      const auto f = locator.find(st, d);
      if (!f) {
        ++total.missed;
        continue;
      }
      const glm::dvec2 q_exact = warp.q_from_st(st);
      const glm::dvec2 q_facet = mesh.facets[*f].project(d);
      total.add(detail::pixel_distance(warp, q_facet, q_exact), q_exact);
      total.add_float(glm::length(q_float32(clip_from_eye[*f], d, mesh.output_size) - q_facet));
    }
  });
  // The lattice inside every facet catches maxima the grid steps over.
  std::vector<double> facet_max(mesh.facets.size());
  detail::parallel_for(mesh.facets.size(), [&](std::size_t f, std::size_t) {
    facet_max[f] = facet_max_error(warp, mesh, std::uint32_t(f), options.facet_subdivisions);
  });

  FacetError result;
  Accumulator total;
  for (const auto& w : workers) {
    if (w.max_px > total.max_px) {
      total.max_px = w.max_px;
      total.worst_q = w.worst_q;
    }
    total.sum_squares += w.sum_squares;
    total.samples += w.samples;
    total.float_max = std::max(total.float_max, w.float_max);
    total.float_sum_squares += w.float_sum_squares;
    total.float_samples += w.float_samples;
    total.missed += w.missed;
  }
  result.max_px = total.max_px;
  result.worst_q = total.worst_q;
  for (double m : facet_max) result.max_px = std::max(result.max_px, m);
  result.rms_px = total.samples ? std::sqrt(total.sum_squares / double(total.samples)) : 0.0;
  result.float32_max_px = total.float_max;
  result.float32_rms_px =
      total.float_samples ? std::sqrt(total.float_sum_squares / double(total.float_samples)) : 0.0;
  result.samples = total.samples;
  result.missed_samples = total.missed;
  return result;
}

}  // namespace facet
