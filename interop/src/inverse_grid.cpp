#include "facet/interop/inverse_grid.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"

namespace facet::interop {
namespace {

bool finite(glm::dvec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }

// The scale of the auxiliary warp that represents an inverse grid: its "output pixels" are
// base-image positions times this. WarpInverse's per-pixel table then has this many pixels per
// side; queries are solved exactly by Newton whatever the table's resolution.
constexpr int kAuxiliaryScale = 1024;

// The largest magnitude of a node's value (a base-image position normalised to [0,1]) that an
// inverse grid may hold: a million base images away is no map, and the bound keeps the auxiliary
// warp's offsets, its extrapolated nodes included, finite as floats.
constexpr double kMaxInverseGridValue = 1e6;

// Nodes found only among filled-in nodes of the inverse grid may come from a fold of that
// extrapolation rather than from the map. A suspect node is kept when it continues its trusted
// neighbours: it lies within `tolerance_px` of the line through two trusted nodes next to it
// (in any of the four directions), checked ring by ring outwards from the trusted nodes. The rest
// become NaN, to be extrapolated from the forward grid instead.
void drop_inconsistent(std::vector<glm::dvec2>& offsets, const std::vector<bool>& suspect,
                       glm::ivec2 grid_size, double tolerance_px) {
  const int w = grid_size.x, h = grid_size.y;
  std::vector<bool> trusted(offsets.size());
  for (std::size_t k = 0; k < offsets.size(); ++k) trusted[k] = !suspect[k] && finite(offsets[k]);
  const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<std::size_t> accepted;
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        const std::size_t k = std::size_t(j) * w + i;
        if (trusted[k] || !suspect[k] || !finite(offsets[k])) continue;
        for (int d = 0; d < 4; ++d) {
          const int i1 = i + di[d], j1 = j + dj[d], i2 = i + 2 * di[d], j2 = j + 2 * dj[d];
          if (i2 < 0 || j2 < 0 || i2 >= w || j2 >= h) continue;
          const std::size_t k1 = std::size_t(j1) * w + i1, k2 = std::size_t(j2) * w + i2;
          if (!trusted[k1] || !trusted[k2]) continue;
          if (glm::length(offsets[k] - (2.0 * offsets[k1] - offsets[k2])) <= tolerance_px) {
            accepted.push_back(k);
            break;
          }
        }
      }
    }
    for (std::size_t k : accepted) trusted[k] = changed = true;
  }
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    if (!trusted[k]) offsets[k] = glm::dvec2(std::numeric_limits<double>::quiet_NaN());
  }
}

