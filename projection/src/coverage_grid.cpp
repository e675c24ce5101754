#include "facet/projection/coverage_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;
// Within this angle of a pole, a box takes every azimuth and reaches the pole.
constexpr double kPoleMargin = 1e-3;
// Arcs whose corner directions have |u_i × u_j| below this are short (or nearly opposite, which
// the walk takes): their interior extreme is bounded by the chord instead.
constexpr double kShortArc = 1e-2;
constexpr std::uint32_t kMaxGridSide = 4096;
constexpr std::uint32_t kMaxGridBuckets = 1u << 20;

struct ChartFrame {
  glm::dvec3 axis, e1, e2;  // φ = atan2(b·e2, b·e1)
};

bool polar(CoverageChart chart) {
  return chart == CoverageChart::cylindrical || chart == CoverageChart::equirectangular;
}

ChartFrame chart_frame(CoverageChart chart) {
  if (polar(chart)) return {{0, 1, 0}, {0, 0, -1}, {1, 0, 0}};
  return {{0, 0, -1}, {1, 0, 0}, {0, 1, 0}};
}

double wrap_pi(double angle) { return std::remainder(angle, 2 * kPi); }

// Chart coordinates (p, q) of a unit base-frame direction.
glm::dvec2 chart_point(const glm::dvec3& b, CoverageChart chart) {
  const ChartFrame frame = chart_frame(chart);
  const double sin_theta = glm::length(glm::cross(b, frame.axis));
  const double theta = std::atan2(sin_theta, glm::dot(b, frame.axis));
  const double x = glm::dot(b, frame.e1), y = glm::dot(b, frame.e2);
  switch (chart) {
    case CoverageChart::cylindrical:
      return {std::atan2(y, x), std::cos(theta) / std::max(std::sin(theta), 1e-6)};
    case CoverageChart::equirectangular:
      return {std::atan2(y, x), kPi / 2 - theta};
    case CoverageChart::fisheye: {
      const double scale = sin_theta > 1e-12 ? theta / sin_theta : 1.0;
      return {scale * x, scale * y};
    }
    case CoverageChart::perspective:
      return {x / -b.z, y / -b.z};
  }
  return {0, 0};
}

// Cells meeting [lo, hi] among those between ascending breaks: first and last index, or
// nullopt.
std::optional<std::pair<std::uint32_t, std::uint32_t>> cells_between(
    const std::vector<double>& breaks, double lo, double hi) {
  const std::size_t cells = breaks.size() - 1;
  if (hi < breaks.front() || lo > breaks.back()) return std::nullopt;
  const auto first = std::lower_bound(breaks.begin(), breaks.end(), lo) - breaks.begin();
  const auto last = std::upper_bound(breaks.begin(), breaks.end(), hi) - breaks.begin();
  return std::pair{
      std::uint32_t(std::clamp<std::ptrdiff_t>(first - 1, 0, std::ptrdiff_t(cells) - 1)),
      std::uint32_t(std::clamp<std::ptrdiff_t>(last - 1, 0, std::ptrdiff_t(cells) - 1))};
}

}  // namespace

CoverageChart coverage_chart(BaseKind kind) {
  switch (kind) {
    case BaseKind::cylindrical:
      return CoverageChart::cylindrical;
    case BaseKind::equirectangular:
      return CoverageChart::equirectangular;
    case BaseKind::fisheye:
      return CoverageChart::fisheye;
    case BaseKind::perspective:
      return CoverageChart::perspective;
  }
  return CoverageChart::perspective;
}

