#include "facet/interop/tiles.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "facet/projection/errors.hpp"
#include "facet/projection/facet_error.hpp"
#include "facet/projection/facets.hpp"
#include "facet/projection_io/display_config.hpp"
#include "test_util.hpp"

namespace facet::interop {
namespace {

namespace fs = std::filesystem;
const fs::path kTiles = fs::path(FACET_SOURCE_DIR) / "configs/tiles";

std::vector<fs::path> sample_screens() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kTiles)) {
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(Tiles, FisheyeLensPolynomialMapsRadiusToAngle) {
  for (double r : {0.0, 0.1, 0.25, 0.5, 0.75, 1.0, 1.2}) {
    const double expected = 1.411269 * r - 0.094389 * r * r * r + 0.25674 * std::pow(r, 5);
    EXPECT_NEAR(fisheye_lens_theta(r), expected, 1e-12) << r;
  }
  // The lens shows that angle from the view axis (−z) at radius r: the centre of a 2:1 output,
  // radius 0.5 output heights, a point r·0.5 heights right of and above the centre.
  TileLens lens;
  lens.radius = 0.5;
  for (double r : {0.1, 0.5, 1.0}) {
    const double offset = r * 0.5 / std::sqrt(2.0);  // output heights, each axis
    const glm::dvec2 xy{0.5 + offset / 2.0, 0.5 - offset};
    const glm::dvec3 d = lens_direction(lens, xy, 2.0);
    EXPECT_NEAR(std::acos(-d.z), fisheye_lens_theta(r), 1e-12) << r;
    EXPECT_NEAR(std::atan2(d.y, d.x), std::atan2(1.0, 1.0), 1e-12) << r;  // up and right
  }
}

// The sample screens, one test each (TileSample below).
const std::vector<std::string> kSamples{"dome-fisheye", "mixed-wide", "off-axis-zoom",
                                        "panorama-360", "split-tpts"};

TEST(Tiles, EverySampleScreenHasItsTest) {
  std::vector<std::string> names;
  for (const fs::path& file : sample_screens()) names.push_back(file.stem().string());
  EXPECT_EQ(names, kSamples);
}

// A sample screen builds (at 240 px wide, its aspect kept); its warps send the screen's own
// direction at pixel centres (a lattice apart from the builder's own check) back to that pixel
// within 0.01 px worst case for RPTS, whose field is C1, and 0.02 px for TPTS, whose triangles
// meet at kinks that the warp's bilinear cells cross; facets meet the 0.25 px tolerance on them.
class TileSample : public testing::TestWithParam<std::string> {};

TEST_P(TileSample, BuildsAndItsWarpsFollowTheScreen) {
  const fs::path file = kTiles / (GetParam() + ".json");
  TileScreen screen = read_tile_screen(file);
  const int width = 240;
  screen.size = {width, int(std::lround(double(width) * screen.size.y / screen.size.x))};
  const TileDisplay tiles = build_tile_display(screen, screen.size, file.string());
  const double bound = screen.kind == TileScreen::Kind::rpts ? 0.01 : 0.02;
  const auto pieces = tile_pieces(screen);
  ASSERT_EQ(tiles.display.projectors.size(), pieces.size());
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const Warp& warp = tiles.display.projectors[p].warp;
    double worst = 0;
    int compared = 0;
    for (int y = 1; y < screen.size.y; y += 5) {
      for (int x = 2; x < screen.size.x; x += 5) {
        const glm::dvec2 q{x + 0.5, y + 0.5};
        const auto d = tile_direction(screen, pieces, int(p), q / glm::dvec2(screen.size));
        if (!d) continue;
        const auto projected = warp.project(*d, q.x / screen.size.x);
        ASSERT_TRUE(projected) << q.x << ", " << q.y;
        worst = std::max(worst, glm::length(projected->q - q));
        ++compared;
      }
    }
    EXPECT_GT(compared, 150);
    EXPECT_LE(worst, bound) << "piece " << p;
    FacetBuildOptions options;
    options.layout = FacetTolerance{0.25};
    const FacetMesh mesh = build_facets(warp, options);
    const FacetError error = evaluate_facet_error(warp, mesh);
    EXPECT_LE(error.max_px, 0.25) << "piece " << p;
    EXPECT_EQ(error.missed_samples, 0u) << "piece " << p;
  }
}

