#pragma once
// Displays shared by the projection tests: every base, analytic and with smooth offsets.
#include <cmath>
#include <string>
#include <vector>

#include "facet/projection/warp.hpp"

namespace facet::test {

struct NamedWarp {
  std::string name;
  Warp warp;
};

// A smooth, injective distortion of up to `amplitude` output pixels, like a projector's lens.
inline Warp with_smooth_offsets(Warp warp, glm::ivec2 grid, double amplitude) {
  warp.grid_size = grid;
  warp.offset_px.resize(std::size_t(grid.x) * grid.y);
  warp.coverage.assign(warp.offset_px.size(), 1.0f);
  for (int j = 0; j < grid.y; ++j) {
    for (int i = 0; i < grid.x; ++i) {
      const double s = double(i) / (grid.x - 1), t = double(j) / (grid.y - 1);
      const double u = 2 * s - 1, v = 2 * t - 1;
      warp.offset_px[warp.node_index(i, j)] = glm::vec2(float(amplitude * u * (u * u + v * v) / 2),
                                                        float(amplitude * 0.5 * v * (1 - u * u)));
    }
  }
  return warp;
}

inline std::vector<NamedWarp> displays_for_tolerance_tests() {
  return {
      {"cylinder 360x90",
       Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {480, 360})},
      {"cylinder 120x60 with offsets",
       with_smooth_offsets(
           Warp::analytic(BaseProjection::cylindrical(-60, 60, 0.6, -0.6), {400, 200}), {17, 9},
           6)},
      {"fisheye 180", Warp::analytic(BaseProjection::fisheye(180), {256, 256})},
      {"fisheye 220", Warp::analytic(BaseProjection::fisheye(220), {192, 192})},
      {"equirectangular 360x150",
       Warp::analytic(BaseProjection::equirectangular(-180, 180, 75, -75), {384, 192})},
      {"perspective 100x70 with offsets",
       with_smooth_offsets(Warp::analytic(BaseProjection::perspective_fov(100, 70), {400, 300}),
                           {9, 7}, 8)},
  };
}

}  // namespace facet::test
