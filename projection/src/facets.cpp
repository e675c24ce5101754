#include "facet/projection/facets.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>

#include "facet/projection/errors.hpp"
#include "facet/projection/facet_error.hpp"
#include "facet/projection/parallel.hpp"
#include "facet/projection/warp.hpp"
#include "facets_internal.hpp"

namespace facet {

glm::dvec2 Facet::project(glm::dvec3 X) const {
  const glm::dvec3 homogeneous = M_q_eye * X;
  return glm::dvec2(homogeneous) / homogeneous.z;
}

glm::dmat4 Facet::clip_from_eye(glm::ivec2 output_size, double z_near) const {
  // glm is column-major: M[c][r]. Rows of M_q_eye are (qx·w, qy·w, w).
  auto row = [&](int r) { return glm::dvec3(M_q_eye[0][r], M_q_eye[1][r], M_q_eye[2][r]); };
  const glm::dvec3 row_x = (2.0 / output_size.x) * row(0) - row(2);
  const glm::dvec3 row_y = row(2) - (2.0 / output_size.y) * row(1);
  const glm::dvec3 row_w = row(2);
  glm::dmat4 clip(0.0);
  for (int c = 0; c < 3; ++c) {
    clip[c][0] = row_x[c];
    clip[c][1] = row_y[c];
    clip[c][3] = row_w[c];
  }
  clip[3][2] = z_near;
  return clip;
}

std::array<glm::dvec3, 3> FacetMesh::corners(std::uint32_t f) const {
  const Facet& facet = facets[f];
  return {vertices[facet.vertex[0]].p_eye, vertices[facet.vertex[1]].p_eye,
          vertices[facet.vertex[2]].p_eye};
}

std::array<glm::dvec3, 3> FacetMesh::clip_planes(std::uint32_t f, double guard_px) const {
  const auto p = detail::guarded_corners(*this, f, guard_px);
  std::array<glm::dvec3, 3> planes;
  for (int k = 0; k < 3; ++k) planes[k] = glm::normalize(glm::cross(p[k], p[(k + 1) % 3]));
  return planes;
}

namespace detail {

std::array<glm::dvec3, 3> guarded_corners(const FacetMesh& mesh, std::uint32_t f, double guard_px) {
  const Facet& facet = mesh.facets[f];
  std::array<glm::dvec3, 3> p = mesh.corners(f);
  if (guard_px <= 0) return p;
  // On the chord plane the facet's projection is affine, so a scaling there is the same scaling
  // in q. Scaling about the incentre by (r + guard) / r, r the inradius in q, moves every edge
  // outwards by exactly guard_px. (About the centroid, the scale that moved the farthest edge by
  // guard_px moved the long edges of a thin facet by a few thousandths of a pixel, less than the
  // rasterizer's subpixel snapping: pixel centres on such a seam were drawn by neither facet.)
  std::array<glm::dvec2, 3> q;
  for (int k = 0; k < 3; ++k) q[k] = mesh.vertices[facet.vertex[k]].q;
  const double twice_area =
      std::abs((q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x));
  std::array<double, 3> opposite_edge;
  for (int k = 0; k < 3; ++k) opposite_edge[k] = glm::length(q[(k + 2) % 3] - q[(k + 1) % 3]);
  const double perimeter = opposite_edge[0] + opposite_edge[1] + opposite_edge[2];
  if (!(twice_area > 0 && perimeter > 0)) return p;
  const double inradius = twice_area / perimeter;
  const double scale = 1 + guard_px / inradius;
  const glm::dvec3 incentre =
      (opposite_edge[0] * p[0] + opposite_edge[1] * p[1] + opposite_edge[2] * p[2]) / perimeter;
  for (auto& corner : p) corner = incentre + scale * (corner - incentre);
  return p;
}

std::optional<Facet> make_facet(const FacetVertex& a, const FacetVertex& b, const FacetVertex& c) {
  std::array<const FacetVertex*, 3> v{&a, &b, &c};
  glm::dvec3 n = glm::cross(b.p_eye - a.p_eye, c.p_eye - a.p_eye);
  const double n_length = glm::length(n);
  const double scale = std::max({glm::length(a.p_eye), glm::length(b.p_eye), glm::length(c.p_eye)});
  if (!(n_length > 1e-14 * scale * scale)) return std::nullopt;
  n /= n_length;
  double h = glm::dot(n, a.p_eye);
  if (h < 0) {
    n = -n;
    h = -h;
  }
  // A chord plane through (or almost through) the eye means the facet spans about 180°.
  if (!(h > 1e-9 * scale)) return std::nullopt;
  // Order the corners so that the edge planes' normals cross(p_k, p_k+1) point inwards.
  if (glm::dot(glm::cross(v[0]->p_eye, v[1]->p_eye), v[2]->p_eye) < 0) std::swap(v[1], v[2]);

  Facet facet;
  const glm::dmat3 D(v[0]->p_eye, v[1]->p_eye, v[2]->p_eye);  // corners as columns
  const glm::dmat3 D_inverse = glm::inverse(D);
  // Rows of H are (qx·h, qy·h, h) at each corner; M = H·D⁻¹ maps every corner exactly.
  glm::dmat3 H;
  for (int k = 0; k < 3; ++k) H[k] = glm::dvec3(v[k]->q * h, h);
  facet.M_q_eye = H * D_inverse;
  // Its last row equals n exactly in exact arithmetic; use n itself so that w = n·X.
  for (int col = 0; col < 3; ++col) facet.M_q_eye[col][2] = n[col];
  facet.n = n;
  facet.h = h;
  for (int k = 0; k < 3; ++k) {
    facet.edge_normal[k] = glm::normalize(glm::cross(v[k]->p_eye, v[(k + 1) % 3]->p_eye));
  }
  // Remember the order chosen, as offsets 0..2 into the caller's (a, b, c).
  facet.vertex = {0, v[1] == &b ? 1u : 2u, v[1] == &b ? 2u : 1u};
  return facet;
}

FacetVertex vertex_at(const Warp& warp, glm::dvec2 st) {
  return {warp.p_eye_surface_from_st(st), st, warp.q_from_st(st)};
}

double angle_between(glm::dvec3 a, glm::dvec3 b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

void append_node_lines(double a, double b, int nodes, std::vector<double>& values) {
  for (int i = int(std::ceil(a * (nodes - 1))); i <= int(std::floor(b * (nodes - 1))); ++i) {
    values.push_back(double(i) / (nodes - 1));
  }
}

double max_coverage(const Warp& warp, double s0, double s1, double t0, double t1) {
  std::vector<double> s_values{s0, s1}, t_values{t0, t1};
  append_node_lines(s0, s1, warp.grid_size.x, s_values);
  append_node_lines(t0, t1, warp.grid_size.y, t_values);
  double best = 0;
  for (double s : s_values) {
    for (double t : t_values) best = std::max(best, warp.coverage_at({s, t}));
  }
  return best;
}

}  // namespace detail

namespace {

using detail::make_facet;

using detail::angle_between;
using detail::append_node_lines;
using detail::kBuildMargin;
using detail::kBuildSubdivisions;
using detail::kMaxFacetAngle;
using detail::kPi;
using detail::max_coverage;
using detail::vertex_at;

// A pixel figure for messages: 0.25, 1e-09 (std::to_string would say 0.250000, 0.000000).
std::string px_figure(double px) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", px);
  return text;
}

struct Cell {
  std::array<FacetVertex, 4> corner;  // (s0,t0) (s1,t0) (s0,t1) (s1,t1)
  std::array<Facet, 2> facet;
  std::array<std::array<int, 3>, 2> corner_of;  // which corners each facet uses, in its order
  double error = 0;
};

// The largest angle between cell corners: the cell's two diagonals and four sides.
double cell_angle(const std::array<FacetVertex, 4>& c) {
  double largest = 0;
  for (auto [a, b] : {std::pair{0, 1}, {0, 2}, {1, 3}, {2, 3}, {0, 3}, {1, 2}}) {
    largest = std::max(largest, angle_between(c[a].p_eye, c[b].p_eye));
  }
  return largest;
}

// Largest error over a lattice of the cell's st rectangle, its edges included: the facets' own
// lattices sample the chord triangles and miss where coverage ends at the image edge, which is
// where a cylinder's error peaks. Each sample is compared with whichever facet holds it.
double st_lattice_error(const Warp& warp, const std::array<Facet, 2>& facets, double s0, double s1,
                        double t0, double t1, int subdivisions, double stop_above) {
  // Offsets are bilinear between nodes, so the error often peaks on node lines: sample those too.
  auto positions = [subdivisions](double a, double b, int nodes) {
    std::vector<double> values;
    for (int k = 0; k <= subdivisions; ++k) values.push_back(a + (b - a) * k / subdivisions);
    append_node_lines(a, b, nodes, values);
    return values;
  };
  const auto s_values = positions(s0, s1, warp.grid_size.x);
  const auto t_values = positions(t0, t1, warp.grid_size.y);
  double largest = 0;
  for (double t : t_values) {
    for (double s : s_values) {
      const glm::dvec2 st{s, t};
      if (warp.coverage_at(st) < 0.5) continue;
      const glm::dvec3 p = warp.p_eye_surface_from_st(st);
      const Facet& facet =
          detail::inside_margin(facets[0], p) >= detail::inside_margin(facets[1], p) ? facets[0]
                                                                                     : facets[1];
      largest =
          std::max(largest, detail::pixel_distance(warp, facet.project(p), warp.q_from_st(st)));
      if (largest > stop_above) return largest;
    }
  }
  return largest;
}

// Splits the cell into two facets along the diagonal that fits better, or along the first one
// whose error is at most good_enough. nullopt for a degenerate cell (a facet through the eye).
std::optional<Cell> fit_cell(const Warp& warp, double s0, double s1, double t0, double t1,
                             int subdivisions, double good_enough = 0) {
  Cell cell;
  cell.corner = {vertex_at(warp, {s0, t0}), vertex_at(warp, {s1, t0}), vertex_at(warp, {s0, t1}),
                 vertex_at(warp, {s1, t1})};
  const double s_hint = (s0 + s1) / 2;
  static constexpr int kDiagonals[2][2][3] = {{{0, 1, 3}, {0, 3, 2}}, {{0, 1, 2}, {1, 3, 2}}};
  double best_error = std::numeric_limits<double>::infinity();
  bool any = false;
  for (const auto& diagonal : kDiagonals) {
    std::array<Facet, 2> facets;
    std::array<std::array<int, 3>, 2> corner_of;
    double error = 0;
    bool ok = true;
    for (int k = 0; k < 2 && ok; ++k) {
      const int* c = diagonal[k];
      auto facet = make_facet(cell.corner[c[0]], cell.corner[c[1]], cell.corner[c[2]]);
      if (!facet) {
        ok = false;
        break;
      }
      for (int m = 0; m < 3; ++m) corner_of[k][m] = c[facet->vertex[m]];
      facets[k] = *facet;
      const std::array<glm::dvec3, 3> p{cell.corner[corner_of[k][0]].p_eye,
                                        cell.corner[corner_of[k][1]].p_eye,
                                        cell.corner[corner_of[k][2]].p_eye};
      error = std::max(error,
                       detail::lattice_error(warp, facets[k], p, s_hint, subdivisions, best_error));
    }
    if (ok && error < best_error) {
      error =
          std::max(error, st_lattice_error(warp, facets, s0, s1, t0, t1, subdivisions, best_error));
    }
    if (ok && error < best_error) {
      best_error = error;
      cell.facet = facets;
      cell.corner_of = corner_of;
      any = true;
      if (best_error <= good_enough) break;
    }
  }
  if (!any) return std::nullopt;
  cell.error = best_error;
  return cell;
}

std::vector<double> uniform_breaks(int count) {
  std::vector<double> breaks(count + 1);
  for (int k = 0; k <= count; ++k) breaks[k] = double(k) / count;
  return breaks;
}

// Builds the tensor-product layout and facet list from breaks.
FacetMesh assemble(const Warp& warp, std::vector<double> s_breaks, std::vector<double> t_breaks,
                   int subdivisions) {
  FacetMesh mesh;
  mesh.output_size = warp.output_size;
  const int columns = int(s_breaks.size()) - 1, rows = int(t_breaks.size()) - 1;
  for (double t : t_breaks) {
    for (double s : s_breaks) mesh.vertices.push_back(vertex_at(warp, {s, t}));
  }
  auto vertex_index = [&](int c, int r) { return std::uint32_t(r * (columns + 1) + c); };
  mesh.cell_first_facet.assign(std::size_t(columns) * rows, UINT32_MAX);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      const double s0 = s_breaks[c], s1 = s_breaks[c + 1], t0 = t_breaks[r], t1 = t_breaks[r + 1];
      if (max_coverage(warp, s0, s1, t0, t1) < 0.5) continue;
      const double angle = cell_angle({vertex_at(warp, {s0, t0}), vertex_at(warp, {s1, t0}),
                                       vertex_at(warp, {s0, t1}), vertex_at(warp, {s1, t1})});
      auto cell =
          angle <= kMaxFacetAngle ? fit_cell(warp, s0, s1, t0, t1, subdivisions) : std::nullopt;
      if (!cell) {
        throw InputError({}, "facets",
                         "a facet would span " +
                             std::to_string(int(std::round(angle * 180 / kPi))) +
                             "°, and at most 150° is allowed; use more pieces");
      }
      const std::uint32_t corner_vertex[4] = {vertex_index(c, r), vertex_index(c + 1, r),
                                              vertex_index(c, r + 1), vertex_index(c + 1, r + 1)};
      mesh.cell_first_facet[std::size_t(r) * columns + c] = std::uint32_t(mesh.facets.size());
      for (int k = 0; k < 2; ++k) {
        Facet facet = cell->facet[k];
        for (int m = 0; m < 3; ++m) facet.vertex[m] = corner_vertex[cell->corner_of[k][m]];
        mesh.facets.push_back(facet);
      }
    }
  }
  mesh.s_breaks = std::move(s_breaks);
  mesh.t_breaks = std::move(t_breaks);
  return mesh;
}