DirectionBox CoverageGrid::direction_box(const std::array<glm::dvec3, 3>& u, CoverageChart chart,
                                         double pad) {
  const ChartFrame frame = chart_frame(chart);
  const glm::dvec3 A = frame.axis;
  DirectionBox box;
  double theta[3], phi[3], sin_theta[3];
  for (int c = 0; c < 3; ++c) {
    sin_theta[c] = glm::length(glm::cross(u[c], A));
    theta[c] = std::atan2(sin_theta[c], glm::dot(u[c], A));
    phi[c] = std::atan2(glm::dot(u[c], frame.e2), glm::dot(u[c], frame.e1));
  }
  const double vertex_pad = 1e-6 + pad;
  double lo = std::min({theta[0], theta[1], theta[2]}) - vertex_pad;
  double hi = std::max({theta[0], theta[1], theta[2]}) + vertex_pad;
  for (int i = 0; i < 3; ++i) {
    const int j = i < 2 ? i + 1 : 0;
    glm::dvec3 n = glm::cross(u[i], u[j]);
    const double length = glm::length(n);
    if (length < kShortArc) {
      if (glm::dot(u[i], u[j]) < 0) {
        box.walk = true;
        return box;
      }
      const double chord = glm::length(u[i] - u[j]);
      lo = std::min(lo, std::min(theta[i], theta[j]) - chord - vertex_pad);
      hi = std::max(hi, std::max(theta[i], theta[j]) + chord + vertex_pad);
      continue;
    }
    n /= length;
    // The arc's great circle comes nearest the axis at p (and farthest at −p), at the angle
    // atan2(|A·n|, |A × n|); that extreme counts when p lies on the arc.
    const double an = glm::dot(A, n);
    const glm::dvec3 p = A - an * n;
    const double circle_min = std::atan2(std::abs(an), glm::length(glm::cross(A, n)));
    const double arc_pad = 4e-7 / length + vertex_pad;
    const double on = -1e-6;
    if (glm::dot(glm::cross(u[i], p), n) >= on && glm::dot(glm::cross(p, u[j]), n) >= on)
      lo = std::min(lo, circle_min - arc_pad);
    if (glm::dot(glm::cross(u[i], -p), n) >= on && glm::dot(glm::cross(-p, u[j]), n) >= on)
      hi = std::max(hi, kPi - circle_min + arc_pad);
  }
  // Each arc turns by less than π about the axis, so its azimuth change is the wrapped
  // difference; around the loop they add up to ±2π exactly when a pole is inside.
  const double d01 = wrap_pi(phi[1] - phi[0]), d12 = wrap_pi(phi[2] - phi[1]),
               d20 = wrap_pi(phi[0] - phi[2]);
  const double winding = d01 + d12 + d20;
  if (!(std::abs(winding) < 0.5 || std::abs(std::abs(winding) - 2 * kPi) < 0.5)) {
    box.walk = true;
    return box;
  }
  if (std::abs(winding) > kPi) {
    // The triangle's cone lies on one side of its corners' plane: that side's pole is inside.
    const glm::dvec3 normal = glm::cross(u[1] - u[0], u[2] - u[0]);
    if (glm::dot(A, normal) * glm::dot(normal, u[0]) > 0)
      lo = 0;
    else
      hi = kPi;
    box.full_phi = true;
  }
  if (lo < kPoleMargin) {
    lo = 0;
    box.full_phi = true;
  }
  if (hi > kPi - kPoleMargin) {
    hi = kPi;
    box.full_phi = true;
  }
  box.theta_lo = lo;
  box.theta_hi = hi;
  if (!box.full_phi) {
    const double c1 = d01, c2 = d01 + d12;
    const double min_sin = std::min({sin_theta[0], sin_theta[1], sin_theta[2]});
    const double phi_pad = (pad + 4e-7) / std::max(min_sin, 1e-9) + 1e-6;
    box.phi_lo = phi[0] + std::min({0.0, c1, c2}) - phi_pad;
    box.phi_hi = phi[0] + std::max({0.0, c1, c2}) + phi_pad;
    if (box.phi_hi - box.phi_lo >= 2 * kPi) box.full_phi = true;
  }
  if (box.full_phi) {
    box.phi_lo = -kPi;
    box.phi_hi = kPi;
  }
  return box;
}

