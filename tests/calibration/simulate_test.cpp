#include "facet/calibration/simulate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>

#include "facet/calibration/capture.hpp"
#include "facet/calibration/decode.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "support/facet_cli.hpp"

namespace facet::calibration {
namespace {

glm::dmat3 look(const glm::dvec3& from, const glm::dvec3& to) {
  const glm::dvec3 forward = glm::normalize(to - from);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  return glm::dmat3(right, glm::cross(forward, right), forward);
}

// A small dome: one 64×48 projector behind the eye, a 160×120 stereographic camera at the eye.
Rig small_rig() {
  Rig rig;
  rig.screen.type = Screen::Type::sphere;
  rig.screen.radius = 4;
  ProjectorModel p;
  p.name = "p0";
  p.size = {64, 48};
  p.focal_px = {40, 40};
  p.principal_px = {31, 26};
  p.k = {-0.05, 0.005, 0};
  p.t_eye_projector = {0.2, -0.3, 1.0};
  p.R_eye_projector = look(p.t_eye_projector, {0.5, 0.8, -4});
  p.gamma = 2.2;
  rig.projectors = {p};
  rig.camera.lensmodel = "LENSMODEL_STEREOGRAPHIC";
  rig.camera.size = {160, 120};
  rig.camera.fov_deg = 150;
  return rig;
}

Rig clean(Rig rig) {
  rig.simulation.noise = 0;
  rig.simulation.defocus_px = 0;
  rig.simulation.camera_blur_px = 0;
  rig.simulation.ambient = 0;
  rig.simulation.phase = false;
  for (auto& p : rig.projectors) p.gamma = 1;
  return rig;
}

bool inside(const cv::Vec2d& q, glm::ivec2 size, double border) {
  return q[0] >= border && q[1] >= border && q[0] <= size.x - border && q[1] <= size.y - border;
}

TEST(Simulate, CleanGrayCodeDecodesExactlyToTheTrueProjectorPixel) {
  const Rig rig = clean(small_rig());
  test::TempFolder folder;
  const auto out = folder.path() / "capture";
  const SimulationReport report = simulate_capture(rig, out);
  EXPECT_EQ(report.camera_size, glm::ivec2(160, 120));
  const Capture capture = read_capture(out);
  ASSERT_EQ(capture.projectors.size(), 1u);
  EXPECT_EQ(capture.screen, rig.screen);
  const DecodedMap decoded = decode_capture(capture, 0);
  const ProjectorView view = view_projector(rig, rig_camera_model(rig.camera), 0);
  int compared = 0, wrong = 0, missed = 0;
  for (int j = 0; j < 120; ++j) {
    for (int i = 0; i < 160; ++i) {
      const cv::Vec2d truth = view.q_projector.at<cv::Vec2d>(j, i);
      const cv::Vec2d q = decoded.q_projector.at<cv::Vec2d>(j, i);
      const bool lit = inside(truth, rig.projectors[0].size, 0) &&
                       truth[0] < rig.projectors[0].size.x && truth[1] < rig.projectors[0].size.y;
      if (decoded.mask.at<std::uint8_t>(j, i) != 0) {
        missed += lit;
        continue;
      }
      ASSERT_TRUE(lit) << "decoded a camera pixel the projector does not light: " << i << "," << j;
      ++compared;
      wrong += q[0] != std::floor(truth[0]) + 0.5 || q[1] != std::floor(truth[1]) + 0.5;
    }
  }
  EXPECT_GT(compared, 2000);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(missed, 0);  // every lit pixel is bright enough to decode without noise
}

TEST(Simulate, NoisyCaptureDecodesWithinTolerance) {
  // The calibration target's settings: noise σ 1% of full scale, defocus σ 1 px, gamma 2.2,
  // 5% ambient, 16-bit, phase period 16 px in 4 steps.
  const Rig rig = small_rig();
  test::TempFolder folder;
  simulate_capture(rig, folder.path() / "capture");
  const Capture capture = read_capture(folder.path() / "capture");
  const DecodedMap decoded = decode_capture(capture, 0);
  const ProjectorView view = view_projector(rig, rig_camera_model(rig.camera), 0);
  std::vector<double> errors;
  for (int j = 0; j < 120; ++j) {
    for (int i = 0; i < 160; ++i) {
      const cv::Vec2d truth = view.q_projector.at<cv::Vec2d>(j, i);
      // FORMATS.md §5 leaves out positions within 8 px of the edge; 4 px suffices per pixel.
      if (!inside(truth, rig.projectors[0].size, 4)) continue;
      if (decoded.mask.at<std::uint8_t>(j, i) != 0) continue;
      const cv::Vec2d q = decoded.q_projector.at<cv::Vec2d>(j, i);
      errors.push_back(std::hypot(q[0] - truth[0], q[1] - truth[1]));
    }
  }
  ASSERT_GT(errors.size(), 1000u);
  double sum2 = 0;
  for (double e : errors) sum2 += e * e;
  const double rms = std::sqrt(sum2 / double(errors.size()));
  std::sort(errors.begin(), errors.end());
  const double p99 = errors[std::size_t(0.99 * double(errors.size() - 1))];
  // Per camera pixel, before any fit averages noise: RMS ≤ 0.15 px, p99 ≤ 0.5 px, max ≤ 1 px.
  EXPECT_LE(rms, 0.15);
  EXPECT_LE(p99, 0.5);
  EXPECT_LE(errors.back(), 1.0);
  RecordProperty("rms_px", std::to_string(rms));
  std::printf("noisy decode: %zu px, RMS %.4f px, p99 %.4f px, max %.4f px\n", errors.size(), rms,
              p99, errors.back());
}

TEST(Simulate, FramesAreAFunctionOfTheSeed) {
  const Rig rig = small_rig();
  const ProjectorView view = view_projector(rig, rig_camera_model(rig.camera), 0);
  const Pattern pattern = Pattern::phase(Axis::x, 16, 1, 4);
  const cv::Mat a = render_frame(rig, view, 0, pattern, 7);
  const cv::Mat b = render_frame(rig, view, 0, pattern, 7);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  Rig other = rig;
  other.simulation.seed = 2;
  const cv::Mat c = render_frame(other, view, 0, pattern, 7);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0);
  const cv::Mat d = render_frame(rig, view, 0, pattern, 8);
  EXPECT_GT(cv::norm(a, d, cv::NORM_INF), 0.0);
  // The noise has the σ asked for: compare with the noiseless frame.
  Rig quiet = rig;
  quiet.simulation.noise = 0;
  const cv::Mat e = render_frame(quiet, view, 0, pattern, 7);
  cv::Scalar mean, stddev;
  cv::meanStdDev(a - e, mean, stddev);
  EXPECT_NEAR(stddev[0], 0.01, 0.001);
}

TEST(Simulate, TruthFilesReadBackAndAgreeWithTheRig) {
  const Rig rig = small_rig();
  test::TempFolder folder;
  simulate_capture(rig, folder.path() / "capture");
  const Capture capture = read_capture(folder.path() / "capture");
  ASSERT_TRUE(capture.truth.has_value());
  const Warp warp = read_warp(capture.resolve(*capture.truth / "p0.warp.exr").string());
  EXPECT_EQ(warp.output_size, rig.projectors[0].size);
  EXPECT_EQ(read_rig(capture.resolve(*capture.truth / "rig.json")), rig);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  int covered = 0;
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec3 v = warp.v_eye_from_st({u(rng), u(rng)});
    const auto exact = exact_projector_pixel(rig.screen, rig.projectors[0], v);
    if (!exact || exact->x < 0 || exact->y < 0 || exact->x > 64 || exact->y > 48) continue;
    const auto projected = warp.project(v);
    ASSERT_TRUE(projected.has_value());
    ++covered;
    worst = std::max(worst, glm::length(projected->q - *exact));
  }
  EXPECT_GT(covered, 2000);
  EXPECT_LE(worst, 0.01);  // float32 offsets in the file included
}