// Fits breaks along one axis of the tensor grid so that every cell meets the tolerance, with as
// few breaks as a greedy sweep finds (optimal in one dimension when the error grows with the
// interval).
class GridFitter {
 public:
  GridFitter(const Warp& warp, double tolerance_px, int max_cells)
      : warp_(warp), tolerance_px_(tolerance_px), max_cells_(max_cells) {}

  // Breaks along `axis` (0: s, 1: t) given the breaks of the other axis, with every cell's error
  // at most `share` of the build tolerance.
  std::vector<double> sweep(int axis, const std::vector<double>& other, double share) const {
    std::vector<double> breaks{0.0};
    double start = 0, previous_width = 0;
    const double min_width = 1e-7;
    while (start < 1) {
      if (fits(axis, start, 1.0, other, share)) {
        breaks.push_back(1.0);
        break;
      }
      // Bracket the widest interval that fits, starting from the previous width (neighbouring
      // intervals need about the same), then bisect to within 0.5% of the width: a finer search
      // buys no facets.
      double lo = start, hi = 1.0;
      double guess = std::min(1.0, start + std::max(previous_width, min_width));
      if (fits(axis, start, guess, other, share)) {
        lo = guess;
        for (double width = guess - start; lo < 1.0;) {
          width *= 1.25;
          const double next = std::min(1.0, start + width);
          if (!fits(axis, start, next, other, share)) {
            hi = next;
            break;
          }
          lo = next;
        }
      } else {
        hi = guess;
      }
      while (hi - lo > std::max(5e-3 * (lo - start), min_width / 4)) {
        const double mid = (lo + hi) / 2;
        (fits(axis, start, mid, other, share) ? lo : hi) = mid;
      }
      if (lo - start < min_width) {
        throw InputError({}, "tolerance",
                         "the warp changes too fast near " + std::string(axis == 0 ? "s" : "t") +
                             " = " + std::to_string(start) + " for facets to meet " +
                             px_figure(tolerance_px_) + " px");
      }
      breaks.push_back(lo);
      previous_width = lo - start;
      start = lo;
      if (breaks.size() * other.size() > std::size_t(max_cells_)) {
        throw InputError({}, "tolerance",
                         "meeting " + px_figure(tolerance_px_) + " px needs more than " +
                             std::to_string(max_cells_) + " cells; a larger tolerance needs fewer");
      }
    }
    // A uniform spacing with the same count spreads the slack evenly; keep it when it fits.
    const int count = int(breaks.size()) - 1;
    auto uniform = uniform_breaks(count);
    bool uniform_fits = true;
    for (int k = 0; k < count && uniform_fits; ++k) {
      uniform_fits = fits(axis, uniform[k], uniform[k + 1], other, share);
    }
    return uniform_fits ? uniform : breaks;
  }

