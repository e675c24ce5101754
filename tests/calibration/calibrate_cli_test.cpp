// `facet calibrate` on bad captures: exit status 2 and no output folder; on the real
// procam-board capture: no pin-holes in the output.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/calibration/calibrate.hpp"
#include "facet/calibration/image_io.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/facet_error.hpp"
#include "facet/projection/facets.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "support/facet_cli.hpp"

namespace fs = std::filesystem;

using facet::test::run_facet;
using facet::test::slurp;

namespace {

// The real procam-board capture, with its images referenced from the shared folder.
nlohmann::json board_capture(const fs::path& into) {
  const fs::path source = fs::path(FACET_SHARED_DATA_DIR) / "captures/procam-board";
  std::ifstream stream(source / "capture.json");
  nlohmann::json capture = nlohmann::json::parse(stream);
  fs::copy_file(source / "camera.cameramodel", into / "camera.cameramodel");
  for (auto& projector : capture["projectors"]) {
    for (auto& frame : projector["frames"]) {
      const fs::path file = source / frame["file"].get<std::string>();
      fs::create_symlink(file, into / file.filename());
      frame["file"] = file.filename().string();
    }
  }
  return capture;
}

void write(const fs::path& path, const nlohmann::json& value) { std::ofstream(path) << value; }

// procam-board calibrated once per test run (about 4 s).
struct BoardCalibration {
  facet::test::TempFolder folder;
  fs::path out;
  facet::calibration::CalibrationReport report;
};
const BoardCalibration& board_calibration() {
  static std::optional<BoardCalibration> cached;
  if (!cached) {
    cached.emplace();
    cached->out = cached->folder.path() / "out";
    cached->report = facet::calibration::calibrate(
        fs::path(FACET_SHARED_DATA_DIR) / "captures/procam-board", cached->out);
  }
  return *cached;
}

// Unlit output pixels inside the lit region: a pixel is inside when the 8 pixels at
// (±r, 0), (0, ±r) and (±r, ±r) from it are all lit, so any unlit speck narrower than r (and any
// hole narrower than 2r whose middle is tested) counts, while notches in the region's outer edge
// do not.
std::size_t unlit_inside(const facet::projection_io::BlendMap& blend, int r) {
  const glm::ivec2 size = blend.size;
  auto lit = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < size.x && y < size.y &&
           blend.values[std::size_t(y) * size.x + x] > 0;
  };
  std::size_t unlit = 0;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      if (lit(x, y)) continue;
      bool inside = true;
      for (int dy = -r; dy <= r && inside; dy += r) {
        for (int dx = -r; dx <= r && inside; dx += r) {
          if (dx != 0 || dy != 0) inside = lit(x + dx, y + dy);
        }
      }
      unlit += inside ? 1 : 0;
    }
  }
  return unlit;
}

}  // namespace

TEST(CliCalibrate, BadCapturesExitWithStatusTwoAndWriteNothing) {
  const facet::test::TempFolder temp;
  const fs::path capture = temp.path() / "cap", out = temp.path() / "out";
  fs::create_directories(capture);
  const nlohmann::json good = board_capture(capture);

  EXPECT_EQ(run_facet("calibrate " + (temp.path() / "none").string() + " --out " + out.string()),
            2);

  nlohmann::json missing_frame = good;
  // The most significant column bit and its inverse.
  missing_frame["projectors"][0]["frames"].erase(1);
  missing_frame["projectors"][0]["frames"].erase(0);
  write(capture / "capture.json", missing_frame);
  EXPECT_EQ(run_facet("calibrate " + capture.string() + " --out " + out.string()), 2);

  nlohmann::json missing_model = good;
  missing_model["camera"]["model"] = "nowhere.cameramodel";
  write(capture / "capture.json", missing_model);
  EXPECT_EQ(run_facet("calibrate " + capture.string() + " --out " + out.string()), 2);

  nlohmann::json unreadable = good;
  std::ofstream(capture / "broken.png") << "not a png";
  unreadable["projectors"][0]["frames"][0]["file"] = "broken.png";
  write(capture / "capture.json", unreadable);
  EXPECT_EQ(run_facet("calibrate " + capture.string() + " --out " + out.string()), 2);

  write(capture / "capture.json", good);
  EXPECT_EQ(run_facet("calibrate " + capture.string() + " --out " + out.string() + " --grid 1x5"),
            2);

  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(temp.path())) {
    EXPECT_TRUE(entry.path() == capture) << "left behind: " << entry.path();
  }
}