INSTANTIATE_TEST_SUITE_P(Tiles, TileSample, testing::ValuesIn(kSamples),
                         [](const testing::TestParamInfo<std::string>& sample) {
                           std::string name = sample.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

TEST(Tiles, DiscontinuousTptsSplitsIntoPiecesWithComplementaryBlends) {
  const TileScreen screen = read_tile_screen(kTiles / "split-tpts.json");
  const auto pieces = tile_pieces(screen);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_EQ(pieces[0].size(), 4u);
  EXPECT_EQ(pieces[1].size(), 2u);
  // Either side of the transition x = 0.5 the directions differ by the features' 20° jump.
  const auto left = tile_direction(screen, pieces, 0, {0.4999, 0.0});
  const auto right = tile_direction(screen, pieces, 1, {0.5001, 0.0});
  ASSERT_TRUE(left && right);
  EXPECT_GT(std::acos(glm::dot(*left, *right)), 0.3);  // radians; the jump is 20° in azimuth
  const TileDisplay tiles = build_tile_display(screen, {400, 200}, "split-tpts.json");
  ASSERT_EQ(tiles.display.projectors.size(), 2u);
  for (int y = 0; y < 200; y += 13) {
    for (int x = 0; x < 400; x += 7) {
      const float a = tiles.display.projectors[0].blend->at(x, y);
      const float b = tiles.display.projectors[1].blend->at(x, y);
      EXPECT_EQ(a + b, 1.0f) << x << ", " << y;  // each pixel in exactly one piece
      EXPECT_EQ(a, x < 200 ? 1.0f : 0.0f) << x << ", " << y;
    }
  }
}

// A TPTS whose triangles share their vertices is one piece, whatever its triangle count; a copy
// of a vertex with the same feature joins too.
TEST(Tiles, SharedOrIdenticalVerticesKeepOnePiece) {
  const std::string text = R"({"size": [200, 100], "tpts": {
    "vertices": [[0, 0, -30, 70], [1, 0, 30, 70], [0, 1, -30, 110], [1, 1, 30, 110],
                 [1, 0, 30, 70]],
    "triangles": [[0, 1, 2], [4, 3, 2]]}})";
  const TileScreen screen = parse_tile_screen(text, "t.json");
  EXPECT_EQ(tile_pieces(screen).size(), 1u);
}

using test::CliRun;
using test::run;

TEST(Tiles, CliWritesADisplayAndReportsTheFacetError) {
  test::TempFolder scratch("facet-interop-tiles-cli");
  const fs::path out = scratch.path() / "display";
  const CliRun r = run("tiles " + (kTiles / "split-tpts.json").string() + " --size 400x200 --out " +
                           out.string() + " --json",
                       scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("\"max_px\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"rms_px\""), std::string::npos) << r.output;
  const auto display = projection_io::read_display_config(out / "display.json");
  ASSERT_EQ(display.projectors.size(), 2u);
  EXPECT_TRUE(display.projectors[0].blend);
}

TEST(Tiles, BadInputExitsTwoNamingFileAndFieldAndWritesNothing) {
  test::TempFolder scratch("facet-interop-tiles-bad");
  const std::string grid = R"({"size": [64, 32], "rpts": {"grid": [2, 2], "features": [
    [0, 0, -20, 80], [1, 0, 20, 80], [0, 1, -20, 100], [1, 1, 20, 100]]}})";
  const std::string tris = R"({"size": [64, 32], "tpts": {
    "vertices": [[0, 0, -20, 80], [1, 0, 20, 80], [0, 1, -20, 100]],
    "triangles": [[0, 1, 2]]}})";
  const auto edit = [](std::string text, const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  struct Case {
    std::string name, text, field, flags;
  };
  const std::vector<Case> cases{
      {"good", grid, "", ""},
      {"nan", edit(grid, "-20, 80]", "NaN, 80]"), "", ""},
      {"nan_text", edit(grid, "-20, 80]", "\"NaN\", 80]"), "rpts.features[0]", ""},
      {"grid_one", edit(grid, "[2, 2]", "[1, 4]"), "rpts.grid", ""},
      {"index", edit(tris, "[0, 1, 2]", "[0, 1, 3]"), "tpts.triangles[0]", ""},
      {"size", edit(grid, "[64, 32]", "[100000, 50000]"), "size", ""},
      {"apart", edit(grid, "[1, 1, 20, 100]", "[1, 1, 150, 100]"), "rpts.features[0]", ""},
      {"flag_size", grid, "--size", "--size 100000x50000"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path file = scratch.path() / (c.name + ".json");
    std::ofstream(file) << c.text;
    const fs::path out = scratch.path() / ("out_" + c.name);
    const CliRun r =
        run("tiles " + file.string() + " --out " + out.string() + " " + c.flags, scratch.path());
    if (c.name == "good") {
      EXPECT_EQ(r.status, 0) << r.output;
      continue;
    }
    EXPECT_EQ(r.status, 2) << r.output;
    if (c.flags.empty()) {
      EXPECT_NE(r.output.find(file.string()), std::string::npos) << r.output;
    }
    if (!c.field.empty()) {
      EXPECT_NE(r.output.find(c.field), std::string::npos) << r.output;
    }
    EXPECT_FALSE(fs::exists(out));
  }
}

}  // namespace
}  // namespace facet::interop