  // The smallest uniform grid, with cells of about equal angular size, whose cells all have errors
  // of at most `share` of the build tolerance.
  std::pair<std::vector<double>, std::vector<double>> uniform_start(double share) const {
    const double angle_s = extent(0), angle_t = extent(1);
    auto grid = [&](int k) {
      const double unit = std::max(angle_s, angle_t) / k;
      return std::pair{uniform_breaks(std::max(1, int(std::ceil(angle_s / unit)))),
                       uniform_breaks(std::max(1, int(std::ceil(angle_t / unit))))};
    };
    auto grid_fits = [&](int k) {
      const auto [s_breaks, t_breaks] = grid(k);
      for (std::size_t c = 0; c + 1 < s_breaks.size(); ++c) {
        if (!fits(0, s_breaks[c], s_breaks[c + 1], t_breaks, share)) return false;
      }
      return true;
    };
    if (grid_fits(1)) return grid(1);
    int lo = 1, hi = 2;
    while (!grid_fits(hi)) {
      lo = hi;
      hi *= 2;
      const auto [s_breaks, t_breaks] = grid(hi);
      if ((s_breaks.size() - 1) * (t_breaks.size() - 1) > std::size_t(max_cells_)) {
        throw InputError({}, "tolerance",
                         "meeting " + px_figure(tolerance_px_) + " px needs more than " +
                             std::to_string(max_cells_) + " cells; a larger tolerance needs fewer");
      }
    }
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      (grid_fits(mid) ? hi : lo) = mid;
    }
    return grid(hi);
  }

 private:
  // The largest angle swept along an axis, over a few lines across the other axis.
  double extent(int axis) const {
    double largest = 0;
    const int samples = 64;
    for (int across = 0; across <= 4; ++across) {
      const double other = across / 4.0;
      double total = 0;
      for (int k = 0; k < samples; ++k) {
        auto st = [&](double x) { return axis == 0 ? glm::dvec2(x, other) : glm::dvec2(other, x); };
        total += angle_between(warp_.v_eye_from_st(st(double(k) / samples)),
                               warp_.v_eye_from_st(st(double(k + 1) / samples)));
      }
      largest = std::max(largest, total);
    }
    return largest;
  }

  bool fits(int axis, double a, double b, const std::vector<double>& other, double share) const {
    const double limit = tolerance_px_ * kBuildMargin * share;
    std::atomic<bool> all_fit{true};
    detail::parallel_for(other.size() - 1, [&](std::size_t k, std::size_t) {
      if (!all_fit.load(std::memory_order_relaxed)) return;
      const double s0 = axis == 0 ? a : other[k], s1 = axis == 0 ? b : other[k + 1];
      const double t0 = axis == 0 ? other[k] : a, t1 = axis == 0 ? other[k + 1] : b;
      if (max_coverage(warp_, s0, s1, t0, t1) < 0.5) return;
      auto cell = fit_cell(warp_, s0, s1, t0, t1, kBuildSubdivisions, limit);
      if (!cell || cell_angle(cell->corner) > kMaxFacetAngle || !(cell->error <= limit)) {
        all_fit = false;
      }
    });
    return all_fit;
  }

  const Warp& warp_;
  double tolerance_px_;
  int max_cells_;
};