std::optional<ChartBox> CoverageGrid::gnomonic_box(const std::array<glm::dvec3, 3>& u) const {
  if (chart_ != CoverageChart::perspective) return std::nullopt;
  ChartBox box;
  box.p_lo = box.q_lo = std::numeric_limits<double>::infinity();
  box.p_hi = box.q_hi = -std::numeric_limits<double>::infinity();
  double largest_squared = 0;
  for (const glm::dvec3& b : u) {
    if (!(-b.z > kGnomonicMinDepth)) return std::nullopt;
    const glm::dvec2 c = glm::dvec2(b.x, b.y) / -b.z;
    box.p_lo = std::min(box.p_lo, c.x);
    box.p_hi = std::max(box.p_hi, c.x);
    box.q_lo = std::min(box.q_lo, c.y);
    box.q_hi = std::max(box.q_hi, c.y);
    largest_squared = std::max(largest_squared, glm::dot(c, c));
  }
  const double pad = kGnomonicPad * (1 + largest_squared);
  box.p_lo -= pad;
  box.p_hi += pad;
  box.q_lo -= pad;
  box.q_hi += pad;
  return box;
}

ChartBox CoverageGrid::chart_box(const DirectionBox& d) const {
  ChartBox box;
  switch (chart_) {
    case CoverageChart::cylindrical:
    case CoverageChart::equirectangular: {
      const auto q = [&](double theta) {
        if (chart_ == CoverageChart::equirectangular) return kPi / 2 - theta;
        return std::cos(theta) / std::max(std::sin(theta), 1e-6);
      };
      box.q_lo = q(d.theta_hi);
      box.q_hi = q(d.theta_lo);
      box.full_p = d.full_phi;
      box.p_lo = d.phi_lo;
      box.p_hi = d.phi_hi;
      return box;
    }
    case CoverageChart::fisheye:
    case CoverageChart::perspective: {
      double rho_lo = d.theta_lo, rho_hi = d.theta_hi;
      if (chart_ == CoverageChart::perspective) {
        if (d.theta_lo >= kPi / 2) {
          box.empty = true;
          return box;
        }
        rho_lo = std::tan(d.theta_lo);
        rho_hi = d.theta_hi >= kPi / 2 - 1e-6 ? radius_cap_
                                              : std::min(std::tan(d.theta_hi), radius_cap_);
      }
      if (d.full_phi) {
        box.p_lo = box.q_lo = -rho_hi;
        box.p_hi = box.q_hi = rho_hi;
        return box;
      }
      box.p_lo = box.q_lo = std::numeric_limits<double>::infinity();
      box.p_hi = box.q_hi = -std::numeric_limits<double>::infinity();
      const auto add = [&](double x, double y) {
        box.p_lo = std::min(box.p_lo, x);
        box.p_hi = std::max(box.p_hi, x);
        box.q_lo = std::min(box.q_lo, y);
        box.q_hi = std::max(box.q_hi, y);
      };
      for (double phi : {d.phi_lo, d.phi_hi}) {
        add(rho_lo * std::cos(phi), rho_lo * std::sin(phi));
        add(rho_hi * std::cos(phi), rho_hi * std::sin(phi));
      }
      // The sector's outer arc reaches furthest along each axis direction it passes.
      const double axis_x[4] = {1, 0, -1, 0}, axis_y[4] = {0, 1, 0, -1};
      for (int k = 0; k < 4; ++k) {
        const double offset = std::fmod(k * kPi / 2 - d.phi_lo, 2 * kPi);
        if (d.phi_lo + (offset < 0 ? offset + 2 * kPi : offset) <= d.phi_hi)
          add(rho_hi * axis_x[k], rho_hi * axis_y[k]);
      }
      return box;
    }
  }
  return box;
}

