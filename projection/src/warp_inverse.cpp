#include "facet/projection/warp_inverse.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "facet/projection/errors.hpp"
#include "facet/projection/parallel.hpp"

namespace facet {
namespace {

double cross(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

// Cell-local coordinates may leave [0,1] by this much and still count as inside: the rounding of
// a solution on a shared edge, far below a pixel (cells are at most a few thousand pixels wide).
constexpr double kCellSlack = 1e-10;
constexpr int kMaxNewtonSteps = 32;

// Newton's method on the bilinear map of a cell with mapped corners q00, q10, q01, q11, from the
// cell-local start f. False when it does not reach WarpInverse::kTolerancePx.
bool newton_in_cell(glm::dvec2 q00, glm::dvec2 q10, glm::dvec2 q01, glm::dvec2 q11, glm::dvec2 q,
                    glm::dvec2& f) {
  for (int step = 0; step < kMaxNewtonSteps; ++step) {
    const glm::dvec2 bottom = q00 * (1 - f.x) + q10 * f.x, top = q01 * (1 - f.x) + q11 * f.x;
    const glm::dvec2 residual = bottom * (1 - f.y) + top * f.y - q;
    if (glm::length(residual) <= WarpInverse::kTolerancePx * 0.5) return true;
    const glm::dvec2 d_dx = (q10 - q00) * (1 - f.y) + (q11 - q01) * f.y;
    const glm::dvec2 d_dy = top - bottom;
    const double det = cross(d_dx, d_dy);
    if (!(std::abs(det) > 1e-300)) return false;
    // Cramer's rule for J·δ = −residual.
    const glm::dvec2 delta(cross(d_dy, residual) / det, cross(residual, d_dx) / det);
    f += delta;
    if (!std::isfinite(f.x) || !std::isfinite(f.y)) return false;
  }
  const glm::dvec2 q_f =
      (q00 * (1 - f.x) + q10 * f.x) * (1 - f.y) + (q01 * (1 - f.x) + q11 * f.x) * f.y;
  return glm::length(q_f - q) <= WarpInverse::kTolerancePx;
}

}  // namespace

WarpInverse::WarpInverse(Warp warp) : WarpInverse(std::move(warp), {}, false) {}

int WarpInverse::cell_rank(const std::vector<float>& ranking, int i, int j) const {
  const int covered = int(ranking[warp_.node_index(i, j)] >= 0.5f) +
                      int(ranking[warp_.node_index(i + 1, j)] >= 0.5f) +
                      int(ranking[warp_.node_index(i, j + 1)] >= 0.5f) +
                      int(ranking[warp_.node_index(i + 1, j + 1)] >= 0.5f);
  return covered == 4 ? 2 : covered > 0 ? 1 : 0;  // bilinear coverage stays within its corners
}

WarpInverse::WarpInverse(Warp warp, const std::vector<float>& ranking_or_empty, bool continued)
    : warp_(std::move(warp)) {
  FACET_ASSERT(warp_.grid_size.x >= 2 && warp_.grid_size.y >= 2);
  FACET_ASSERT(warp_.offset_px.size() == std::size_t(warp_.grid_size.x) * warp_.grid_size.y);
  FACET_ASSERT(warp_.coverage.size() == warp_.offset_px.size());
  const std::vector<float>& ranking = ranking_or_empty.empty() ? warp_.coverage : ranking_or_empty;
  FACET_ASSERT(ranking.size() == warp_.coverage.size());
  cells_ = warp_.grid_size - 1;
  const glm::ivec2 size = warp_.output_size;
  cell_of_pixel_.assign(std::size_t(std::max(size.x, 0)) * std::max(size.y, 0), -1);

  // Cells of lower rank first, so that where an uncovered part overlaps a fully covered cell
  // (uncovered nodes need not be injective) the covered cell is stored.
  for (int pass = continued ? 0 : 1; pass <= 2; ++pass) {
    for (int j = 0; j < cells_.y; ++j) {
      for (int i = 0; i < cells_.x; ++i) {
        if (cell_rank(ranking, i, j) != pass) continue;
        const std::int32_t cell = j * cells_.x + i;
        // Counter-clockwise in a y-down image: s right, t down.
        const glm::dvec2 quad[4] = {q_node(i, j), q_node(i + 1, j), q_node(i + 1, j + 1),
                                    q_node(i, j + 1)};
        glm::dvec2 lo = quad[0], hi = quad[0];
        for (const auto& corner : quad) {
          lo = glm::min(lo, corner);
          hi = glm::max(hi, corner);
        }
        // Pixel centres within the bounds, clamped while still doubles: any finite offset is a
        // valid warp, and a corner 1e13 pixels away must not overflow an int.
        const int x0 = int(std::clamp(std::ceil(lo.x - 0.5), 0.0, double(size.x)));
        const int x1 = int(std::clamp(std::floor(hi.x - 0.5), -1.0, double(size.x - 1)));
        const int y0 = int(std::clamp(std::ceil(lo.y - 0.5), 0.0, double(size.y)));
        const int y1 = int(std::clamp(std::floor(hi.y - 0.5), -1.0, double(size.y - 1)));
        for (int y = y0; y <= y1; ++y) {
          for (int x = x0; x <= x1; ++x) {
            const glm::dvec2 p(x + 0.5, y + 0.5);
            bool inside = true;
            for (int e = 0; e < 4 && inside; ++e) {
              inside = cross(quad[(e + 1) % 4] - quad[e], p - quad[e]) >= 0;
            }
            if (inside) cell_of_pixel_[std::size_t(y) * size.x + x] = cell;
          }
        }
        // Cells narrower than a pixel may hold no pixel centre: give them the pixel under their
        // middle when nothing else claimed it, so that queries there still find a start.
        const glm::dvec2 middle = (quad[0] + quad[1] + quad[2] + quad[3]) * 0.25;
        if (middle.x >= 0 && middle.y >= 0 && middle.x < size.x && middle.y < size.y) {
          auto& slot = cell_of_pixel_[std::size_t(middle.y) * size.x + std::size_t(middle.x)];
          if (slot < 0) slot = cell;
        }
      }
    }
  }
  build_bins(ranking, continued);
}

void WarpInverse::build_bins(const std::vector<float>& ranking, bool continued) {
  // Bounds of every cell that has a covered corner (every cell when continued), grown by a hair
  // so that points on an edge land in the bin of each cell they touch; higher ranks first.
  std::vector<std::int32_t> cells;
  std::vector<glm::dvec2> lo, hi;
  for (int rank = 2; rank >= (continued ? 0 : 1); --rank) {
    for (int j = 0; j < cells_.y; ++j) {
      for (int i = 0; i < cells_.x; ++i) {
        if (cell_rank(ranking, i, j) != rank) continue;
        const glm::dvec2 a = q_node(i, j), b = q_node(i + 1, j), c = q_node(i, j + 1),
                         d = q_node(i + 1, j + 1);
        cells.push_back(j * cells_.x + i);
        lo.push_back(glm::min(glm::min(a, b), glm::min(c, d)) - 1e-6);
        hi.push_back(glm::max(glm::max(a, b), glm::max(c, d)) + 1e-6);
      }
    }
  }
  if (cells.empty()) return;
  glm::dvec2 all_lo = lo[0], all_hi = hi[0];
  for (std::size_t k = 0; k < cells.size(); ++k) {
    all_lo = glm::min(all_lo, lo[k]);
    all_hi = glm::max(all_hi, hi[k]);
  }
  // About one bin per cell: each bin then overlaps a handful of cells.
  bins_ = glm::clamp(cells_, 1, 256);
  bins_lo_ = all_lo;
  bin_size_ = glm::max((all_hi - all_lo) / glm::dvec2(bins_), glm::dvec2(1e-9));
  auto bin_range = [&](std::size_t k) {
    const glm::ivec2 b0 =
        glm::clamp(glm::ivec2((lo[k] - bins_lo_) / bin_size_), glm::ivec2(0), bins_ - 1);
    const glm::ivec2 b1 =
        glm::clamp(glm::ivec2((hi[k] - bins_lo_) / bin_size_), glm::ivec2(0), bins_ - 1);
    return std::pair(b0, b1);
  };
  std::vector<std::uint32_t> count(std::size_t(bins_.x) * bins_.y + 1, 0);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const auto [b0, b1] = bin_range(k);
    for (int y = b0.y; y <= b1.y; ++y) {
      for (int x = b0.x; x <= b1.x; ++x) ++count[std::size_t(y) * bins_.x + x + 1];
    }
  }
  for (std::size_t k = 1; k < count.size(); ++k) count[k] += count[k - 1];
  bin_start_ = count;
  bin_cells_.resize(count.back());
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const auto [b0, b1] = bin_range(k);
    for (int y = b0.y; y <= b1.y; ++y) {
      for (int x = b0.x; x <= b1.x; ++x)
        bin_cells_[count[std::size_t(y) * bins_.x + x]++] = cells[k];
    }
  }
}

