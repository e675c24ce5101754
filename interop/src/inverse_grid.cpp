#include "facet/interop/inverse_grid.hpp"

#include <cmath>

#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"

namespace facet::interop {
namespace {

bool finite(glm::dvec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }

// The scale of the auxiliary warp that represents an inverse grid: its "output pixels" are
// base-image positions times this. WarpInverse's per-pixel table then has this many pixels per
// side; queries are solved exactly by Newton whatever the table's resolution.
constexpr int kAuxiliaryScale = 1024;

}  // namespace

std::vector<bool> fill_missing(std::vector<glm::dvec2>& values, glm::ivec2 grid_size,
                               const std::string& source) {
  const int w = grid_size.x, h = grid_size.y;
  std::vector<bool> valid(values.size());
  bool any = false;
  for (std::size_t k = 0; k < values.size(); ++k) {
    valid[k] = finite(values[k]);
    any = any || valid[k];
  }
  if (!any) throw InputError(source, "nodes", "expected at least one valid (non-NaN) node");
  std::vector<bool> known = valid;
  const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<std::pair<std::size_t, glm::dvec2>> front;
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        const std::size_t k = std::size_t(j) * w + i;
        if (known[k]) continue;
        glm::dvec2 linear{0.0}, mean{0.0};
        int n_linear = 0, n_mean = 0;
        for (int d = 0; d < 4; ++d) {
          const int i1 = i + di[d], j1 = j + dj[d], i2 = i + 2 * di[d], j2 = j + 2 * dj[d];
          if (i1 < 0 || j1 < 0 || i1 >= w || j1 >= h) continue;
          const std::size_t k1 = std::size_t(j1) * w + i1;
          if (!known[k1]) continue;
          mean += values[k1];
          ++n_mean;
          if (i2 >= 0 && j2 >= 0 && i2 < w && j2 < h && known[std::size_t(j2) * w + i2]) {
            linear += 2.0 * values[k1] - values[std::size_t(j2) * w + i2];
            ++n_linear;
          }
        }
        if (n_linear) {
          front.emplace_back(k, linear / double(n_linear));
        } else if (n_mean) {
          front.emplace_back(k, mean / double(n_mean));
        }
      }
    }
    for (const auto& [k, value] : front) {
      values[k] = value;
      known[k] = true;
      changed = true;
    }
  }
  return valid;
}

Warp warp_from_inverse_grid(const InverseGrid& grid, const BaseProjection& base,
                            const glm::dmat3& R_eye_base, glm::ivec2 output_size,
                            glm::ivec2 warp_grid, const std::string& source) {
  FACET_ASSERT(grid.grid_size.x >= 2 && grid.grid_size.y >= 2);
  FACET_ASSERT(grid.st.size() == std::size_t(grid.grid_size.x) * grid.grid_size.y);
  FACET_ASSERT(warp_grid.x >= 2 && warp_grid.y >= 2);
  // The inverse grid as a Warp of its own: its base image is the output (normalised), its
  // "output" the base image of the result scaled by kAuxiliaryScale. Inverting that warp
  // answers "which output position shows st".
  std::vector<glm::dvec2> st = grid.st;
  const std::vector<bool> valid = fill_missing(st, grid.grid_size, source);
  Warp auxiliary;
  auxiliary.output_size = {kAuxiliaryScale, kAuxiliaryScale};
  auxiliary.grid_size = grid.grid_size;
  auxiliary.offset_px.resize(st.size());
  auxiliary.coverage.resize(st.size());
  for (int j = 0; j < grid.grid_size.y; ++j) {
    for (int i = 0; i < grid.grid_size.x; ++i) {
      const std::size_t k = auxiliary.node_index(i, j);
      const glm::dvec2 q_output{double(i) / (grid.grid_size.x - 1),
                                double(j) / (grid.grid_size.y - 1)};
      auxiliary.offset_px[k] = glm::vec2((st[k] - q_output) * double(kAuxiliaryScale));
      auxiliary.coverage[k] = valid[k] ? 1.0f : 0.0f;
    }
  }
  const WarpInverse inverse(std::move(auxiliary));

  Warp warp;
  warp.base = base;
  warp.R_eye_base = R_eye_base;
  warp.output_size = output_size;
  warp.grid_size = warp_grid;
  std::vector<glm::dvec2> offsets(std::size_t(warp_grid.x) * warp_grid.y,
                                  glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  for (int j = 0; j < warp_grid.y; ++j) {
    for (int i = 0; i < warp_grid.x; ++i) {
      const glm::dvec2 st_node{double(i) / (warp_grid.x - 1), double(j) / (warp_grid.y - 1)};
      if (auto output = inverse.st_from_q(st_node * double(kAuxiliaryScale))) {
        const glm::dvec2 q = *output * glm::dvec2(output_size);
        offsets[warp.node_index(i, j)] = q - st_node * glm::dvec2(output_size);
      }
    }
  }
  const std::vector<bool> covered = fill_missing(offsets, warp_grid, source);
  warp.offset_px.resize(offsets.size());
  warp.coverage.resize(offsets.size());
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    warp.offset_px[k] = glm::vec2(offsets[k]);
    warp.coverage[k] = covered[k] ? 1.0f : 0.0f;
  }
  warp.validate(source);
  return warp;
}

InverseGrid inverse_grid_from_warp(
    const Warp& warp, glm::ivec2 grid_size,
    const std::function<std::optional<glm::dvec2>(const glm::dvec3& v_eye)>& st_of_direction) {
  FACET_ASSERT(grid_size.x >= 2 && grid_size.y >= 2);
  const WarpInverse inverse(warp);
  InverseGrid grid;
  grid.grid_size = grid_size;
  grid.st.assign(std::size_t(grid_size.x) * grid_size.y,
                 glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  for (int j = 0; j < grid_size.y; ++j) {
    for (int i = 0; i < grid_size.x; ++i) {
      const glm::dvec2 q{double(i) / (grid_size.x - 1) * warp.output_size.x,
                         double(j) / (grid_size.y - 1) * warp.output_size.y};
      if (auto inverted = inverse.invert(q)) {
        if (auto st = st_of_direction(inverted->v_eye)) {
          grid.st[std::size_t(j) * grid_size.x + i] = *st;
        }
      }
    }
  }
  return grid;
}

}  // namespace facet::interop
