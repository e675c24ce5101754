#pragma once
// Shared helpers of the interop tests: running the CLI and small synthetic warps.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <glm/glm.hpp>
#include <string>

#include "facet/projection/warp.hpp"
#include "support/facet_cli.hpp"

namespace facet::interop::test {

using facet::test::TempFolder;

// What `facet <arguments>` exited with and printed (stdout and stderr, also left in
// SCRATCH/cli.log); with limit_s > 0 it runs under timeout(1), which exits 124 on expiry.
struct CliRun {
  int status;
  std::string output;
};
inline CliRun run(const std::string& arguments, const std::filesystem::path& scratch,
                  int limit_s = 0) {
  const int status = facet::test::run_facet(arguments, scratch / "cli.log", limit_s);
  return {status, facet::test::slurp(scratch / "cli.log")};
}

// A warp like a calibrated one: a perspective base lined up with the projector (asymmetric
// extents, turned by yaw, pitch and roll) plus smooth offsets of up to about 12 px.
inline Warp calibrated_like_warp(glm::ivec2 output_size = {640, 400}, glm::ivec2 grid = {33, 21}) {
  Warp warp =
      Warp::analytic(BaseProjection::perspective(-0.7, 0.9, 0.55, -0.45), output_size, grid);
  const double yaw = glm::radians(-35.0), pitch = glm::radians(20.0), roll = glm::radians(7.0);
  const glm::dmat3 Ry{std::cos(yaw), 0, -std::sin(yaw), 0, 1, 0, std::sin(yaw), 0, std::cos(yaw)};
  const glm::dmat3 Rx{
      1, 0, 0, 0, std::cos(pitch), std::sin(pitch), 0, -std::sin(pitch), std::cos(pitch)};
  const glm::dmat3 Rz{
      std::cos(roll), std::sin(roll), 0, -std::sin(roll), std::cos(roll), 0, 0, 0, 1};
  warp.R_eye_base = Ry * Rx * Rz;
  for (int j = 0; j < grid.y; ++j) {
    for (int i = 0; i < grid.x; ++i) {
      const double s = double(i) / (grid.x - 1), t = double(j) / (grid.y - 1);
      warp.offset_px[warp.node_index(i, j)] =
          glm::vec2(float(8 * std::sin(2.1 * s + 0.4) * std::cos(1.3 * t) + 3 * s * t),
                    float(-6 * std::cos(1.7 * s) * std::sin(2.4 * t + 0.2) + 4 * s));
    }
  }
  return warp;
}

// Where `original` sends eye directions against where `back` sends them (their bases may differ),
// over a `samples`² st lattice of `original`, skipping directions it does not cover and output
// positions within `margin_px` of the image edge: the worst distance, output px, among directions
// `back` covers; how many were compared; how many `back` does not cover.
struct DirectionDifference {
  double worst_px = 0;
  int compared = 0;
  int uncovered = 0;
};
inline DirectionDifference direction_difference(const Warp& original, const Warp& back,
                                                double margin_px, int samples = 81) {
  DirectionDifference d;
  for (int j = 0; j < samples; ++j) {
    for (int i = 0; i < samples; ++i) {
      const glm::dvec2 st{double(i) / (samples - 1), double(j) / (samples - 1)};
      if (original.coverage_at(st) < 0.5) continue;
      const glm::dvec2 q = original.q_from_st(st);
      if (q.x < margin_px || q.y < margin_px || q.x > original.output_size.x - margin_px ||
          q.y > original.output_size.y - margin_px) {
        continue;
      }
      const auto p = back.project(original.v_eye_from_st(st));
      if (!p || !p->covered) {
        ++d.uncovered;
        continue;
      }
      d.worst_px = std::max(d.worst_px, glm::length(p->q - q));
      ++d.compared;
    }
  }
  return d;
}

}  // namespace facet::interop::test
