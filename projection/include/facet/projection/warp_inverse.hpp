#pragma once
// The inverse of a warp's exact map: from an output pixel position q back to the base-image
// coordinates st (and the eye direction) with Warp::q_from_st(st) = q.
//
// Within one cell of the node grid, q_from_st is bilinear in st (s·W and t·H are linear, the
// offsets bilinear), so the image of a cell is the quadrilateral of its four mapped nodes with
// straight edges. The inverse rasterises those quadrilaterals into the output image once, giving
// for each output pixel centre the cell that holds it, then solves the cell's bilinear equation
// by Newton's method in double precision. Queries anywhere (not only at pixel centres) start from
// the cell stored for the pixel that holds q and walk to neighbouring cells when the solution
// leaves the cell; where that finds nothing (q outside the image, a walk blocked by uncovered
// cells) the cells whose bounding boxes hold q are tried, found through a coarse grid of bins.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <stop_token>
#include <vector>

#include "facet/projection/warp.hpp"

namespace facet {

class WarpInverse {
 public:
  // Newton stops once |q_from_st(st) - q| is at most this many output pixels.
  static constexpr double kTolerancePx = 1e-9;

  // Builds the per-pixel cell lookup: about one point-in-quadrilateral test per output pixel
  // plus one per cell. The warp is copied. The warp should pass Warp::validate(); on a warp that
  // folds, the inverse returns one of the preimages.
  explicit WarpInverse(Warp warp);

  const Warp& warp() const { return warp_; }

  struct Inverted {
    glm::dvec2 st;     // base-image coordinates in [0,1]², t downwards
    glm::dvec3 v_eye;  // unit eye-frame direction, Warp::v_eye_from_st(st)
  };
  // q in output pixels (x right, y down, the top-left corner of the image is (0, 0), pixel
  // centres at half-integers). nullopt where no st in [0,1]² with coverage_at(st) >= 0.5 maps to
  // q, and where Newton does not reach kTolerancePx (a fold inside a partly covered cell). On a
  // cell edge either neighbour's st is returned; both map to q.
  std::optional<Inverted> invert(glm::dvec2 q) const;
  std::optional<glm::dvec2> st_from_q(glm::dvec2 q) const;

  // invert() at every output pixel centre (x + 0.5, y + 0.5), row 0 at the top, row-major;
  // uncovered pixels hold NaN in every component. Rows are shared among `threads` threads (0:
  // one per hardware thread); each row is solved on its own, so the answer is the same to the
  // bit for any count. Newton starts from the neighbouring pixel's solution where both lie in
  // one cell, so an answer may differ from st_from_q's in the last bits, never by more than
  // kTolerancePx in output pixels.
  std::vector<glm::dvec2> st_at_pixel_centres(std::size_t threads = 0) const;
  // The same pixel centres' unit eye directions, normalize(Warp::v_eye_from_st(st)) rounded to
  // float (as a direction lookup texture holds them); NaN where uncovered. Once `stop` is
  // requested, rows not yet begun are left NaN and the call returns when the rows under way
  // finish: the result is then incomplete, for the caller to drop.
  std::vector<glm::vec3> v_eye_at_pixel_centres(std::size_t threads = 0,
                                                std::stop_token stop = {}) const;

  // The cell (i + j·(Gw − 1)) stored for the pixel holding q's centre, or −1: for tests.
  std::int32_t cell_at_pixel(glm::ivec2 pixel) const;

 private:
  // Solves the bilinear equation of cell (i, j) for q from `f`, the cell-local start in [0,1]².
  // Returns false when Newton fails to converge.
  bool solve_in_cell(glm::ivec2 cell, glm::dvec2 q, glm::dvec2& f) const;
  // The covered st of cell `cell` that maps to q, if q lies in that cell.
  std::optional<glm::dvec2> solve_here(glm::ivec2 cell, glm::dvec2 q) const;
  // Moves from cell to neighbouring cell towards q until the solution lies inside the cell.
  std::optional<glm::dvec2> walk_from(glm::ivec2 cell, glm::dvec2 q) const;
  glm::dvec2 q_node(int i, int j) const;
  // The cell table and the bins, with cells ranked by `ranking` (node coverage, the warp's own
  // for an inverse, the warp's real one for a continued inverse): cells with every corner covered
  // are stored last, so that they hold every pixel centre they cover, and the bins list them
  // first. Cells of rank 0 (no covered corner) enter only when `continued`.
  WarpInverse(Warp warp, const std::vector<float>& ranking, bool continued);
  friend WarpInverse continued_inverse(Warp warp);
  // 2 when all four corners of cell (i, j) are covered in `ranking`, 1 when some are, else 0.
  int cell_rank(const std::vector<float>& ranking, int i, int j) const;
  // Calls found(y · width + x, st) for every covered pixel centre, rows in parallel on
  // `threads` threads (0: every hardware thread); no row begins once `stop` is requested.
  void for_each_pixel_centre(const std::function<void(std::size_t, glm::dvec2)>& found,
                             std::size_t threads, std::stop_token stop = {}) const;
  void build_bins(const std::vector<float>& ranking, bool continued);

  Warp warp_;
  glm::ivec2 cells_{0, 0};
  std::vector<std::int32_t> cell_of_pixel_;  // output-sized, −1 where no cell holds the centre
  // The fallback: a coarse grid of bins over the bounds of every cell with a covered corner; the
  // cells overlapping bin b are bin_cells_[bin_start_[b] .. bin_start_[b + 1]).
  glm::ivec2 bins_{0, 0};
  glm::dvec2 bins_lo_{0.0}, bin_size_{1.0};
  std::vector<std::uint32_t> bin_start_;
  std::vector<std::int32_t> bin_cells_;
};

// The inverse of the warp's map over its whole base image, coverage ignored: output positions
// just past the coverage's edge invert too, the offsets being defined there. Where the
// continuation folds back over covered output (its offsets are only an extrapolation), a
// position the warp covers still inverts to its covered st, as the plain inverse gives it.
WarpInverse continued_inverse(Warp warp);

}  // namespace facet