std::optional<BucketRange> CoverageGrid::buckets(const ChartBox& box) const {
  if (box.empty) return std::nullopt;
  if (cells_) {
    const auto rows = cells_between(q_breaks_, box.q_lo - pad_q_, box.q_hi + pad_q_);
    if (!rows) return std::nullopt;
    BucketRange range;
    range.first_row = rows->first;
    range.rows = rows->second - rows->first + 1;
    const double width = box.p_hi - box.p_lo + 2 * pad_p_;
    if (periodic_ && (box.full_p || width >= 2 * kPi)) {
      range.columns = columns_;
      return range;
    }
    double lo = box.p_lo - pad_p_;
    if (periodic_)
      lo = p_breaks_.front() +
           std::fmod(std::fmod(lo - p_breaks_.front(), 2 * kPi) + 2 * kPi, 2 * kPi);
    const double hi = lo + width;
    if (!periodic_) {
      const auto columns = cells_between(p_breaks_, lo, hi);
      if (!columns) return std::nullopt;
      range.first_column = columns->first;
      range.columns = columns->second - columns->first + 1;
      return range;
    }
    // Periodic: the breaks span the whole turn, so lo lies in the first turn and hi may wrap.
    const auto first = cells_between(p_breaks_, lo, lo);
    std::uint32_t last =
        cells_between(p_breaks_, std::min(hi, p_breaks_.back()), std::min(hi, p_breaks_.back()))
            ->second;
    if (hi > p_breaks_.back())
      last = columns_ + cells_between(p_breaks_, hi - 2 * kPi, hi - 2 * kPi)->second;
    range.first_column = first->first;
    range.columns = std::min(last - first->first + 1, columns_);
    if (range.columns == columns_) range.first_column = 0;
    return range;
  }
  const auto index = [](double value, double origin, double step, std::uint32_t count) {
    return std::clamp(std::floor((value - origin) / step), -1.0, double(count));
  };
  const double j_lo = std::max(index(box.q_lo, q0_, dq_, rows_), 0.0);
  const double j_hi = std::min(index(box.q_hi, q0_, dq_, rows_), double(rows_) - 1);
  if (j_hi < j_lo) return std::nullopt;
  BucketRange range;
  range.first_row = std::uint32_t(j_lo);
  range.rows = std::uint32_t(j_hi - j_lo) + 1;
  if (periodic_) {
    if (box.full_p) {
      range.columns = columns_;
      return range;
    }
    const double i_lo = std::floor((box.p_lo - p0_) / dp_);
    const double i_hi = std::floor((box.p_hi - p0_) / dp_);
    if (i_hi - i_lo + 1 >= double(columns_)) {
      range.columns = columns_;
      return range;
    }
    const double first = i_lo - double(columns_) * std::floor(i_lo / double(columns_));
    range.first_column = std::min(std::uint32_t(first), columns_ - 1);
    range.columns = std::uint32_t(i_hi - i_lo) + 1;
    return range;
  }
  const double i_lo = std::max(index(box.p_lo, p0_, dp_, columns_), 0.0);
  const double i_hi = std::min(index(box.p_hi, p0_, dp_, columns_), double(columns_) - 1);
  if (i_hi < i_lo) return std::nullopt;
  range.first_column = std::uint32_t(i_lo);
  range.columns = std::uint32_t(i_hi - i_lo) + 1;
  return range;
}