glm::dvec2 WarpInverse::q_node(int i, int j) const {
  return glm::dvec2(double(i) * warp_.output_size.x / cells_.x,
                    double(j) * warp_.output_size.y / cells_.y) +
         glm::dvec2(warp_.offset_px[warp_.node_index(i, j)]);
}

bool WarpInverse::solve_in_cell(glm::ivec2 cell, glm::dvec2 q, glm::dvec2& f) const {
  return newton_in_cell(q_node(cell.x, cell.y), q_node(cell.x + 1, cell.y),
                        q_node(cell.x, cell.y + 1), q_node(cell.x + 1, cell.y + 1), q, f);
}

std::optional<WarpInverse::Inverted> WarpInverse::invert(glm::dvec2 q) const {
  const auto st = st_from_q(q);
  if (!st) return std::nullopt;
  return Inverted{*st, warp_.v_eye_from_st(*st)};
}

std::optional<glm::dvec2> WarpInverse::st_from_q(glm::dvec2 q) const {
  if (!std::isfinite(q.x) || !std::isfinite(q.y) || cell_of_pixel_.empty()) return std::nullopt;
  const glm::ivec2 size = warp_.output_size;
  // q may lie outside the image when offsets push part of the base beyond it; start from the
  // nearest pixel then.
  const glm::ivec2 pixel(int(std::clamp(std::floor(q.x), 0.0, double(size.x - 1))),
                         int(std::clamp(std::floor(q.y), 0.0, double(size.y - 1))));
  std::int32_t start = cell_at_pixel(pixel);
  // The centre of q's pixel may be uncovered while q itself is covered (near the edge of
  // coverage): try the neighbouring pixels' cells.
  for (int k = 0; start < 0 && k < 9; ++k) {
    const glm::ivec2 other = pixel + glm::ivec2(k % 3 - 1, k / 3 - 1);
    if (other.x >= 0 && other.y >= 0 && other.x < size.x && other.y < size.y) {
      start = cell_at_pixel(other);
    }
  }
  if (start >= 0) {
    if (auto st = walk_from(glm::ivec2(start % cells_.x, start / cells_.x), q)) return st;
  }
  // No pixel stores a cell for q (it lies outside the image, or in a sliver between pixel
  // centres), or the walk met an uncovered cell: try the cells whose bounds overlap q's bin.
  if (bins_.x == 0) return std::nullopt;
  const glm::dvec2 b = (q - bins_lo_) / bin_size_;
  if (!(b.x >= 0 && b.y >= 0 && b.x < bins_.x && b.y < bins_.y)) return std::nullopt;
  const std::size_t bin = std::size_t(b.y) * bins_.x + std::size_t(b.x);
  for (std::uint32_t k = bin_start_[bin]; k < bin_start_[bin + 1]; ++k) {
    const std::int32_t cell = bin_cells_[k];
    if (auto st = solve_here(glm::ivec2(cell % cells_.x, cell / cells_.x), q)) return st;
  }
  return std::nullopt;
}

