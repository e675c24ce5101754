#include "facet/calibration/patterns.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "facet/calibration/image_io.hpp"
#include "facet/projection/errors.hpp"
#include "support/files.hpp"

namespace fc = facet::calibration;

TEST(Patterns, GrayBitsIsCeilLog2) {
  EXPECT_EQ(fc::gray_bits(1), 0);
  EXPECT_EQ(fc::gray_bits(2), 1);
  EXPECT_EQ(fc::gray_bits(3), 2);
  EXPECT_EQ(fc::gray_bits(768), 10);
  EXPECT_EQ(fc::gray_bits(1024), 10);
  EXPECT_EQ(fc::gray_bits(1025), 11);
}

TEST(Patterns, GrayCodeIdentifiesEveryColumnAndNeighboursDifferInOneBit) {
  const int width = 37;
  const int bits = fc::gray_bits(width);
  std::vector<unsigned> codes;
  for (int c = 0; c < width; ++c) {
    unsigned code = 0;
    for (int b = 0; b < bits; ++b) {
      const double value = fc::pattern_value(fc::Pattern::gray(fc::Axis::x, b), c, 5);
      const double inverse = fc::pattern_value(fc::Pattern::gray(fc::Axis::x, b, true), c, 5);
      EXPECT_EQ(value + inverse, 1.0);
      if (value == 1.0) code |= 1u << b;
    }
    EXPECT_EQ(code, unsigned(c) ^ (unsigned(c) >> 1));
    if (c > 0) {
      EXPECT_EQ(__builtin_popcount(code ^ codes.back()), 1);
    }
    codes.push_back(code);
  }
}

TEST(Patterns, PhaseFollowsTheFormula) {
  const auto pattern = fc::Pattern::phase(fc::Axis::y, 10, 1, 4);
  // At row 2 the argument is 2π·2.5/10 − 2π/4 = 0, so the value is 1; half a period on, 0.
  EXPECT_NEAR(fc::pattern_value(pattern, 100, 2), 1.0, 1e-12);
  EXPECT_NEAR(fc::pattern_value(pattern, 100, 7), 0.0, 1e-12);
  const cv::Mat image = fc::render_pattern(pattern, {8, 20});
  EXPECT_NEAR(image.at<float>(2, 7), 1.0f, 1e-6f);
  EXPECT_NEAR(image.at<float>(7, 0), 0.0f, 1e-6f);
}

TEST(Patterns, StandardSequenceAndJsonRoundTrip) {
  fc::PatternSetOptions options;
  options.phase_period = 12.5;
  options.phase_steps = 5;
  const auto patterns = fc::standard_patterns({1024, 768}, options);
  EXPECT_EQ(patterns.size(), 2u + 2u * 10 + 2u * 10 + 2u * 5);
  EXPECT_EQ(patterns[2], fc::Pattern::gray(fc::Axis::x, 9));
  EXPECT_EQ(patterns[3], fc::Pattern::gray(fc::Axis::x, 9, true));
  for (const auto& pattern : patterns) {
    EXPECT_EQ(fc::pattern_from_json(fc::pattern_to_json(pattern), "test", "p"), pattern);
  }
  EXPECT_EQ(fc::default_file_name(fc::Pattern::gray(fc::Axis::x, 9, true)), "gx9i.png");
}

TEST(Patterns, BadPatternObjectsNameTheField) {
  const auto expect_field = [](const nlohmann::json& object, const std::string& field) {
    try {
      fc::pattern_from_json(object, "capture.json", "frames[2].pattern");
      FAIL() << "accepted " << object.dump();
    } catch (const facet::InputError& error) {
      EXPECT_EQ(error.field(), field) << error.what();
      EXPECT_EQ(error.source(), "capture.json");
    }
  };
  expect_field({{"type", "grey"}}, "frames[2].pattern.type");
  expect_field({{"type", "gray"}, {"axis", "z"}, {"bit", 1}}, "frames[2].pattern.axis");
  expect_field({{"type", "gray"}, {"axis", "x"}}, "frames[2].pattern.bit");
  expect_field({{"type", "gray"}, {"axis", "x"}, {"bit", 1.5}}, "frames[2].pattern.bit");
  expect_field({{"type", "phase"}, {"axis", "x"}, {"period", -1}, {"step", 0}, {"steps", 4}},
               "frames[2].pattern.period");
  expect_field({{"type", "phase"}, {"axis", "x"}, {"period", 8}, {"step", 4}, {"steps", 4}},
               "frames[2].pattern.step");
  expect_field(nlohmann::json::array(), "frames[2].pattern");
}

TEST(Patterns, FolderHoldsQuantisedImagesAndManifest) {
  const facet::test::TempFolder temp;
  const auto out = temp.path() / "patterns";
  fc::PatternSetOptions options;
  options.phase_period = 8;
  const auto patterns = fc::standard_patterns({40, 24}, options);
  fc::write_pattern_folder(out, {40, 24}, patterns, 8);

  std::ifstream stream(out / "manifest.json");
  const auto manifest = nlohmann::json::parse(stream);
  EXPECT_EQ(manifest["format"], "facet-patterns/1");
  ASSERT_EQ(manifest["frames"].size(), patterns.size());
  double worst_8bit = 0;
  for (std::size_t k = 0; k < patterns.size(); ++k) {
    const auto& frame = manifest["frames"][k];
    EXPECT_EQ(fc::pattern_from_json(frame["pattern"], "manifest", "frames"), patterns[k]);
    const cv::Mat read = fc::read_luminance(out / frame["file"].get<std::string>());
    const cv::Mat exact = fc::render_pattern(patterns[k], {40, 24});
    ASSERT_EQ(read.size(), exact.size());
    worst_8bit = std::max(worst_8bit, cv::norm(read, exact, cv::NORM_INF));
  }
  // Rounding to the nearest of 256 levels: worst case half a level.
  EXPECT_LE(worst_8bit, 0.5 / 255 + 1e-6);

  // The folder now exists and is full: a second write is refused and leaves it alone.
  EXPECT_THROW(fc::write_pattern_folder(out, {40, 24}, patterns, 8), facet::InputError);
  EXPECT_TRUE(std::filesystem::exists(out / "manifest.json"));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(temp.path())) {
    ++entries;
  }
  EXPECT_EQ(entries, 1u) << "no temporary folder may be left behind";
}