CoverageGrid::CoverageGrid(const FacetMesh& mesh, const BaseProjection& base,
                           const glm::dmat3& R_eye_base, double guard_px)
    : chart_(coverage_chart(base.kind)),
      periodic_(polar(chart_)),
      radius_cap_(1e6),
      R_base_eye_(glm::transpose(R_eye_base)) {
  const std::size_t facet_count = mesh.facets.size();
  planes_.resize(facet_count);
  corners_.resize(facet_count);
  std::vector<ChartBox> boxes(facet_count);
  for (std::uint32_t f = 0; f < facet_count; ++f) {
    planes_[f] = mesh.clip_planes(f, guard_px);
    std::array<glm::dvec3, 3> corners;
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3& a = planes_[f][k];
      const glm::dvec3& b = planes_[f][(k + 1) % 3];
      const glm::dvec3& c = planes_[f][(k + 2) % 3];
      glm::dvec3 corner = glm::normalize(glm::cross(a, b));
      if (glm::dot(corner, c) < 0) corner = -corner;
      corners_[f][k] = corner;
      corners[k] = R_base_eye_ * corner;
    }
    DirectionBox d = direction_box(corners, chart_, 1e-9);
    if (d.walk) d = {false, 0, kPi, -kPi, kPi, true};  // cannot happen below 180°
    boxes[f] = chart_box(d);
  }
  // The grid spans every facet box; periodic charts span every azimuth.
  double p_lo = 0, p_hi = 0, q_lo = 0, q_hi = 0;
  std::vector<double> widths_p, widths_q;
  bool first = true;
  for (const ChartBox& box : boxes) {
    if (box.empty) continue;
    if (first) {
      p_lo = box.p_lo, p_hi = box.p_hi, q_lo = box.q_lo, q_hi = box.q_hi;
      first = false;
    }
    p_lo = std::min(p_lo, box.p_lo);
    p_hi = std::max(p_hi, box.p_hi);
    q_lo = std::min(q_lo, box.q_lo);
    q_hi = std::max(q_hi, box.q_hi);
    if (!box.full_p) widths_p.push_back(box.p_hi - box.p_lo);
    widths_q.push_back(box.q_hi - box.q_lo);
  }
  if (periodic_) {
    p_lo = -kPi;
    p_hi = kPi;
  }
  const auto median = [](std::vector<double>& values, double fallback) {
    if (values.empty()) return fallback;
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2),
                     values.end());
    return values[values.size() / 2];
  };
  const double extent_p = std::max(p_hi - p_lo, 1e-12), extent_q = std::max(q_hi - q_lo, 1e-12);
  const auto side = [](double extent, double width) {
    if (!(width > 0)) return 1u;
    return std::uint32_t(std::clamp(std::ceil(extent / width), 1.0, double(kMaxGridSide)));
  };
  columns_ = side(extent_p, median(widths_p, extent_p));
  rows_ = side(extent_q, median(widths_q, extent_q));
  while (std::uint64_t(columns_) * rows_ > kMaxGridBuckets) {
    if (columns_ >= rows_)
      columns_ = (columns_ + 1) / 2;
    else
      rows_ = (rows_ + 1) / 2;
  }
  p0_ = p_lo;
  q0_ = q_lo;
  // A hair wider than the extent, so that the far edge falls in the last bucket.
  dp_ = periodic_ ? 2 * kPi / columns_ : extent_p * (1 + 1e-9) / columns_;
  dq_ = extent_q * (1 + 1e-9) / rows_;
  if (chart_ == CoverageChart::perspective) {
    radius_cap_ =
        2 * std::max({std::abs(p_lo), std::abs(p_hi), std::abs(q_lo), std::abs(q_hi)}) + 1;
  }

  std::vector<std::uint32_t> cell_of_facet;
  if (fit_cells(mesh, cell_of_facet)) {
    cells_ = true;
    columns_ = std::uint32_t(p_breaks_.size() - 1);
    rows_ = std::uint32_t(q_breaks_.size() - 1);
  }

  facet_buckets_.assign(facet_count, BucketRange{});
  std::vector<std::uint32_t> counts(std::size_t(columns_) * rows_ + 1, 0);
  const auto for_each_bucket = [&](const BucketRange& r, auto&& visit) {
    for (std::uint32_t j = r.first_row; j < r.first_row + r.rows; ++j)
      for (std::uint32_t k = 0; k < r.columns; ++k) {
        const std::uint32_t i = periodic_ ? (r.first_column + k) % columns_ : r.first_column + k;
        visit(std::size_t(j) * columns_ + i);
      }
  };
  for (std::uint32_t f = 0; f < facet_count; ++f) {
    std::optional<BucketRange> range;
    if (cells_) {
      if (cell_of_facet[f] != UINT32_MAX)
        range = BucketRange{cell_of_facet[f] % columns_, cell_of_facet[f] / columns_, 1, 1};
    } else {
      range = buckets(boxes[f]);
    }
    if (!range) continue;
    facet_buckets_[f] = *range;
    for_each_bucket(*range, [&](std::size_t b) { ++counts[b + 1]; });
  }
  for (std::size_t b = 1; b < counts.size(); ++b) counts[b] += counts[b - 1];
  bucket_first_ = counts;
  bucket_facets_.resize(bucket_first_.back());
  for (std::uint32_t f = 0; f < facet_count; ++f) {
    if (facet_buckets_[f].rows == 0) continue;
    for_each_bucket(facet_buckets_[f], [&](std::size_t b) { bucket_facets_[counts[b]++] = f; });
  }
}