// The real board capture: decoding fails on the chessboard's black squares (nodes with too few
// samples, formerly extrapolated three rings deep and uncovered: about 14 black pin-holes) and
// along the shadow at the bottom (wrong codes, formerly 53 nodes uncovered by folds). Enclosed
// holes are interpolated from all sides and folded cells interpolated again, so the blend map has
// no unlit pixel inside its lit region (r = 24 px, bridge_px: the widest hole the coverage bridges;
// 544 such pixels without the hole filling, 40 without the fold refilling), and the fit residual
// over the covered samples stays within a stated margin of the 0.388 px median and 3.15 px p99
// it had before: the median within 0.02 px; the p99 within 0.5 px, as the refilled nodes now
// cover samples along the shadow's edge that the folds had uncovered (3.39 px).
TEST(CliCalibrate, RealBoardOutputHasNoPinHoles) {
  const BoardCalibration& board = board_calibration();
  ASSERT_EQ(board.report.projectors.size(), 1u);
  const auto& projector = board.report.projectors.front();
  const auto blend =
      facet::projection_io::read_blend_map((board.out / "projector.blend.exr").string());
  const std::size_t unlit = unlit_inside(blend, 24);
  std::printf(
      "procam-board: coverage %.4f, holes filled %zu, folds refilled %zu, folds %zu, "
      "residual p50 %.3f p99 %.3f rms %.3f px, unlit inside %zu\n",
      projector.coverage, projector.fit.holes_filled, projector.fit.folds_refilled,
      projector.fit.folds, projector.fit.residual_p50_px, projector.fit.residual_p99_px,
      projector.fit.residual_rms_px, unlit);
  EXPECT_EQ(unlit, 0u);
  // No covered cell of the warp written folds, and fewer nodes are cut back for folding than the
  // 53 uncovered before (37 now, along the shadow's edge, where cutting leaves no pin-hole).
  EXPECT_FALSE(facet::read_warp((board.out / "projector.warp.exr").string()).find_fold());
  EXPECT_LE(projector.fit.folds, 40u);
  EXPECT_GT(projector.fit.holes_filled, 0u);
  EXPECT_LT(projector.fit.residual_p50_px, 0.388 + 0.02);
  EXPECT_LT(projector.fit.residual_p99_px, 3.15 + 0.5);
  EXPECT_GT(projector.coverage, 0.47);
}

namespace {

// A projector report that meets every threshold with room to spare.
facet::calibration::ProjectorReport good_projector() {
  facet::calibration::ProjectorReport projector;
  projector.name = "p";
  projector.coverage = 0.99;
  projector.fit.supported = 1000;
  projector.fit.residual_p50_px = 0.1;
  projector.fit.residual_p99_px = 0.5;
  projector.fit.worst_region_rms_px = 0.6;
  return projector;
}

}  // namespace