// Least-squares fit of forward offsets to the valid samples of an inverse grid: sample k at output
// position q_k shows st_k, so Σ_i w_i(st_k)·(st_i·size + o_i) = q_k with the bilinear weights
// of st_k's forward cell. A small pull towards the starting offsets keeps nodes that no sample
// pins where they were. Conjugate gradients on the normal equations, x and y together.
void fit_to_samples(std::vector<glm::dvec2>& offsets, const InverseGrid& grid, glm::ivec2 warp_grid,
                    glm::ivec2 output_size) {
  struct Sample {
    std::size_t node[4];
    double weight[4];
    glm::dvec2 b;  // q_k − st_k·size
  };
  std::vector<Sample> samples;
  const glm::dvec2 size(output_size);
  const glm::dvec2 cells(warp_grid - 1);
  for (int j = 0; j < grid.grid_size.y; ++j) {
    for (int i = 0; i < grid.grid_size.x; ++i) {
      const glm::dvec2 st = grid.st[std::size_t(j) * grid.grid_size.x + i];
      if (!finite(st) || st.x < 0 || st.y < 0 || st.x > 1 || st.y > 1) continue;
      const glm::dvec2 q{double(i) / (grid.grid_size.x - 1) * size.x,
                         double(j) / (grid.grid_size.y - 1) * size.y};
      const glm::dvec2 g = st * cells;
      const int ci = std::min(int(g.x), warp_grid.x - 2), cj = std::min(int(g.y), warp_grid.y - 2);
      const double fx = g.x - ci, fy = g.y - cj;
      Sample sample;
      const std::size_t k0 = std::size_t(cj) * warp_grid.x + ci;
      sample.node[0] = k0;
      sample.node[1] = k0 + 1;
      sample.node[2] = k0 + warp_grid.x;
      sample.node[3] = k0 + warp_grid.x + 1;
      sample.weight[0] = (1 - fx) * (1 - fy);
      sample.weight[1] = fx * (1 - fy);
      sample.weight[2] = (1 - fx) * fy;
      sample.weight[3] = fx * fy;
      sample.b = q - st * size;
      samples.push_back(sample);
    }
  }
  if (samples.empty()) return;
  constexpr double kPull = 1e-6;
  const std::size_t n = offsets.size();
  const std::vector<glm::dvec2> start = offsets;
  // (AᵀA + λI)·x
  const auto apply = [&](const std::vector<glm::dvec2>& x, std::vector<glm::dvec2>& out) {
    for (std::size_t k = 0; k < n; ++k) out[k] = kPull * x[k];
    for (const Sample& sample : samples) {
      glm::dvec2 r{0.0};
      for (int c = 0; c < 4; ++c) r += sample.weight[c] * x[sample.node[c]];
      for (int c = 0; c < 4; ++c) out[sample.node[c]] += sample.weight[c] * r;
    }
  };
  std::vector<glm::dvec2> rhs(n), r(n), p(n), Ap(n);
  for (std::size_t k = 0; k < n; ++k) rhs[k] = kPull * start[k];
  for (const Sample& sample : samples) {
    for (int c = 0; c < 4; ++c) rhs[sample.node[c]] += sample.weight[c] * sample.b;
  }
  apply(offsets, Ap);
  glm::dvec2 rr{0.0};
  for (std::size_t k = 0; k < n; ++k) {
    r[k] = rhs[k] - Ap[k];
    p[k] = r[k];
    rr += r[k] * r[k];
  }
  // x and y are independent systems with the same matrix: one CG step size each.
  double rhs_norm = 0;
  for (const glm::dvec2& v : rhs) rhs_norm += glm::dot(v, v);
  for (int iteration = 0; iteration < 1000; ++iteration) {
    if (rr.x + rr.y <= 1e-22 * std::max(rhs_norm, 1.0)) break;
    apply(p, Ap);
    glm::dvec2 pAp{0.0};
    for (std::size_t k = 0; k < n; ++k) pAp += p[k] * Ap[k];
    const glm::dvec2 alpha{pAp.x > 0 ? rr.x / pAp.x : 0.0, pAp.y > 0 ? rr.y / pAp.y : 0.0};
    glm::dvec2 rr_next{0.0};
    for (std::size_t k = 0; k < n; ++k) {
      offsets[k] += alpha * p[k];
      r[k] -= alpha * Ap[k];
      rr_next += r[k] * r[k];
    }
    const glm::dvec2 beta{rr.x > 0 ? rr_next.x / rr.x : 0.0, rr.y > 0 ? rr_next.y / rr.y : 0.0};
    for (std::size_t k = 0; k < n; ++k) p[k] = r[k] + beta * p[k];
    rr = rr_next;
  }
}

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
  for (int j = 0; j < grid.grid_size.y; ++j) {
    for (int i = 0; i < grid.grid_size.x; ++i) {
      const glm::dvec2 value = grid.st[std::size_t(j) * grid.grid_size.x + i];
      if (std::abs(value.x) > kMaxInverseGridValue || std::abs(value.y) > kMaxInverseGridValue) {
        throw InputError(source, "node (" + std::to_string(i) + ", " + std::to_string(j) + ")",
                         "a normalised position within ±1e6 (or NaN for none); got (" +
                             std::to_string(value.x) + ", " + std::to_string(value.y) + ")");
      }
    }
  }
  // The inverse grid as a Warp of its own: its base image is the output (normalised), its
  // "output" the base image of the result scaled by kAuxiliaryScale. Inverting that warp answers
  // "which output position shows st". The grid is padded by extrapolated nodes on every side, so
  // that base positions landing just outside the output image still get accurate offsets (they
  // are uncovered, but bilinear interpolation towards them must stay smooth).
  const glm::ivec2 pad{std::max(2, grid.grid_size.x / 8), std::max(2, grid.grid_size.y / 8)};
  const glm::ivec2 padded = grid.grid_size + 2 * pad;
  std::vector<glm::dvec2> st(std::size_t(padded.x) * padded.y,
                             glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  for (int j = 0; j < grid.grid_size.y; ++j) {
    for (int i = 0; i < grid.grid_size.x; ++i) {
      st[std::size_t(j + pad.y) * padded.x + i + pad.x] =
          grid.st[std::size_t(j) * grid.grid_size.x + i];
    }
  }
  const std::vector<bool> valid = fill_missing(st, padded, source);
  FACET_ASSERT(grid.shown.empty() || grid.shown.size() == grid.st.size());
  std::vector<bool> shown = valid;
  if (!grid.shown.empty()) {
    for (int j = 0; j < grid.grid_size.y; ++j) {
      for (int i = 0; i < grid.grid_size.x; ++i) {
        const std::size_t k = std::size_t(j + pad.y) * padded.x + i + pad.x;
        shown[k] = shown[k] && grid.shown[std::size_t(j) * grid.grid_size.x + i];
      }
    }
  }
  Warp auxiliary;
  auxiliary.output_size = {kAuxiliaryScale, kAuxiliaryScale};
  auxiliary.grid_size = padded;
  auxiliary.offset_px.resize(st.size());
  // Two inverses of the same nodes. `inside` counts only the nodes that were valid as covered:
  // where filled-in nodes fold over valid ones (large NaN areas, extrapolated front by front, can),
  // it still finds the valid preimage of a base position that the output shows. `anywhere` also
  // covers the filled-in and padding nodes, for the accurate offsets of base positions that land
  // just outside the output image.
  auxiliary.coverage.assign(st.size(), 1.0f);
  // Auxiliary base position (a, b) in [0,1]² ↔ normalised output position
  // ((a·(Pw−1) − pad)/(Gw−1), ...).
  const glm::dvec2 cells_in_grid = glm::dvec2(grid.grid_size - 1);
  const glm::dvec2 cells_padded = glm::dvec2(padded - 1);
  for (int j = 0; j < padded.y; ++j) {
    for (int i = 0; i < padded.x; ++i) {
      const std::size_t k = auxiliary.node_index(i, j);
      const glm::dvec2 a{double(i) / (padded.x - 1), double(j) / (padded.y - 1)};
      auxiliary.offset_px[k] = glm::vec2((st[k] - a) * double(kAuxiliaryScale));
    }
  }
  const WarpInverse anywhere(auxiliary);
  for (std::size_t k = 0; k < st.size(); ++k) auxiliary.coverage[k] = valid[k] ? 1.0f : 0.0f;
  const WarpInverse inside(std::move(auxiliary));
  // Bilinear mask of the nodes that were valid and show something, at a normalised output
  // position.
  const auto shown_at = [&](glm::dvec2 output) {
    const glm::dvec2 g = output * cells_in_grid + glm::dvec2(pad);
    const int i = std::clamp(int(std::floor(g.x)), 0, padded.x - 2);
    const int j = std::clamp(int(std::floor(g.y)), 0, padded.y - 2);
    const double fx = g.x - i, fy = g.y - j;
    const auto v = [&](int a, int b) { return shown[std::size_t(b) * padded.x + a] ? 1.0 : 0.0; };
    return (v(i, j) * (1 - fx) + v(i + 1, j) * fx) * (1 - fy) +
           (v(i, j + 1) * (1 - fx) + v(i + 1, j + 1) * fx) * fy;
  };

  Warp warp;
  warp.base = base;
  warp.R_eye_base = R_eye_base;
  warp.output_size = output_size;
  warp.grid_size = warp_grid;
  std::vector<glm::dvec2> offsets(std::size_t(warp_grid.x) * warp_grid.y,
                                  glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  std::vector<bool> covered(offsets.size(), false), from_anywhere(offsets.size(), false);
  for (int j = 0; j < warp_grid.y; ++j) {
    for (int i = 0; i < warp_grid.x; ++i) {
      const glm::dvec2 st_node{double(i) / (warp_grid.x - 1), double(j) / (warp_grid.y - 1)};
      const glm::dvec2 q_auxiliary = st_node * double(kAuxiliaryScale);
      std::optional<glm::dvec2> a = inside.st_from_q(q_auxiliary);
      const bool from_inside = a.has_value();
      if (!a) a = anywhere.st_from_q(q_auxiliary);
      from_anywhere[warp.node_index(i, j)] = a && !from_inside;
      if (a) {
        const glm::dvec2 output = (*a * cells_padded - glm::dvec2(pad)) / cells_in_grid;
        const std::size_t k = warp.node_index(i, j);
        offsets[k] = output * glm::dvec2(output_size) - st_node * glm::dvec2(output_size);
      }
    }
  }
  // A smooth map bends by a small part of a cell from one node to the next.
  const double cell_px = glm::length(glm::dvec2(output_size) / glm::dvec2(warp_grid - 1));
  drop_inconsistent(offsets, from_anywhere, warp_grid, std::max(1.0, 0.1 * cell_px));
  std::vector<bool> inverted(offsets.size());
  for (std::size_t k = 0; k < offsets.size(); ++k) inverted[k] = finite(offsets[k]);
  fill_missing(offsets, warp_grid, source);
  // A dense inverse grid says more than its values at the forward nodes: every sample is a point
  // of the map, and the map is bilinear in each forward cell. Fitting the forward offsets to all
  // samples recovers a forward warp that was itself bilinear on this grid (facet's own export)
  // where inverting at the nodes alone would leave the inverse grid's interpolation error, which
  // is first order in its spacing at the forward cells' edges. Sparser grids do not pin the cells.
  if (grid.grid_size.x >= 2 * warp_grid.x - 1 && grid.grid_size.y >= 2 * warp_grid.y - 1) {
    fit_to_samples(offsets, grid, warp_grid, output_size);
  }

  // Covered: what the output shows. Coverage is bilinear between nodes, so a node just outside the
  // image is covered too when a cell of it reaches into the image; otherwise coverage would fall
  // below 0.5 inside the image's edge pixels, by up to half a cell, which where the map crowds
  // many output pixels into a cell is several pixels the facets are not held to.
  const glm::dvec2 size(output_size);
  const auto output_of = [&](int i, int j) {
    const glm::dvec2 st_node{double(i) / (warp_grid.x - 1), double(j) / (warp_grid.y - 1)};
    return st_node + offsets[warp.node_index(i, j)] / size;
  };
  for (int j = 0; j < warp_grid.y; ++j) {
    for (int i = 0; i < warp_grid.x; ++i) {
      const std::size_t k = warp.node_index(i, j);
      const glm::dvec2 output = output_of(i, j);
      if (!inverted[k]) continue;
      const glm::dvec2 nearest = glm::clamp(output, glm::dvec2(0.0), glm::dvec2(1.0));
      glm::dvec2 reach(0.0);
      const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
      for (int d = 0; d < 4; ++d) {
        const int i1 = i + di[d], j1 = j + dj[d];
        if (i1 < 0 || j1 < 0 || i1 >= warp_grid.x || j1 >= warp_grid.y) continue;
        reach = glm::max(reach, glm::abs(output_of(i1, j1) - output));
      }
      covered[k] = glm::all(glm::lessThanEqual(glm::abs(output - nearest), reach)) &&
                   shown_at(nearest) >= 0.5;
    }
  }

  warp.offset_px.resize(offsets.size());
  warp.coverage.resize(offsets.size());
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    warp.offset_px[k] = glm::vec2(offsets[k]);
    warp.coverage[k] = covered[k] ? 1.0f : 0.0f;
  }
  warp.validate(source);
  return warp;
}

