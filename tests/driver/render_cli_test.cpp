// `facet render` end to end: bad input exits 2 with a message, --json reports the fields that
// `facet bench` and the paper comparison read, --out writes the images.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace {

struct Result {
  int status = -1;
  std::string output;  // stdout and stderr
};

Result run_cli(const std::string& arguments) {
  const std::string command = std::string(FACET_CLI) + " " + arguments + " 2>&1";
  Result result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), int(buffer.size()), pipe)) result.output += buffer.data();
  const int status = pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

TEST(RenderCli, BadInputExitsWithStatus2) {
  for (const std::string& arguments :
       {std::string("render --display builtin:nothing"),
        std::string("render --display missing.warp.exr"),
        std::string("render --display builtin:cylinder360 --method bogus"),
        std::string("render --display builtin:cylinder360 --size 0x10"),
        std::string("render --display builtin:cylinder360 --frames 0"),
        std::string("render --display builtin:cylinder360 --scene missing.gltf"),
        std::string("render --display builtin:cylinder360 --anisotropy 0.5")}) {
    const Result result = run_cli(arguments);
    EXPECT_EQ(result.status, 2) << arguments << "\n" << result.output;
    EXPECT_NE(result.output.find("error"), std::string::npos) << arguments;
  }
}

TEST(RenderCli, JsonHasTheReportedFieldsAndOutWritesImages) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("facet_render_cli_" + std::to_string(getpid()));
  std::filesystem::remove_all(folder);
  const Result result = run_cli(
      "render --display builtin:cylinder360 --size 128x96 --scene builtin:city --method "
      "facets --pieces 16 --frames 2 --json --ids --depth --out " +
      folder.string());
  ASSERT_EQ(result.status, 0) << result.output;
  const nlohmann::json report = nlohmann::json::parse(result.output);
  for (const char* field : {"replication_ratio", "triangles_in", "replicas", "facets", "frame_ms",
                            "pass_ms", "triangles_visible"}) {
    EXPECT_TRUE(report.contains(field)) << field;
  }
  EXPECT_EQ(report["facets"].get<int>(), 32);  // 16 strips, two facets each
  const double ratio = report["replication_ratio"].get<double>();
  // Every triangle that survives culling is drawn at least once; culled ones (back faces, outside
  // the ±45° band) not at all, so the ratio over all triangles in may be below 1.
  const auto visible = report["triangles_visible"].get<std::uint64_t>();
  EXPECT_GT(visible, 0u);
  EXPECT_LE(visible, report["triangles_in"].get<std::uint64_t>());
  EXPECT_GE(report["replicas"].get<std::uint64_t>(), visible);
  EXPECT_GT(ratio, 0.0);
  EXPECT_EQ(report["replicas"].get<double>(),
            std::round(ratio * report["triangles_in"].get<double>()));
  EXPECT_TRUE(report["pass_ms"].contains("pass1 coverage"));
  EXPECT_TRUE(std::filesystem::is_regular_file(folder / "cylinder360.png"));
  EXPECT_TRUE(std::filesystem::is_regular_file(folder / "cylinder360.ids.exr"));
  EXPECT_TRUE(std::filesystem::is_regular_file(folder / "cylinder360.depth.exr"));
  std::filesystem::remove_all(folder);
}

// --reference: the dome master at 0.25 px against the Embree ray cast of the same frame. The
// facets' geometric error is at most 0.25 px, so edges lie within that (plus 0.02 px for snapping
// and rounding, as in Facets.EdgesLieWithinTheToleranceOfTheReference). A pixel away from the
// reference image's edges can still differ where a sliver that meets no pixel centre passes
// within 0.25 px of it (measured: 1 pixel here), so id_mismatch is only bounded loosely.
TEST(RenderCli, ReferenceReportsTheEdgeDisplacement) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("facet_render_ref_" + std::to_string(getpid()));
  std::filesystem::remove_all(folder);
  const Result result = run_cli(
      "render --display builtin:dome180 --size 128x128 --scene builtin:city --tolerance 0.25 "
      "--reference --json --ids --out " +
      folder.string());
  ASSERT_EQ(result.status, 0) << result.output;
  const nlohmann::json report = nlohmann::json::parse(result.output);
  ASSERT_TRUE(report.contains("reference")) << result.output;
  const nlohmann::json& reference = report["reference"];
  EXPECT_LE(reference["id_mismatch"].get<double>(), 1e-3);
  EXPECT_GT(reference["differing_pixels"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(reference["edge_beyond_window_pixels"].get<std::uint64_t>(), 0u);
  EXPECT_LE(reference["max_edge_px"].get<double>(), 0.25 + 0.02);
  EXPECT_EQ(report["texture_anisotropy"].get<double>(), 1.0);  // llvmpipe: automatic is off
  EXPECT_TRUE(std::filesystem::is_regular_file(folder / "dome180.reference.ids.exr"));
  std::filesystem::remove_all(folder);
}

}  // namespace