ChartBox CoverageGrid::chart_point_box(const glm::dvec3& v_eye) const {
  const glm::dvec2 pq = chart_point(R_base_eye_ * glm::normalize(v_eye), chart_);
  ChartBox box;
  box.p_lo = box.p_hi = pq.x;
  box.q_lo = box.q_hi = pq.y;
  box.empty = !std::isfinite(pq.x) || !std::isfinite(pq.y) ||
              (chart_ == CoverageChart::perspective &&
               !(glm::dot(R_base_eye_ * v_eye, glm::dvec3(0, 0, -1)) > 0));
  return box;
}

bool CoverageGrid::fit_cells(const FacetMesh& mesh, std::vector<std::uint32_t>& cell_of_facet) {
  if (mesh.s_breaks.size() < 2 || mesh.t_breaks.size() < 2) return false;
  const std::size_t C = mesh.s_breaks.size() - 1, R = mesh.t_breaks.size() - 1;
  // The chart coordinate of every break, from the corners that lie on it: s is affine in p and t
  // in q, so every corner on one break must agree.
  std::vector<std::optional<double>> p_of(C + 1), q_of(R + 1);
  bool agree = true;
  const auto record = [&](std::optional<double>& slot, double value, bool angular) {
    if (!std::isfinite(value)) agree = false;
    if (!slot) {
      slot = value;
      return;
    }
    const double difference = angular ? wrap_pi(value - *slot) : value - *slot;
    if (std::abs(difference) > 1e-9 * std::max(1.0, std::abs(value))) agree = false;
  };
  const auto break_of = [](const std::vector<double>& breaks, std::size_t cell, double value) {
    const double span = std::abs(breaks[cell + 1] - breaks[cell]);
    if (std::abs(value - breaks[cell]) <= 1e-9 * span) return int(cell);
    if (std::abs(value - breaks[cell + 1]) <= 1e-9 * span) return int(cell + 1);
    return -1;
  };
  cell_of_facet.assign(mesh.facets.size(), UINT32_MAX);
  for (std::size_t r = 0; r < R; ++r)
    for (std::size_t c = 0; c < C; ++c) {
      const std::uint32_t first = mesh.cell_first_facet[r * C + c];
      if (first == UINT32_MAX) continue;
      for (std::uint32_t f = first; f < first + 2; ++f) {
        cell_of_facet[f] = std::uint32_t(r * C + c);
        for (const std::uint32_t v : mesh.facets[f].vertex) {
          const FacetVertex& vertex = mesh.vertices[v];
          const int i = break_of(mesh.s_breaks, c, vertex.st.x);
          const int j = break_of(mesh.t_breaks, r, vertex.st.y);
          if (i < 0 || j < 0) return false;
          const glm::dvec2 pq = chart_point(R_base_eye_ * glm::normalize(vertex.p_eye), chart_);
          record(p_of[std::size_t(i)], pq.x, periodic_);
          record(q_of[std::size_t(j)], pq.y, false);
        }
      }
    }
  if (!agree) return false;
  for (const auto& p : p_of)
    if (!p) return false;
  for (const auto& q : q_of)
    if (!q) return false;
  // Breaks in order along the chart, unwrapped across the seam of a periodic chart.
  std::vector<double> p(C + 1), q(R + 1);
  p[0] = *p_of[0];
  for (std::size_t i = 1; i <= C; ++i)
    p[i] = periodic_ ? p[i - 1] + wrap_pi(*p_of[i] - *p_of[i - 1]) : *p_of[i];
  for (std::size_t j = 0; j <= R; ++j) q[j] = *q_of[j];
  const auto monotonic = [](const std::vector<double>& x) {
    bool up = true, down = true;
    for (std::size_t i = 1; i < x.size(); ++i) {
      up = up && x[i] > x[i - 1];
      down = down && x[i] < x[i - 1];
    }
    return up ? 1 : down ? -1 : 0;
  };
  const int p_order = monotonic(p), q_order = monotonic(q);
  if (p_order == 0 || q_order == 0) return false;
  // A periodic chart's cells must go once round: a part of a turn would need its own wrapping.
  if (periodic_ && std::abs(std::abs(p.back() - p.front()) - 2 * kPi) > 1e-9) return false;
  if (p_order < 0) std::reverse(p.begin(), p.end());
  if (q_order < 0) std::reverse(q.begin(), q.end());
  if (periodic_) {  // the turn starting in [-π, π)
    const double shift = p.front() - wrap_pi(p.front());
    for (double& x : p) x -= shift;
  }
  // How far any guarded pyramid reaches beyond its cell: its boundary arcs sampled in the chart,
  // each sample's reach grown by the largest step between samples.
  constexpr int kSamples = 64;
  double pad_p = 0, pad_q = 0;
  for (std::uint32_t f = 0; f < mesh.facets.size(); ++f) {
    if (cell_of_facet[f] == UINT32_MAX) continue;
    std::size_t c = cell_of_facet[f] % C, r = cell_of_facet[f] / C;
    if (p_order < 0) c = C - 1 - c;
    if (q_order < 0) r = R - 1 - r;
    cell_of_facet[f] = std::uint32_t(r * C + c);
    const double cell_middle = 0.5 * (p[c] + p[c + 1]);
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 a = R_base_eye_ * corners_[f][k], b = R_base_eye_ * corners_[f][(k + 1) % 3];
      const double angle = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
      glm::dvec2 previous{0.0};
      double step_p = 0, step_q = 0, reach_p = 0, reach_q = 0;
      for (int m = 0; m <= kSamples; ++m) {
        const double w = double(m) / kSamples;
        const glm::dvec3 d =
            angle > 1e-12
                ? (std::sin((1 - w) * angle) * a + std::sin(w * angle) * b) / std::sin(angle)
                : a;
        glm::dvec2 pq = chart_point(glm::normalize(d), chart_);
        if (!std::isfinite(pq.x) || !std::isfinite(pq.y)) return false;
        if (periodic_) pq.x = cell_middle + wrap_pi(pq.x - cell_middle);
        if (m > 0) {
          step_p = std::max(step_p, std::abs(pq.x - previous.x));
          step_q = std::max(step_q, std::abs(pq.y - previous.y));
        }
        previous = pq;
        reach_p = std::max({reach_p, p[c] - pq.x, pq.x - p[c + 1]});
        reach_q = std::max({reach_q, q[r] - pq.y, pq.y - q[r + 1]});
      }
      pad_p = std::max(pad_p, reach_p + step_p);
      pad_q = std::max(pad_q, reach_q + step_q);
    }
  }
  const auto narrowest = [](const std::vector<double>& breaks) {
    double width = std::numeric_limits<double>::infinity();
    for (std::size_t k = 1; k < breaks.size(); ++k)
      width = std::min(width, breaks[k] - breaks[k - 1]);
    return width;
  };
  pads_under_a_cell_ = pad_p < narrowest(p) && pad_q < narrowest(q);
  p_breaks_ = std::move(p);
  q_breaks_ = std::move(q);
  pad_p_ = pad_p;
  pad_q_ = pad_q;
  return true;
}