// The tolerance layout with per-cell targets `tolerance`: start from the smallest uniform grid
// with some slack, then let each axis in turn take the slack with a greedy sweep, keeping the
// layout with the fewest cells. Each sweep may use more of the tolerance than the one before, so
// that it has room to move.
FacetMesh build_tolerance_layout(const Warp& warp, double tolerance, int max_cells) {
  GridFitter fitter(warp, tolerance, max_cells);
  auto [s_breaks, t_breaks] = fitter.uniform_start(0.8);
  auto cells = [](const std::vector<double>& s, const std::vector<double>& t) {
    return (s.size() - 1) * (t.size() - 1);
  };
  auto s_next = s_breaks, t_next = t_breaks;
  for (auto [axis, share] : {std::pair{0, 0.9}, {1, 1.0}, {0, 1.0}}) {
    try {
      if (axis == 0) {
        s_next = fitter.sweep(0, t_next, share);
      } else {
        t_next = fitter.sweep(1, s_next, share);
      }
    } catch (const InputError&) {
      break;  // this axis has no slack left; keep the best layout so far
    }
    if (cells(s_next, t_next) < cells(s_breaks, t_breaks)) {
      s_breaks = s_next;
      t_breaks = t_next;
    }
  }
  if (cells(s_breaks, t_breaks) > std::size_t(max_cells)) {
    throw InputError({}, "tolerance",
                     "meeting " + px_figure(tolerance) + " px needs more than " +
                         std::to_string(max_cells) + " cells; a larger tolerance needs fewer");
  }
  return assemble(warp, std::move(s_breaks), std::move(t_breaks), kBuildSubdivisions);
}