std::optional<glm::dvec2> WarpInverse::solve_here(glm::ivec2 cell, glm::dvec2 q) const {
  glm::dvec2 f(0.5);
  if (!solve_in_cell(cell, q, f)) return std::nullopt;
  if (f.x < -kCellSlack || f.y < -kCellSlack || f.x > 1 + kCellSlack || f.y > 1 + kCellSlack) {
    return std::nullopt;
  }
  f = glm::clamp(f, 0.0, 1.0);
  const glm::dvec2 st((cell.x + f.x) / cells_.x, (cell.y + f.y) / cells_.y);
  if (!(warp_.coverage_at(st) >= 0.5)) return std::nullopt;
  return st;
}

std::optional<glm::dvec2> WarpInverse::walk_from(glm::ivec2 cell, glm::dvec2 q) const {
  // A walk across the grid never needs more steps than the grid has cells along both axes.
  const int max_walk = cells_.x + cells_.y + 2;
  for (int walk = 0; walk < max_walk; ++walk) {
    glm::dvec2 f(0.5);
    if (!solve_in_cell(cell, q, f)) return std::nullopt;
    glm::ivec2 move(0);
    if (f.x < -kCellSlack) move.x = -1;
    if (f.x > 1 + kCellSlack) move.x = 1;
    if (f.y < -kCellSlack) move.y = -1;
    if (f.y > 1 + kCellSlack) move.y = 1;
    if (move == glm::ivec2(0)) {
      f = glm::clamp(f, 0.0, 1.0);
      const glm::dvec2 st((cell.x + f.x) / cells_.x, (cell.y + f.y) / cells_.y);
      if (!(warp_.coverage_at(st) >= 0.5)) return std::nullopt;
      return st;
    }
    const glm::ivec2 next = cell + move;
    // Beyond the grid's edge: q is outside the warped image.
    if (next.x < 0 || next.y < 0 || next.x >= cells_.x || next.y >= cells_.y) return std::nullopt;
    cell = next;
  }
  return std::nullopt;
}