// The CLI's exit status; `prefix` runs before it in the same shell (e.g. "cd DIR && ").
int run_cli_in(const std::string& prefix, const std::string& arguments) {
  std::string dropped;
  return test::run_shell(prefix + std::string(FACET_CLI) + " " + arguments, &dropped);
}

TEST(Simulate, BadRigsFailCleanlyWithNoOutput) {
  test::TempFolder folder;
  const auto out = folder.path() / "capture";
  // A lens mrcal does not know.
  Rig rig = small_rig();
  rig.camera.lensmodel = "LENSMODEL_NONSENSE";
  try {
    simulate_capture(rig, out, "r.json");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "camera.lensmodel");
  }
  EXPECT_FALSE(std::filesystem::exists(out));

  const auto bad = folder.path() / "bad.json";
  std::ofstream(bad) << R"({"format": "facet-rig/1", "screen": {"type": "sphere", "radius": 4}})";
  EXPECT_EQ(test::run_facet("simulate --rig " + bad.string() + " --out " + out.string()), 2);
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_EQ(test::run_facet("simulate --rig " + (folder.path() / "missing.json").string() +
                            " --out " + out.string()),
            2);
  EXPECT_FALSE(std::filesystem::exists(out));

  // A good rig with a bad override.
  Rig small = small_rig();
  small.camera.size = {40, 30};
  const auto good = folder.path() / "good.json";
  write_rig(good, small);
  EXPECT_EQ(
      test::run_facet("simulate --rig " + good.string() + " --out " + out.string() + " --bits 12"),
      2);
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_EQ(test::run_facet("simulate --rig " + good.string() + " --out " + out.string() +
                            " --camera-size 0x5"),
            2);
  EXPECT_FALSE(std::filesystem::exists(out));
  // No partial folder is left beside the output either.
  for (const auto& entry : std::filesystem::directory_iterator(folder.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".capture"), std::string::npos);
  }
  EXPECT_EQ(test::run_facet("simulate --rig " + good.string() + " --out " + out.string() +
                            " --no-phase --noise 0.02 --seed 3"),
            0);
  EXPECT_TRUE(std::filesystem::exists(out / "capture.json"));
  EXPECT_TRUE(std::filesystem::exists(out / "truth" / "p0.warp.exr"));
  // An existing, non-empty output folder is refused.
  EXPECT_EQ(test::run_facet("simulate --rig " + good.string() + " --out " + out.string()), 2);
}

// A built-in rig (configs/rigs, compiled in) simulates from a folder that holds no configs/; an
// unknown built-in name exits 2.
TEST(Simulate, BuiltinRigsWorkFromAnyFolder) {
  test::TempFolder folder;
  const auto out = folder.path() / "capture";
  const std::string in_folder = "cd '" + folder.path().string() + "' && ";
  EXPECT_EQ(run_cli_in(in_folder, "simulate --rig builtin:wall2x2 --out " + out.string() +
                                      " --camera-size 64x48 --no-phase"),
            0);
  EXPECT_TRUE(std::filesystem::exists(out / "capture.json"));
  EXPECT_TRUE(std::filesystem::exists(out / "truth" / "p3.warp.exr"));
  const auto unknown = folder.path() / "unknown";
  EXPECT_EQ(run_cli_in(in_folder, "simulate --rig builtin:dome5 --out " + unknown.string()), 2);
  EXPECT_FALSE(std::filesystem::exists(unknown));
}

}  // namespace
}  // namespace facet::calibration