TEST(Verdict, EachThresholdMakesItCheckOrBad) {
  using facet::calibration::judge;
  using facet::calibration::Verdict;
  EXPECT_EQ(judge(good_projector()).verdict, Verdict::good);
  EXPECT_TRUE(judge(good_projector()).reasons.empty());

  struct Case {
    const char* what;
    void (*change)(facet::calibration::ProjectorReport&);
    Verdict expected;
  };
  const Case cases[] = {
      // At a threshold is not past it.
      {"residual p99", [](auto& p) { p.fit.residual_p99_px = 2.0; }, Verdict::good},
      {"residual p99", [](auto& p) { p.fit.residual_p99_px = 2.01; }, Verdict::check},
      {"residual p99", [](auto& p) { p.fit.residual_p99_px = 5.01; }, Verdict::bad},
      {"residual p50", [](auto& p) { p.fit.residual_p50_px = 0.51; }, Verdict::check},
      {"residual p50", [](auto& p) { p.fit.residual_p50_px = 1.01; }, Verdict::bad},
      {"worst region", [](auto& p) { p.fit.worst_region_rms_px = 2.01; }, Verdict::check},
      {"worst region", [](auto& p) { p.fit.worst_region_rms_px = 5.01; }, Verdict::bad},
      {"coverage", [](auto& p) { p.coverage = 0.9; }, Verdict::good},
      {"coverage", [](auto& p) { p.coverage = 0.89; }, Verdict::check},
      {"coverage", [](auto& p) { p.coverage = 0.09; }, Verdict::bad},
      {"holes filled", [](auto& p) { p.fit.holes_filled = 50; }, Verdict::good},
      {"holes filled", [](auto& p) { p.fit.holes_filled = 51; }, Verdict::check},
      {"holes filled", [](auto& p) { p.fit.holes_filled = 251; }, Verdict::bad},
      {"folds cut", [](auto& p) { p.fit.folds = 1; }, Verdict::check},
      {"unlit pixels", [](auto& p) { p.unlit_inside = 1; }, Verdict::bad},
  };
  for (const Case& c : cases) {
    auto projector = good_projector();
    c.change(projector);
    const auto verdict = judge(projector);
    EXPECT_EQ(verdict.verdict, c.expected)
        << c.what << ": " << ::testing::PrintToString(verdict.reasons);
    if (c.expected == Verdict::good) {
      EXPECT_TRUE(verdict.reasons.empty()) << c.what;
    } else {
      ASSERT_EQ(verdict.reasons.size(), 1u) << c.what;
      EXPECT_NE(verdict.reasons[0].find(c.what), std::string::npos) << verdict.reasons[0];
      EXPECT_NE(verdict.reasons[0].find(facet::calibration::to_string(c.expected)),
                std::string::npos)
          << verdict.reasons[0];
    }
  }
  // The worst reason wins.
  auto projector = good_projector();
  projector.fit.folds = 3;
  projector.unlit_inside = 5;
  const auto verdict = judge(projector);
  EXPECT_EQ(verdict.verdict, Verdict::bad);
  EXPECT_EQ(verdict.reasons.size(), 2u);
}

// procam-board: half the projector's image falls beside the board (coverage 48 %), the shadow's
// edge leaves a 3.4 px residual p99 and a 4.1 px worst region: "check", with reasons, in the JSON
// report and in the text summary.
TEST(Verdict, RealBoardIsCheckInJsonAndText) {
  const BoardCalibration& board = board_calibration();
  const nlohmann::json json = board.report.to_json();
  EXPECT_EQ(json["verdict"], "check");
  const nlohmann::json& projector = json["projectors"][0];
  EXPECT_EQ(projector["verdict"], "check");
  EXPECT_EQ(projector["unlit_inside"], 0);
  EXPECT_GE(projector["reasons"].size(), 2u);
  // The worst region lies along the shadow at the bottom of the lit region (y about 656).
  EXPECT_GT(projector["worst_region_px"][1].get<double>(), 600);
  EXPECT_GT(projector["worst_region_rms_px"].get<double>(), 2.0);

  const facet::test::TempFolder temp;
  const fs::path text = temp.path() / "summary.txt";
  ASSERT_EQ(run_facet("calibrate " + std::string(FACET_SHARED_DATA_DIR) +
                          "/captures/procam-board --out " + (temp.path() / "out").string(),
                      text),
            0);
  const std::string summary = slurp(text);
  std::printf("%s", summary.c_str());
  for (const char* expected :
       {"projector    coverage", "p50 px", "p99 px", "worst region", "verdict",
        "projector: residual p99 3.", "(check)", "verdict: check"}) {
    EXPECT_NE(summary.find(expected), std::string::npos) << expected << " in\n" << summary;
  }
  EXPECT_EQ(summary.find("(bad)"), std::string::npos) << summary;
}

