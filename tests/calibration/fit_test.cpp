// Warp fitting on synthetic correspondences with a known analytic warp and injected noise.
#include "facet/calibration/fit.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "facet/projection/errors.hpp"

namespace fc = facet::calibration;

namespace {

// A projector as seen from the eye: a pinhole with radial distortion, looking 30° to the right
// and 20° up, rolled by 10°. Projector position q (output pixels) → eye direction v.
struct TruthProjector {
  glm::ivec2 size{320, 240};
  double focal_px = 300;
  double k1 = 0.08;
  glm::dmat3 R_eye_projector;

  TruthProjector() {
    const double yaw = glm::radians(-30.0), pitch = glm::radians(20.0), roll = glm::radians(10.0);
    const glm::dmat3 Ry(std::cos(yaw), 0, -std::sin(yaw), 0, 1, 0, std::sin(yaw), 0, std::cos(yaw));
    const glm::dmat3 Rx(1, 0, 0, 0, std::cos(pitch), std::sin(pitch), 0, -std::sin(pitch),
                        std::cos(pitch));
    const glm::dmat3 Rz(std::cos(roll), std::sin(roll), 0, -std::sin(roll), std::cos(roll), 0, 0, 0,
                        1);
    R_eye_projector = Ry * Rx * Rz;
  }
  glm::dvec3 v_eye(glm::dvec2 q) const {
    const glm::dvec2 m = (q - glm::dvec2(size) * 0.5) / focal_px;
    const double r2 = glm::dot(m, m);
    const glm::dvec2 d = m * (1 + k1 * r2);
    // Projector image y grows downwards; its frame has y up.
    return glm::normalize(R_eye_projector * glm::dvec3(d.x, -d.y, -1));
  }
};

struct Errors {
  double rms = 0, p99 = 0, max = 0;
  std::size_t compared = 0, uncovered = 0;
};

// Error at projector pixel centres at least 8 px from the edge (FORMATS.md §5).
Errors evaluate(const TruthProjector& truth, const facet::Warp& warp) {
  std::vector<double> errors;
  Errors result;
  for (int y = 8; y < truth.size.y - 8; ++y) {
    for (int x = 8; x < truth.size.x - 8; ++x) {
      const glm::dvec2 q(x + 0.5, y + 0.5);
      const auto projected = warp.project(truth.v_eye(q));
      if (!projected || !projected->covered) {
        ++result.uncovered;
        continue;
      }
      errors.push_back(glm::length(projected->q - q));
    }
  }
  double sum = 0;
  for (const double e : errors) sum += e * e;
  result.compared = errors.size();
  result.rms = std::sqrt(sum / double(errors.size()));
  std::sort(errors.begin(), errors.end());
  result.p99 = errors[std::size_t(0.99 * double(errors.size()))];
  result.max = errors.back();
  return result;
}

// Samples as a camera of `density` samples per projector pixel would give them, each position
// perturbed by Gaussian noise of sigma_px per axis; `quantise` keeps only the pixel centre (Gray
// code alone); a share of gross outliers models wrong Gray codes.
std::vector<fc::FitSample> make_samples(const TruthProjector& truth, double density,
                                        double sigma_px, bool quantise, double outlier_share,
                                        unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> noise(0, sigma_px);
  const std::size_t count = std::size_t(density * truth.size.x * truth.size.y);
  std::vector<fc::FitSample> samples;
  for (std::size_t k = 0; k < count; ++k) {
    const glm::dvec2 q_true(uniform(random) * truth.size.x, uniform(random) * truth.size.y);
    glm::dvec2 q = quantise ? glm::floor(q_true) + 0.5 : q_true;
    q += glm::dvec2(noise(random), noise(random));
    if (uniform(random) < outlier_share) q += glm::dvec2(uniform(random) - 0.5, 0) * 64.0;
    samples.push_back({truth.v_eye(q_true), q, 1.0f});
  }
  return samples;
}

}  // namespace