std::optional<std::vector<std::uint32_t>> CoverageGrid::candidates(const BucketRange& r) const {
  if (std::uint64_t(r.columns) * r.rows > kMaxBuckets) return std::nullopt;
  // Listed facets per row, from at most two runs of contiguous buckets.
  std::uint32_t listed = 0;
  const std::uint32_t end = r.first_column + r.columns;
  for (std::uint32_t j = r.first_row; j < r.first_row + r.rows; ++j) {
    const std::size_t row = std::size_t(j) * columns_;
    const std::uint32_t first_end = std::min(end, columns_);
    listed += bucket_first_[row + first_end] - bucket_first_[row + r.first_column];
    if (end > columns_) listed += bucket_first_[row + end - columns_] - bucket_first_[row];
  }
  if (listed > kMaxCandidates) return std::nullopt;
  std::vector<std::uint32_t> out;
  for (std::uint32_t j = r.first_row; j < r.first_row + r.rows; ++j) {
    for (std::uint32_t k = 0; k < r.columns; ++k) {
      const std::uint32_t i = periodic_ ? (r.first_column + k) % columns_ : r.first_column + k;
      const std::size_t b = std::size_t(j) * columns_ + i;
      for (std::uint32_t m = bucket_first_[b]; m < bucket_first_[b + 1]; ++m) {
        const std::uint32_t f = bucket_facets_[m];
        const BucketRange& fb = facet_buckets_[f];
        // The first bucket both ranges share, in visiting order.
        const std::uint32_t first_row = std::max(r.first_row, fb.first_row);
        std::uint32_t first_column = std::max(r.first_column, fb.first_column);
        if (periodic_) {
          const std::uint32_t d = (r.first_column + columns_ - fb.first_column) % columns_;
          first_column = d < fb.columns ? r.first_column : fb.first_column;
        }
        if (i == first_column && j == first_row) out.push_back(f);
      }
    }
  }
  return out;
}