#ifndef FACET_TEST_WITHOUT_DRIVER
namespace {

// The RGB colour of pixel (x, y) of an 8-bit RGB image file.
std::array<int, 3> rgb_at(const fs::path& path, int x, int y) {
  auto input = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(input) << path;
  if (!input) return {-1, -1, -1};
  std::array<std::uint8_t, 3> pixel{};
  std::vector<std::uint8_t> row(std::size_t(input->spec().width) * 3);
  input->read_scanline(y, 0, OIIO::TypeDesc::UINT8, row.data());
  for (int c = 0; c < 3; ++c) pixel[std::size_t(c)] = row[std::size_t(x) * 3 + std::size_t(c)];
  return {pixel[0], pixel[1], pixel[2]};
}

// The RGB pixels of an image file (its first three channels), row-major.
std::vector<std::uint8_t> rgb_pixels(const fs::path& path, glm::ivec2& size) {
  auto input = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(input) << path;
  if (!input) return {};
  const OIIO::ImageSpec& spec = input->spec();
  size = {spec.width, spec.height};
  std::vector<std::uint8_t> all(std::size_t(spec.width) * spec.height * spec.nchannels);
  input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, all.data());
  std::vector<std::uint8_t> rgb(std::size_t(spec.width) * spec.height * 3);
  for (std::size_t i = 0; i < std::size_t(spec.width) * spec.height; ++i)
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = all[i * spec.nchannels + std::size_t(c)];
  return rgb;
}

}  // namespace

// report/: per projector a residual heat map and a coverage map at the output's size, and the
// display seen from the eye, by projector (composite.png) and by residual (preview.png). On
// procam-board the black square whose undecoded middle sits near output pixel (280, 328) is a
// filled hole (blue 0, 110, 255), the wall left of the board is covered and plain (grey 160), the
// wall above it unlit (black); the residual map is black where no sample falls and, on the plain
// wall, in the scale's colour of that 8×8 block's RMS residual.
TEST(CliCalibrate, RealBoardReportHasResidualAndCoverageMaps) {
  const BoardCalibration& board = board_calibration();
  const fs::path coverage = board.out / "report/projector.coverage.png";
  const fs::path residual = board.out / "report/projector.residual.png";
  for (const fs::path& path : {coverage, residual}) {
    const auto info = facet::calibration::read_image_info(path);
    EXPECT_EQ(info.size, glm::ivec2(1024, 768)) << path;
    EXPECT_EQ(info.channels, 3) << path;
  }
  EXPECT_EQ(rgb_at(coverage, 280, 328), (std::array<int, 3>{0, 110, 255}));
  EXPECT_EQ(rgb_at(coverage, 120, 300), (std::array<int, 3>{160, 160, 160}));
  EXPECT_EQ(rgb_at(coverage, 500, 100), (std::array<int, 3>{0, 0, 0}));
  EXPECT_EQ(rgb_at(residual, 500, 100), (std::array<int, 3>{0, 0, 0}));
  // The colour scale: below 0.5 px, from blue (0 px) to green (0.5 px), linearly.
  const float rms = board.report.projectors[0].fit.residual_map.at<float>(300 / 8, 120 / 8);
  ASSERT_LT(rms, 0.5f);
  const auto wall = rgb_at(residual, 120, 300);
  EXPECT_EQ(wall[0], 0);
  EXPECT_NEAR(wall[1], 255 * rms / 0.5, 1.0) << rms << " px";
  EXPECT_NEAR(wall[2], 255 * (1 - rms / 0.5), 1.0) << rms << " px";
  // report/preview.png: the display as seen from the eye (a fisheye about the projector's mean
  // direction, 768 rows) coloured by the residual; its centre is covered, its corner outside the
  // fisheye's disc black.
  const fs::path preview = board.out / "report/preview.png";
  const auto info = facet::calibration::read_image_info(preview);
  EXPECT_EQ(info.size, glm::ivec2(768, 768));
  EXPECT_EQ(info.channels, 3);
  EXPECT_NE(rgb_at(preview, 384, 384), (std::array<int, 3>{0, 0, 0}));
  EXPECT_EQ(rgb_at(preview, 767, 767), (std::array<int, 3>{0, 0, 0}));

  // report/composite.png: the same view coloured by projector, blended, as facet preview draws
  // it: pixel for pixel what `facet preview` draws of the display.json calibrate wrote.
  const fs::path composite = board.out / "report/composite.png";
  const auto composite_info = facet::calibration::read_image_info(composite);
  EXPECT_EQ(composite_info.size, glm::ivec2(768, 768));
  EXPECT_EQ(composite_info.channels, 3);
  const facet::test::TempFolder temp;
  const fs::path drawn = temp.path() / "preview.png";
  const fs::path figures = temp.path() / "figures.json";
  const std::string command =
      std::string(FACET_CLI) + " preview " + (board.out / "display.json").string() +
      " --preview-size 768 --json --out " + drawn.string() + " > " + figures.string();
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  glm::ivec2 size{0}, drawn_size{0};
  const std::vector<std::uint8_t> pixels = rgb_pixels(composite, size);
  const std::vector<std::uint8_t> expected = rgb_pixels(drawn, drawn_size);
  ASSERT_EQ(size, drawn_size);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i) differing += pixels[i] != expected[i] ? 1 : 0;
  EXPECT_EQ(differing, 0u);
  // Its covered region: inside the fisheye's disc, the pixels in colour (a projector's) rather
  // than grey (uncovered, with or without a grid line). On the fitted view of this one narrow
  // projector (a fisheye about 30° wide, where every pixel's solid angle is within 2% of the
  // others'), their share of the disc is preview's covered_sr / view_sr within 0.01.
  std::size_t disc = 0, covered = 0;
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      const double dx = x + 0.5 - size.x / 2.0, dy = y + 0.5 - size.y / 2.0;
      if (dx * dx + dy * dy >= size.y * size.y / 4.0) continue;
      const std::uint8_t* p = &pixels[(std::size_t(y) * size.x + x) * 3];
      ++disc;
      covered += p[0] != p[1] || p[1] != p[2] ? 1 : 0;
    }
  std::ifstream figures_stream(figures);
  const nlohmann::json json = nlohmann::json::parse(figures_stream);
  const double expected_share = json["covered_sr"].get<double>() / json["view_sr"].get<double>();
  const double share = double(covered) / double(disc);
  std::printf(
      "composite.png: %zu of %zu disc pixels covered (%.4f); preview covers %.4f of the "
      "view's solid angle (fov %.0f deg)\n",
      covered, disc, share, expected_share, json["fov_deg"].get<double>());
  EXPECT_GT(covered, 0u);
  EXPECT_NEAR(share, expected_share, 0.01);
}
#endif