// Phase-like noise of 0.3 px per axis plus 1% wrong codes: the FORMATS.md §5 errors must meet
// the calibration targets (RMS ≤ 0.1 px, p99 ≤ 0.3 px, max ≤ 1 px).
TEST(FitWarp, NoisyCorrespondencesMeetTheTargets) {
  const TruthProjector truth;
  const auto samples = make_samples(truth, 0.5, 0.3, false, 0.01, 1);
  const fc::WarpFit fit = fc::fit_warp(samples, truth.size);
  const Errors errors = evaluate(truth, fit.warp);
  EXPECT_LE(errors.rms, 0.1);
  EXPECT_LE(errors.p99, 0.3);
  EXPECT_LE(errors.max, 1.0);
  EXPECT_EQ(errors.uncovered, 0u);
  EXPECT_EQ(fit.report.folds, 0u);
  EXPECT_EQ(fit.report.samples, samples.size());
  // The residual reflects the injected noise: sqrt(2)·0.3 px RMS over both axes, plus outliers.
  EXPECT_NEAR(fit.report.residual_p50_px, 0.3 * 1.1774, 0.05);
  EXPECT_NEAR(fit.report.outlier_fraction, 0.01, 0.005);
  std::printf("noisy: rms %.4f p99 %.4f max %.4f px over %zu pixels, grid %dx%d\n", errors.rms,
              errors.p99, errors.max, errors.compared, fit.report.grid.x, fit.report.grid.y);
}

// Gray code alone: positions quantised to pixel centres; target RMS ≤ 0.3 px.
TEST(FitWarp, QuantisedCorrespondencesMeetTheGrayCodeTarget) {
  const TruthProjector truth;
  const auto samples = make_samples(truth, 0.5, 0.0, true, 0.0, 2);
  const fc::WarpFit fit = fc::fit_warp(samples, truth.size);
  const Errors errors = evaluate(truth, fit.warp);
  std::printf("gray: rms %.4f p99 %.4f max %.4f px\n", errors.rms, errors.p99, errors.max);
  EXPECT_LE(errors.rms, 0.3);
  EXPECT_LE(errors.max, 1.0);
  EXPECT_EQ(errors.uncovered, 0u);
}

// The fitted coverage ends at the image edge: directions a few pixels outside are not covered.
TEST(FitWarp, CoverageEndsAtTheProjectorEdge) {
  const TruthProjector truth;
  const auto samples = make_samples(truth, 0.5, 0.3, false, 0.0, 3);
  const fc::WarpFit fit = fc::fit_warp(samples, truth.size);
  int wrong = 0, checked = 0;
  for (int x = 0; x < truth.size.x; x += 4) {
    for (const double y : {-6.0, double(truth.size.y) + 6.0}) {
      const auto projected = fit.warp.project(truth.v_eye({x + 0.5, y}));
      wrong += projected && projected->covered ? 1 : 0;
      ++checked;
    }
  }
  EXPECT_EQ(wrong, 0) << "of " << checked << " directions 6 px outside the image";
}

// A small gap in the samples is filled by extrapolation and stays covered; a large part of the
// image the camera never saw is reported as holes and left uncovered rather than guessed.
TEST(FitWarp, FillsSmallGapsAndReportsHoles) {
  const TruthProjector truth;
  const glm::dvec2 centre(160, 120);
  for (const double radius : {20.0, 60.0}) {
    auto samples = make_samples(truth, 0.5, 0.3, false, 0.0, 4);
    std::erase_if(samples,
                  [&](const fc::FitSample& s) { return glm::length(s.q - centre) < radius; });
    const fc::WarpFit fit = fc::fit_warp(samples, truth.size);
    EXPECT_EQ(fit.report.folds, 0u);
    const auto projected = fit.warp.project(truth.v_eye(centre));
    ASSERT_TRUE(projected.has_value());
    if (radius < 30) {
      EXPECT_GT(fit.report.filled, 0u);
      EXPECT_EQ(fit.report.holes, 0u);
      EXPECT_TRUE(projected->covered);
      // Extrapolated over about 1.5 node spacings from each side with 0.3 px noise.
      EXPECT_LT(glm::length(projected->q - centre), 0.5);
    } else {
      EXPECT_GT(fit.report.holes, 0u);
      EXPECT_FALSE(projected->covered);
    }
  }
}

TEST(FitWarp, TooFewSamplesIsAnInputError) {
  const TruthProjector truth;
  const auto samples = make_samples(truth, 0.0003, 0.3, false, 0.0, 5);
  EXPECT_THROW(fc::fit_warp(samples, truth.size, {}, "capture.json"), facet::InputError);
}