// Of the two tolerance layouts, the one with fewer facets. A tensor-product grid suits warps whose
// difficulty lines up with the base image's axes (a cylinder's strips are exact along their
// height); bisection suits warps that are hard to follow in one place only (a spherical mirror's
// crowded rim). Bisection is built first because it is quick; the tensor grid then gets a cell
// budget of four times bisection's facet count (its uniform start and first sweep pass through
// layouts several times larger than its result) and gives up past it.
FacetMesh build_fewest_facets(const Warp& warp, double target, int max_cells) {
  std::optional<FacetMesh> adaptive;
  try {
    adaptive = detail::build_adaptive_layout(warp, target, max_cells);
  } catch (const InputError&) {
    // The tensor grid may still meet the target; if not, its error is the one reported.
  }
  const int tensor_cells =
      adaptive ? int(std::min<std::size_t>(max_cells, 4 * adaptive->facets.size())) : max_cells;
  try {
    FacetMesh tensor = build_tolerance_layout(warp, target, tensor_cells);
    if (!adaptive || tensor.facets.size() <= adaptive->facets.size()) return tensor;
  } catch (const InputError&) {
    if (!adaptive) throw;
  }
  return std::move(*adaptive);
}

// The layout `builder` makes for a per-cell target of `target` px.
FacetMesh build_layout(const Warp& warp, FacetTolerance::Builder builder, double target,
                       int max_cells) {
  switch (builder) {
    case FacetTolerance::Builder::tensor:
      return build_tolerance_layout(warp, target, max_cells);
    case FacetTolerance::Builder::bisection:
      return detail::build_adaptive_layout(warp, target, max_cells);
    case FacetTolerance::Builder::fewest:
      break;
  }
  return build_fewest_facets(warp, target, max_cells);
}