// A run never refuses over a whisker (facets.hpp, kRunNearMiss). The procam-board display at half
// its size (as `facet run --scale 0.5` previews it) with a tolerance of 0.29 px is a near miss:
// of the builder's three tries the best reaches 0.301 px, 3.9 % over. Within 10 % the facets are
// kept, with one warning naming the display's own field; beyond the fraction the build is
// refused with an error naming that field and the tolerance to set.
namespace {

constexpr double kNearMissPx = 0.29;

// The board's warp as scale_session_display makes it for --scale 0.5.
facet::Warp half_size_board_warp() {
  facet::Warp warp = facet::read_warp((board_calibration().out / "projector.warp.exr").string());
  const glm::ivec2 old_size = warp.output_size;
  warp.output_size = old_size / 2;
  const glm::vec2 ratio = glm::vec2(warp.output_size) / glm::vec2(old_size);
  for (glm::vec2& offset : warp.offset_px) offset *= ratio;
  return warp;
}

#ifndef FACET_TEST_WITHOUT_DRIVER
// A copy of the board's display folder whose display.json sets render.tolerance_px.
fs::path board_display_with_tolerance(const fs::path& folder, double tolerance_px) {
  for (const char* file : {"projector.warp.exr", "projector.blend.exr"})
    fs::copy_file(board_calibration().out / file, folder / file);
  std::ifstream stream(board_calibration().out / "display.json");
  nlohmann::json display = nlohmann::json::parse(stream);
  display["render"]["tolerance_px"] = tolerance_px;
  write(folder / "display.json", display);
  return folder / "display.json";
}
#endif

}  // namespace