NodeDirections node_directions(const Warp& warp, glm::ivec2 grid_size, int continued_rings) {
  FACET_ASSERT(grid_size.x >= 2 && grid_size.y >= 2 && continued_rings >= 0);
  const WarpInverse inverse(warp);
  const auto q_of = [&](int i, int j) {
    return glm::dvec2(double(i) / (grid_size.x - 1) * warp.output_size.x,
                      double(j) / (grid_size.y - 1) * warp.output_size.y);
  };
  NodeDirections nodes;
  nodes.v_eye.resize(std::size_t(grid_size.x) * grid_size.y);
  nodes.shown.assign(nodes.v_eye.size(), false);
  for (int j = 0; j < grid_size.y; ++j) {
    for (int i = 0; i < grid_size.x; ++i) {
      const std::size_t k = std::size_t(j) * grid_size.x + i;
      if (auto inverted = inverse.invert(q_of(i, j))) {
        nodes.v_eye[k] = inverted->v_eye;
        nodes.shown[k] = true;
      }
    }
  }
  if (continued_rings == 0) return nodes;
  const WarpInverse continued = continued_inverse(warp);
  for (int j = 0; j < grid_size.y; ++j) {
    for (int i = 0; i < grid_size.x; ++i) {
      const std::size_t k = std::size_t(j) * grid_size.x + i;
      if (nodes.shown[k]) continue;
      // Rings as wide as the grid take every node without looking.
      bool near_shown = continued_rings >= std::max(grid_size.x, grid_size.y);
      for (int dj = -continued_rings; dj <= continued_rings && !near_shown; ++dj) {
        for (int di = -continued_rings; di <= continued_rings && !near_shown; ++di) {
          const int i1 = i + di, j1 = j + dj;
          near_shown = i1 >= 0 && j1 >= 0 && i1 < grid_size.x && j1 < grid_size.y &&
                       nodes.shown[std::size_t(j1) * grid_size.x + i1];
        }
      }
      if (!near_shown) continue;
      if (auto inverted = continued.invert(q_of(i, j))) nodes.v_eye[k] = inverted->v_eye;
    }
  }
  return nodes;
}

InverseGrid inverse_grid_from_warp(
    const Warp& warp, glm::ivec2 grid_size,
    const std::function<std::optional<glm::dvec2>(const glm::dvec3& v_eye)>& st_of_direction,
    int continued_rings) {
  const NodeDirections nodes = node_directions(warp, grid_size, continued_rings);
  InverseGrid grid;
  grid.grid_size = grid_size;
  grid.st.assign(nodes.v_eye.size(), glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  for (std::size_t k = 0; k < nodes.v_eye.size(); ++k) {
    if (!nodes.v_eye[k]) continue;
    if (auto st = st_of_direction(*nodes.v_eye[k])) grid.st[k] = *st;
  }
  if (continued_rings > 0) grid.shown = nodes.shown;
  return grid;
}

}  // namespace facet::interop