bool CoverageGrid::query(const std::array<glm::dvec3, 3>& triangle, const CoverageIndex& walk,
                         std::vector<std::uint32_t>& facets, bool cull_back_faces) const {
  const auto take_walk = [&] {
    walk.query(triangle, facets, cull_back_faces);
    return false;
  };
  for (const glm::dvec3& p : triangle) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return take_walk();
  }
  const glm::dvec3 normal = glm::cross(triangle[1] - triangle[0], triangle[2] - triangle[0]);
  if (cull_back_faces && !(glm::dot(normal, triangle[0]) < 0)) return true;
  // A plane through the eye: the corner directions need not bound the cone (the triangle may
  // surround the eye), and the GPU culls such triangles; the walk answers.
  const double scale =
      std::max({glm::length(triangle[0]), glm::length(triangle[1]), glm::length(triangle[2])});
  if (!(std::abs(glm::dot(normal, triangle[0])) > 1e-9 * glm::length(normal) * scale))
    return take_walk();
  std::array<glm::dvec3, 3> u;
  for (int c = 0; c < 3; ++c) u[c] = R_base_eye_ * glm::normalize(triangle[c]);
  std::optional<ChartBox> box = gnomonic_box(u);
  if (!box) {
    const DirectionBox directions = direction_box(u, chart_, 0);
    if (directions.walk) return take_walk();
    box = chart_box(directions);
  }
  const auto range = buckets(*box);
  if (!range) return true;
  const auto listed = candidates(*range);
  if (!listed) return take_walk();
  const std::size_t first_output = facets.size();
  for (std::uint32_t f : *listed) {
    if (triangle_meets_cone(triangle, planes_[f].data(), 3)) facets.push_back(f);
  }
  std::sort(facets.begin() + std::ptrdiff_t(first_output), facets.end());
  return true;
}

}  // namespace facet
