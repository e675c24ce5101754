// The `facet patterns` command, run as a user would.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "facet/calibration/image_io.hpp"
#include "facet/calibration/patterns.hpp"
#include "support/facet_cli.hpp"

namespace fc = facet::calibration;

using facet::test::run_facet;

TEST(CliPatterns, WritesImagesAndManifest) {
  const facet::test::TempFolder temp;
  const auto out = temp.path() / "p";
  ASSERT_EQ(run_facet("patterns --size 48x20 --out " + out.string() +
                      " --phase-period 6.5 --phase-steps 3"),
            0);
  std::ifstream stream(out / "manifest.json");
  const auto manifest = nlohmann::json::parse(stream);
  EXPECT_EQ(manifest["size"], nlohmann::json({48, 20}));
  // white, black, 6 x bits and 5 y bits with inverses, 3 phase steps per axis.
  ASSERT_EQ(manifest["frames"].size(), 2u + 2 * 6 + 2 * 5 + 2 * 3);
  for (const auto& frame : manifest["frames"]) {
    const auto pattern = fc::pattern_from_json(frame["pattern"], "manifest", "frames");
    const cv::Mat image = fc::read_luminance(out / frame["file"].get<std::string>());
    EXPECT_LE(cv::norm(image, fc::render_pattern(pattern, {48, 20}), cv::NORM_INF),
              0.5 / 255 + 1e-6)
        << frame.dump();
  }
}

TEST(CliPatterns, BadArgumentsExitWithStatusTwoAndWriteNothing) {
  const facet::test::TempFolder temp;
  const auto out = temp.path() / "p";
  EXPECT_EQ(run_facet("patterns --size 48by20 --out " + out.string()), 2);
  EXPECT_EQ(run_facet("patterns --size 0x20 --out " + out.string()), 2);
  EXPECT_EQ(run_facet("patterns --size 48x20 --out " + out.string() + " --phase-period -3"), 2);
  EXPECT_EQ(run_facet("patterns --size 48x20 --out " + out.string() + " --phase-steps 2"), 2);
  EXPECT_TRUE(std::filesystem::is_empty(temp.path()));
  std::filesystem::create_directories(out);
  std::ofstream(out / "keep.txt") << "x";
  EXPECT_EQ(run_facet("patterns --size 48x20 --out " + out.string()), 2);
  EXPECT_FALSE(std::filesystem::exists(out / "manifest.json"));
}