void WarpInverse::for_each_pixel_centre(const std::function<void(std::size_t, glm::dvec2)>& found,
                                        std::size_t threads, std::stop_token stop) const {
  const glm::ivec2 size = warp_.output_size;
  // Along a row, consecutive pixel centres mostly lie in the same cell: Newton starts there from
  // the previous pixel's cell-local solution, a pixel away, and converges in a step or two
  // instead of four or five from the cell's middle. It still stops only within kTolerancePx, so
  // the answer is the same point to that tolerance; anything else (another cell, a solution
  // outside this one, no convergence) takes st_from_q's path.
  const auto row = [&](std::size_t y, std::size_t) {
    if (stop.stop_requested()) return;
    const std::int32_t* cells = cell_of_pixel_.data() + y * std::size_t(size.x);
    std::int32_t previous = -1;  // the cell of the previous pixel's solution, or −1
    glm::dvec2 f(0.5), q00(0.0), q10(0.0), q01(0.0), q11(0.0);
    for (int x = 0; x < size.x; ++x) {
      const glm::dvec2 q(x + 0.5, double(y) + 0.5);
      const std::int32_t cell = cells[x];
      if (cell >= 0 && cell == previous) {
        glm::dvec2 g = f;
        if (newton_in_cell(q00, q10, q01, q11, q, g) && g.x >= -kCellSlack && g.y >= -kCellSlack &&
            g.x <= 1 + kCellSlack && g.y <= 1 + kCellSlack) {
          const glm::ivec2 c(cell % cells_.x, cell / cells_.x);
          const glm::dvec2 clamped = glm::clamp(g, 0.0, 1.0);
          const glm::dvec2 st((c.x + clamped.x) / cells_.x, (c.y + clamped.y) / cells_.y);
          // Uncovered here: st_from_q also tries the other cells that may hold q.
          if (warp_.coverage_at(st) >= 0.5) {
            f = g;
            found(y * std::size_t(size.x) + x, st);
            continue;
          }
        }
      }
      previous = -1;
      const auto st = st_from_q(q);
      if (!st) continue;
      found(y * std::size_t(size.x) + x, *st);
      // Start the next pixel from this solution when it lies in the cell stored for that pixel.
      const glm::ivec2 c = glm::min(glm::ivec2(*st * glm::dvec2(cells_)), cells_ - 1);
      if (cell == c.y * cells_.x + c.x) {
        previous = cell;
        f = *st * glm::dvec2(cells_) - glm::dvec2(c);
        q00 = q_node(c.x, c.y);
        q10 = q_node(c.x + 1, c.y);
        q01 = q_node(c.x, c.y + 1);
        q11 = q_node(c.x + 1, c.y + 1);
      }
    }
  };
  detail::parallel_for(std::size_t(std::max(size.y, 0)), row, 8, threads);
}

std::vector<glm::dvec2> WarpInverse::st_at_pixel_centres(std::size_t threads) const {
  std::vector<glm::dvec2> st(cell_of_pixel_.size(),
                             glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  for_each_pixel_centre([&](std::size_t pixel, glm::dvec2 found) { st[pixel] = found; }, threads);
  return st;
}

std::vector<glm::vec3> WarpInverse::v_eye_at_pixel_centres(std::size_t threads,
                                                           std::stop_token stop) const {
  std::vector<glm::vec3> v_eye(cell_of_pixel_.size(),
                               glm::vec3(std::numeric_limits<float>::quiet_NaN()));
  for_each_pixel_centre(
      [&](std::size_t pixel, glm::dvec2 found) {
        v_eye[pixel] = glm::vec3(glm::normalize(warp_.v_eye_from_st(found)));
      },
      threads, stop);
  return v_eye;
}

std::int32_t WarpInverse::cell_at_pixel(glm::ivec2 pixel) const {
  if (pixel.x < 0 || pixel.y < 0 || pixel.x >= warp_.output_size.x ||
      pixel.y >= warp_.output_size.y) {
    return -1;
  }
  return cell_of_pixel_[std::size_t(pixel.y) * warp_.output_size.x + pixel.x];
}

WarpInverse continued_inverse(Warp warp) {
  const std::vector<float> ranking = warp.coverage;
  warp.coverage.assign(warp.coverage.size(), 1.0f);
  return WarpInverse(std::move(warp), ranking, true);
}

}  // namespace facet
