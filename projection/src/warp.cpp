#include "facet/projection/warp.hpp"

#include <algorithm>
#include <cmath>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

std::string node_name(int i, int j) {
  return "node (" + std::to_string(i) + ", " + std::to_string(j) + ")";
}

double cross(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

}  // namespace

void check_image_size(glm::ivec2 size, const std::string& source, const InputField& field) {
  if (size.x < 1 || size.y < 1 || size.x > kMaxImageSide || size.y > kMaxImageSide ||
      std::int64_t(size.x) * size.y > kMaxImagePixels) {
    throw InputError(source, field,
                     "a width and height from 1 to " + std::to_string(kMaxImageSide) + ", " +
                         std::to_string(kMaxImagePixels) + " pixels in all; got " +
                         std::to_string(size.x) + "x" + std::to_string(size.y));
  }
}

Warp Warp::analytic(const BaseProjection& base, glm::ivec2 output_size, glm::ivec2 grid_size,
                    const glm::dmat3& R_eye_base) {
  Warp warp;
  warp.base = base;
  warp.R_eye_base = R_eye_base;
  warp.output_size = output_size;
  warp.grid_size = grid_size;
  const std::size_t nodes = std::size_t(std::max(grid_size.x, 0)) * std::max(grid_size.y, 0);
  warp.offset_px.assign(nodes, glm::vec2(0.0f));
  warp.coverage.assign(nodes, 1.0f);
  return warp;
}

void Warp::validate(const std::string& source) const {
  base.validate(source);
  check_image_size(output_size, source, "output_size");
  if (grid_size.x < 2 || grid_size.y < 2) {
    throw InputError(source, "grid", "expected at least 2×2 nodes");
  }
  const std::size_t nodes = std::size_t(grid_size.x) * grid_size.y;
  if (offset_px.size() != nodes || coverage.size() != nodes) {
    throw InputError(source, "nodes", "expected one offset and one coverage value per node");
  }
  for (int j = 0; j < grid_size.y; ++j) {
    for (int i = 0; i < grid_size.x; ++i) {
      const std::size_t k = node_index(i, j);
      if (!std::isfinite(offset_px[k].x) || !std::isfinite(offset_px[k].y)) {
        throw InputError(source, "R,G (offset) at " + node_name(i, j), "expected finite pixels");
      }
      if (!std::isfinite(coverage[k])) {
        throw InputError(source, "A (coverage) at " + node_name(i, j),
                         "expected a finite value in [0,1]");
      }
    }
  }
  const glm::dmat3 RtR = glm::transpose(R_eye_base) * R_eye_base;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (!(std::abs(RtR[c][r] - (r == c ? 1.0 : 0.0)) < 1e-6)) {
        throw InputError(source, "rotation", "expected an orthonormal 3×3 rotation");
      }
    }
  }
  if (!(glm::determinant(R_eye_base) > 0)) {
    throw InputError(source, "rotation", "expected a proper rotation (determinant +1)");
  }
  if (auto fold = find_fold()) {
    throw InputError(source, "R,G (offset) at " + node_name(fold->x, fold->y),
                     "the offset map folds over here (the output orientation reverses or "
                     "collapses), so it is not injective");
  }
}

std::optional<glm::ivec2> Warp::find_fold() const {
  const glm::dvec2 step{double(output_size.x) / (grid_size.x - 1),
                        double(output_size.y) / (grid_size.y - 1)};
  auto q_node = [&](int i, int j) {
    return glm::dvec2(i * step.x, j * step.y) + glm::dvec2(offset_px[node_index(i, j)]);
  };
  for (int j = 0; j + 1 < grid_size.y; ++j) {
    for (int i = 0; i + 1 < grid_size.x; ++i) {
      const bool covered =
          coverage[node_index(i, j)] >= 0.5f && coverage[node_index(i + 1, j)] >= 0.5f &&
          coverage[node_index(i, j + 1)] >= 0.5f && coverage[node_index(i + 1, j + 1)] >= 0.5f;
      if (!covered) continue;
      // The bilinear cell keeps its orientation (s right, t down) iff the Jacobian is positive at
      // all four corners.
      const glm::dvec2 q00 = q_node(i, j), q10 = q_node(i + 1, j), q01 = q_node(i, j + 1),
                       q11 = q_node(i + 1, j + 1);
      const double corner_jacobians[4] = {cross(q10 - q00, q01 - q00), cross(q11 - q10, q00 - q10),
                                          cross(q01 - q11, q10 - q11), cross(q00 - q01, q11 - q01)};
      const double area_scale = step.x * step.y;
      for (int c = 0; c < 4; ++c) {
        if (!(corner_jacobians[c] > 1e-9 * area_scale)) {
          static constexpr int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
          return glm::ivec2(i + di[c], j + dj[c]);
        }
      }
    }
  }
  return std::nullopt;
}

glm::dvec2 Warp::offset_at(glm::dvec2 st) const {
  const double x = std::clamp(st.x, 0.0, 1.0) * (grid_size.x - 1);
  const double y = std::clamp(st.y, 0.0, 1.0) * (grid_size.y - 1);
  const int i = std::min(int(x), grid_size.x - 2), j = std::min(int(y), grid_size.y - 2);
  const double fx = x - i, fy = y - j;
  const glm::dvec2 o00(offset_px[node_index(i, j)]), o10(offset_px[node_index(i + 1, j)]),
      o01(offset_px[node_index(i, j + 1)]), o11(offset_px[node_index(i + 1, j + 1)]);
  return (o00 * (1 - fx) + o10 * fx) * (1 - fy) + (o01 * (1 - fx) + o11 * fx) * fy;
}

double Warp::coverage_at(glm::dvec2 st) const {
  const double x = std::clamp(st.x, 0.0, 1.0) * (grid_size.x - 1);
  const double y = std::clamp(st.y, 0.0, 1.0) * (grid_size.y - 1);
  const int i = std::min(int(x), grid_size.x - 2), j = std::min(int(y), grid_size.y - 2);
  const double fx = x - i, fy = y - j;
  return (coverage[node_index(i, j)] * (1 - fx) + coverage[node_index(i + 1, j)] * fx) * (1 - fy) +
         (coverage[node_index(i, j + 1)] * (1 - fx) + coverage[node_index(i + 1, j + 1)] * fx) * fy;
}

glm::dvec2 Warp::q_from_st(glm::dvec2 st) const {
  return glm::dvec2(st.x * output_size.x, st.y * output_size.y) + offset_at(st);
}

std::optional<Warp::Projected> Warp::project(glm::dvec3 v_eye, double s_hint) const {
  const auto st = base.st_from_direction(glm::transpose(R_eye_base) * v_eye, s_hint);
  if (!st) return std::nullopt;
  // Directions on the image's edge come back a rounding error outside it.
  constexpr double kEdge = 1e-9;
  const bool inside =
      st->x >= -kEdge && st->x <= 1 + kEdge && st->y >= -kEdge && st->y <= 1 + kEdge;
  return Projected{q_from_st(*st), *st, inside && coverage_at(*st) >= 0.5};
}

}  // namespace facet