// A figure rounded up to two significant digits, for "set it to at least ...".
double round_up_2(double x) {
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 1);
  return std::ceil(x / unit * (1 - 1e-12)) * unit;
}

// The tolerance layout of build_facets; InputErrors say field "tolerance" and no source.
FacetMesh build_to_tolerance(const Warp& warp, const FacetBuildOptions& options) {
  const FacetTolerance& layout = std::get<FacetTolerance>(options.layout);
  const double tolerance = layout.px;
  // Past the largest image side a tolerance bounds nothing (1e308 px built the coarsest layout).
  if (!(tolerance > 0 && tolerance <= kMaxImageSide)) {
    throw InputError({}, "tolerance", "expected a number of pixels in (0, 16384]");
  }
  if (!(options.near_miss >= 0) || !std::isfinite(options.near_miss)) {
    throw InputError({}, "near_miss", "expected a fraction >= 0");
  }
  // Below kProbePx / 10 a tolerance is first checked against an estimate of the cells it needs,
  // from a build at kProbePx by the same builder: a cell's error grows as the square of its size
  // where the warp curves both ways, so its cells grow at most about as 1/tolerance. One that
  // would need more than twice max_cells is refused before building (1e-9 px took 13 s and
  // 2.7 GB to give up on the dome, and 20 s on the calibrated board, whose tensor grid cannot
  // meet 1 px where bisection can).
  constexpr double kProbePx = 1.0;
  std::optional<double> probe_cells;
  if (tolerance < 0.1 * kProbePx) {
    try {
      probe_cells =
          double(build_layout(warp, layout.builder, kProbePx, options.max_cells).facets.size()) / 2;
    } catch (const InputError&) {
      // No estimate: the build below reports what it cannot meet.
    }
  }
  if (probe_cells) {
    const double estimate = *probe_cells * kProbePx / tolerance;
    if (estimate > 2.0 * options.max_cells) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "a tolerance the facets can meet with at most %d cells; %g px needs about "
                    "%.3g (%g at %g px)",
                    options.max_cells, tolerance, estimate, *probe_cells, kProbePx);
      throw InputError({}, "tolerance", text);
    }
  }
  // The per-cell checks sample each cell alone; the mesh is then measured as a whole, as
  // evaluate_facet_error measures it (every covered direction against the facet that holds it,
  // which near a cell's edge may be its neighbour's). Where that exceeds the tolerance (a warp
  // with a kink, such as a folded node masked by an import), the build is repeated with the
  // cells' target scaled down by the overshoot, twice at most (a retry whose finer target cannot
  // be built ends the tries). The try with the smallest worst error is then kept when it misses
  // by at most near_miss; beyond, the build gives up rather than return facets that break the
  // tolerance.
  double target = tolerance;
  std::optional<FacetMesh> best;
  FacetError best_error;
  for (int attempt = 0; attempt < 3; ++attempt) {
    FacetMesh mesh;
    try {
      mesh = build_layout(warp, layout.builder, target, options.max_cells);
    } catch (const InputError&) {
      if (!best) throw;
      break;  // a retry's finer target cannot be built: judge the tries so far
    }
    const FacetError measured = evaluate_facet_error(warp, mesh);
    if (measured.max_px <= tolerance) return mesh;
    if (!best || measured.max_px < best_error.max_px) {
      best = std::move(mesh);
      best_error = measured;
    }
    target *= 0.9 * tolerance / measured.max_px;
  }
  const double reached = best_error.max_px;
  const std::string where = "(" + std::to_string(int(std::floor(best_error.worst_q.x))) + ", " +
                            std::to_string(int(std::floor(best_error.worst_q.y))) + ")";
  char text[400];
  if (reached <= tolerance * (1 + options.near_miss)) {
    best->tolerance_miss = FacetToleranceMiss{tolerance, reached, best_error.worst_q};
    if (options.warn) {
      const FacetToleranceOrigin& origin = options.origin;
      std::snprintf(text, sizeof text,
                    "%s: field '%s': %s%g px not met: the facets reach %.3g px (%.1f%% over, "
                    "within the %g%% accepted) at output pixel %s; rendering with them (they meet "
                    "%g px)",
                    origin.source.empty() ? "input" : origin.source.c_str(),
                    origin.field.name().c_str(),
                    origin.output.empty() ? "" : ("output '" + origin.output + "': ").c_str(),
                    tolerance, reached, 100 * (reached / tolerance - 1), 100 * options.near_miss,
                    where.c_str(), round_up_2(reached));
      options.warn(text);
    }
    return std::move(*best);
  }
  std::snprintf(text, sizeof text,
                "the facets built for %g px still reach %.3g px (%.1f%% over) at output pixel "
                "%s: the warp is not smooth enough there; set it to %g px or more",
                tolerance, reached, 100 * (reached / tolerance - 1), where.c_str(),
                round_up_2(reached));
  throw InputError({}, "tolerance", text);
}

}  // namespace