TEST(NearMiss, KeptWithinItsFractionWithOneWarningAndRefusedBeyond) {
  const facet::Warp warp = half_size_board_warp();
  facet::FacetBuildOptions options;
  options.layout = facet::FacetTolerance{kNearMissPx};
  options.near_miss = facet::kRunNearMiss;
  options.origin = {"disp/display.json", "render.tolerance_px", "projector"};
  std::vector<std::string> warnings;
  options.warn = [&](const std::string& line) { warnings.push_back(line); };
  const facet::FacetMesh mesh = facet::build_facets(warp, options);
  ASSERT_TRUE(mesh.tolerance_miss) << "the half-size board warp no longer misses " << kNearMissPx
                                   << " px: choose another tolerance (probe: build_facets with "
                                      "near_miss 1 and read tolerance_miss)";
  const double over = mesh.tolerance_miss->max_px / kNearMissPx - 1;
  std::printf("%g px: the facets kept reach %.5f px (%.2f %% over)\n", kNearMissPx,
              mesh.tolerance_miss->max_px, 100 * over);
  EXPECT_GT(over, 0.0);
  EXPECT_LE(over, facet::kRunNearMiss);
  const facet::FacetError measured = facet::evaluate_facet_error(warp, mesh);
  EXPECT_DOUBLE_EQ(measured.max_px, mesh.tolerance_miss->max_px);
  ASSERT_EQ(warnings.size(), 1u);
  std::printf("warning: %s\n", warnings[0].c_str());
  for (const char* part : {"disp/display.json: field 'render.tolerance_px'", "output 'projector'",
                           "0.29 px not met", "rendering with them"})
    EXPECT_NE(warnings[0].find(part), std::string::npos) << part << " in " << warnings[0];

  // Beyond the accepted fraction (here 1 %, under the 3.9 % missed) the same build is refused.
  options.near_miss = 0.01;
  warnings.clear();
  try {
    facet::build_facets(warp, options);
    ADD_FAILURE() << "a miss beyond near_miss was kept";
  } catch (const facet::InputError& error) {
    std::printf("error: %s\n", error.what());
    EXPECT_EQ(error.source(), "disp/display.json");
    EXPECT_EQ(error.field(), "render.tolerance_px");
    EXPECT_NE(error.expected().find("still reach 0.301 px"), std::string::npos) << error.what();
    EXPECT_NE(error.expected().find("set it to 0.31 px or more"), std::string::npos)
        << error.what();
  }
  EXPECT_TRUE(warnings.empty());
}

#ifndef FACET_TEST_WITHOUT_DRIVER
// facet run --headless on that display renders (exit 0) and says why once; a tolerance no build
// can meet stops it with exit 2 and an error naming display.json's render.tolerance_px.
TEST(NearMiss, RunRendersANearMissWithAWarningAndNamesTheDisplaysField) {
  const facet::test::TempFolder temp;
  const fs::path display = board_display_with_tolerance(temp.path(), kNearMissPx);
  const fs::path log = temp.path() / "run.log";
  const int status =
      run_facet("run " + display.string() + " --headless --scale 0.5 --frames 1 --out " +
                    (temp.path() / "frames").string(),
                log);
  const std::string output = slurp(log);
  std::printf("%s", output.c_str());
  EXPECT_EQ(status, 0) << output;
  EXPECT_TRUE(fs::exists(temp.path() / "frames/projector/00000.png")) << output;
  const std::string warning = "facet run: warning: " + display.string() +
                              ": field 'render.tolerance_px': output 'projector': 0.29 px not met";
  EXPECT_NE(output.find(warning), std::string::npos) << output;
  EXPECT_EQ(output.find("warning:"), output.rfind("warning:")) << "one warning: " << output;

  const facet::test::TempFolder far;
  const fs::path tight = board_display_with_tolerance(far.path(), 1e-9);
  const fs::path far_log = far.path() / "run.log";
  const int far_status =
      run_facet("run " + tight.string() + " --headless --scale 0.5 --frames 1 --out " +
                    (far.path() / "frames").string(),
                far_log);
  const std::string far_output = slurp(far_log);
  std::printf("%s", far_output.c_str());
  EXPECT_EQ(far_status, 2) << far_output;
  EXPECT_NE(
      far_output.find(tight.string() + ": field 'render.tolerance_px': for output 'projector'"),
      std::string::npos)
      << far_output;
  // Refused from the estimate of a 1 px build by the same builder, before building: the board's
  // tensor grid cannot meet 1 px, its bisection can.
  EXPECT_NE(far_output.find("px needs about"), std::string::npos) << far_output;
  EXPECT_EQ(far_output.find("--tolerance"), std::string::npos) << far_output;
  EXPECT_FALSE(fs::exists(far.path() / "frames"));
}
#endif