FacetMesh build_facets(const Warp& warp, const FacetBuildOptions& options) {
  warp.validate();
  if (const auto* strips = std::get_if<FacetStrips>(&options.layout)) {
    if (strips->count < 1) throw InputError({}, "pieces", "expected at least 1 strip");
    if (strips->count > options.max_cells)
      throw InputError({}, "pieces",
                       "at most " + std::to_string(options.max_cells) + " strips; got " +
                           std::to_string(strips->count));
    return assemble(warp, uniform_breaks(strips->count), uniform_breaks(1), kBuildSubdivisions);
  }
  if (const auto* grid = std::get_if<FacetGrid>(&options.layout)) {
    if (grid->columns < 1 || grid->rows < 1) {
      throw InputError({}, "grid", "expected at least 1×1 cells");
    }
    if (std::int64_t(grid->columns) * grid->rows > options.max_cells) {
      throw InputError({}, "grid",
                       "at most " + std::to_string(options.max_cells) + " cells; got " +
                           std::to_string(grid->columns) + "x" + std::to_string(grid->rows));
    }
    return assemble(warp, uniform_breaks(grid->columns), uniform_breaks(grid->rows),
                    kBuildSubdivisions);
  }
  // The tolerance layout's own errors say "tolerance"; they are the field the tolerance came from.
  try {
    return build_to_tolerance(warp, options);
  } catch (const InputError& error) {
    if (error.field() != "tolerance" || !error.source().empty()) throw;
    const std::string& output = options.origin.output;
    throw InputError(options.origin.source, options.origin.field,
                     (output.empty() ? "" : "for output '" + output + "', ") + error.expected());
  }
}

}  // namespace facet
