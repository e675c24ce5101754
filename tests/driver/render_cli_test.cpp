// `facet render` end to end: bad input exits 2 with a message, --json reports the fields that
// `facet bench` and the paper comparison read, --out writes the images, the view moves every
// frame unless --static-view, SIGINT stops it with exit 130 and nothing written.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/facet_cli.hpp"

namespace {

struct Result {
  int status = -1;
  std::string output;  // stdout and stderr
};

Result run_cli(const std::string& arguments) {
  Result result;
  result.status = facet::test::run_facet(arguments, &result.output);
  return result;
}

// Two unit-metre squares 5 m in front of and behind the bounds' centre (the origin), facing it:
// FILE.gltf beside FILE.bin.
void write_two_walls_gltf(const std::filesystem::path& gltf) {
  const float positions[8][3] = {{-1, -1, -5}, {1, -1, -5}, {1, 1, -5}, {-1, 1, -5},
                                 {1, -1, 5},   {-1, -1, 5}, {-1, 1, 5}, {1, 1, 5}};
  const std::uint16_t indices[12] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  std::filesystem::path bin = gltf;
  bin.replace_extension(".bin");
  std::ofstream out(bin, std::ios::binary);
  out.write(reinterpret_cast<const char*>(positions), sizeof positions);
  out.write(reinterpret_cast<const char*>(indices), sizeof indices);
  out.close();
  std::ofstream json(gltf);
  json << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
     "min": [-1, -1, -5], "max": [1, 1, 5]},
    {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96},
                  {"buffer": 0, "byteOffset": 96, "byteLength": 24}],
  "buffers": [{"byteLength": 120, "uri": ")"
       << bin.filename().string() << R"("}]})";
}

// A closed 2 m box around the origin (faces counter-clockwise from outside) and a camera node
// "Front" 5 m along +z: FILE.gltf beside FILE.bin.
void write_box_gltf(const std::filesystem::path& gltf) {
  const float positions[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                 {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const int faces[6][4] = {{4, 5, 6, 7}, {1, 0, 3, 2}, {5, 1, 2, 6},
                           {0, 4, 7, 3}, {3, 7, 6, 2}, {0, 1, 5, 4}};
  std::vector<std::uint16_t> indices;
  for (const auto& f : faces)
    for (const int k : {0, 1, 2, 0, 2, 3}) indices.push_back(std::uint16_t(f[k]));
  std::filesystem::path bin = gltf;
  bin.replace_extension(".bin");
  std::ofstream out(bin, std::ios::binary);
  out.write(reinterpret_cast<const char*>(positions), sizeof positions);
  out.write(reinterpret_cast<const char*>(indices.data()), std::streamsize(indices.size() * 2));
  out.close();
  std::ofstream json(gltf);
  json << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
  "nodes": [{"mesh": 0}, {"name": "Front", "camera": 0, "translation": [0, 0, 5]}],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
     "min": [-1, -1, -1], "max": [1, 1, 1]},
    {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96},
                  {"buffer": 0, "byteOffset": 96, "byteLength": 72}],
  "buffers": [{"byteLength": 168, "uri": ")"
       << bin.filename().string() << R"("}]})";
}

// Pixels of a PNG whose colour is not black (0 when it cannot be read).
int non_black_pixels(const std::filesystem::path& png) {
  auto in = OIIO::ImageInput::open(png.string());
  if (!in) return 0;
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<unsigned char> pixels(std::size_t(spec.width) * std::size_t(spec.height) *
                                    std::size_t(spec.nchannels));
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data());
  int count = 0;
  for (std::size_t i = 0; i + 2 < pixels.size(); i += std::size_t(spec.nchannels))
    count += pixels[i] + pixels[i + 1] + pixels[i + 2] > 0;
  return count;
}

// The centre of a closed model is inside it: the default eye goes outside and above (a note
// says so) and the box is seen; --eye inside it is rendered with a warning (and shows nothing);
// an unknown --camera or a malformed --eye exits 2 naming what was expected.
TEST(RenderCli, GltfViewLeavesClosedGeometryAndTakesEyeAndCamera) {
  namespace fs = std::filesystem;
  const facet::test::TempFolder temp("facet_render_gltf_view");
  const fs::path& folder = temp.path();
  const fs::path gltf = folder / "box.gltf";
  write_box_gltf(gltf);
  const std::string common =
      "render --display builtin:cylinder360 --size 64x48 --pieces 8 --scene " + gltf.string();

  const Result outside = run_cli(common + " --out " + (folder / "default").string());
  ASSERT_EQ(outside.status, 0) << outside.output;
  EXPECT_NE(outside.output.find("facet render: the eye is at (0, 1.04, 2.77), outside and above"),
            std::string::npos)
      << outside.output;
  EXPECT_GT(non_black_pixels(folder / "default" / "cylinder360.png"), 64 * 48 / 50);

  const Result inside = run_cli(common + " --eye 0.1,0,0 --out " + (folder / "inside").string());
  ASSERT_EQ(inside.status, 0) << inside.output;
  EXPECT_NE(
      inside.output.find("facet render: warning: the eye point (0.1, 0, 0) is inside geometry"),
      std::string::npos)
      << inside.output;
  EXPECT_EQ(non_black_pixels(folder / "inside" / "cylinder360.png"), 0);

  const Result camera = run_cli(common + " --camera Front --out " + (folder / "camera").string());
  ASSERT_EQ(camera.status, 0) << camera.output;
  EXPECT_EQ(camera.output.find("warning"), std::string::npos) << camera.output;
  EXPECT_GT(non_black_pixels(folder / "camera" / "cylinder360.png"), 0);

  const Result unknown = run_cli(common + " --camera Top");
  EXPECT_EQ(unknown.status, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("--camera"), std::string::npos) << unknown.output;
  EXPECT_NE(unknown.output.find("'Front'"), std::string::npos) << unknown.output;
  const Result malformed = run_cli(common + " --eye 1,2");
  EXPECT_EQ(malformed.status, 2) << malformed.output;
  EXPECT_NE(malformed.output.find("--eye"), std::string::npos) << malformed.output;
}

// A glTF scene's view turns every frame, so the facet pipeline replicates every frame; with
// --static-view it keeps frame 1's view and reuses passes 1 and 2 on the frames after it.
TEST(RenderCli, TheViewMovesUnlessStatic) {
  const facet::test::TempFolder temp("facet_render_view");
  const std::filesystem::path& folder = temp.path();
  const std::filesystem::path gltf = folder / "walls.gltf";
  write_two_walls_gltf(gltf);
  const std::string common =
      "render --display builtin:cylinder360 --size 64x48 --pieces 8 "
      "--frames 3 --json --scene " +
      gltf.string();
  const Result moving = run_cli(common);
  ASSERT_EQ(moving.status, 0) << moving.output;
  const nlohmann::json m = nlohmann::json::parse(moving.output);
  EXPECT_EQ(m["triangles_scene"].get<int>(), 4);
  EXPECT_FALSE(m["reused_replication"].get<bool>());
  EXPECT_EQ(m["reused_frames"].get<int>(), 0);
  EXPECT_FALSE(m["static_view"].get<bool>());
  EXPECT_GT(m["gpu_buffer_bytes"].get<std::uint64_t>(), 0u);
  const Result still = run_cli(common + " --static-view");
  ASSERT_EQ(still.status, 0) << still.output;
  const nlohmann::json s = nlohmann::json::parse(still.output);
  EXPECT_TRUE(s["reused_replication"].get<bool>());
  EXPECT_EQ(s["reused_frames"].get<int>(), 2);
  EXPECT_TRUE(s["static_view"].get<bool>());
  // --triangle-list: auto takes the CPU on this software renderer; gpu draws the same.
  EXPECT_FALSE(m["triangle_list_on_gpu"].get<bool>());
  const Result on_gpu = run_cli(common + " --triangle-list gpu");
  ASSERT_EQ(on_gpu.status, 0) << on_gpu.output;
  const nlohmann::json g = nlohmann::json::parse(on_gpu.output);
  EXPECT_TRUE(g["triangle_list_on_gpu"].get<bool>());
  EXPECT_EQ(g["replicas"], m["replicas"]);
  EXPECT_EQ(g["triangles_in"], m["triangles_in"]);
}

// The cube map reports the memory of its faces and lookup textures: two 32-pixel cube maps
// (colour and IDs, 4 bytes a texel each), their depth face and one RGBA32F lookup texel per
// output pixel.
TEST(RenderCli, CubemapReportsItsGpuBufferBytes) {
  const Result result = run_cli(
      "render --display builtin:dome180 --size 40x40 --method cubemap --face-size 32 --json");
  ASSERT_EQ(result.status, 0) << result.output;
  const nlohmann::json report = nlohmann::json::parse(result.output);
  ASSERT_TRUE(report.contains("gpu_buffer_bytes")) << result.output;
  EXPECT_EQ(report["gpu_buffer_bytes"].get<std::uint64_t>(),
            6u * 32 * 32 * 8 + 32 * 32 * 4 + 40 * 40 * 16);
}

TEST(RenderCli, BadInputExitsWithStatus2) {
  for (const std::string& arguments :
       {std::string("render --display builtin:nothing"),
        std::string("render --display missing.warp.exr"),
        std::string("render --display builtin:cylinder360 --method bogus"),
        std::string("render --display builtin:cylinder360 --size 0x10"),
        std::string("render --display builtin:cylinder360 --frames 0"),
        std::string("render --display builtin:cylinder360 --frames -1"),
        std::string("render --display builtin:cylinder360 --frames 99999999"),
        std::string("render --display builtin:cylinder360 --scene missing.gltf"),
        std::string("render --display builtin:cylinder360 --scene builtin:town"),
        std::string("render --display builtin:cylinder360 --scene builtin:city:0"),
        std::string("render --display builtin:cylinder360 --scene builtin:city-fine:60"),
        std::string("render --display builtin:cylinder360 --anisotropy 0.5")}) {
    const Result result = run_cli(arguments);
    EXPECT_EQ(result.status, 2) << arguments << "\n" << result.output;
    EXPECT_NE(result.output.find("error"), std::string::npos) << arguments;
  }
}

// A GLC camera (*.glc.json) renders with --method glc alone, and its file's errors name the file
// and the field; the result is compared with the oracle casting the camera's own rays.
TEST(RenderCli, GlcCameraRendersWithItsMethodAndRefusesBadInput) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("facet_render_glc_" + std::to_string(getpid()));
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const std::string good = (folder / "small.glc.json").string();
  std::ofstream(good) << R"({"format": "facet-glc/1", "camera": {"type": "cross-slit",
    "size": [96, 32], "plane_size": [3.2, 2.0],
    "slit1": {"point": [0, 0, -1], "direction": [0, 1, 0]},
    "slit2": {"point": [0, 0, -4], "direction": [1, 0, 0]}}})";
  const std::string bad = (folder / "bad.glc.json").string();
  std::ofstream(bad) << R"({"format": "facet-glc/1", "camera": {"type": "generators",
    "size": [96, 32], "generators": [
      {"origin": [0, 0, 0], "direction": [0, 0, 1], "pixel": [0, 0]},
      {"origin": [1, 0, 0], "direction": [1, 0, 0], "pixel": [96, 0]},
      {"origin": [0, 1, 0], "direction": [0, 0, 1], "pixel": [0, 32]}]}})";
  const std::string huge = (folder / "huge.glc.json").string();
  std::ofstream(huge) << R"({"format": "facet-glc/1", "camera": {"type": "panorama",
    "size": [100000, 100000], "angle_deg": 360, "radius": 0.2, "vertical_fov_deg": 90,
    "strips": 40}})";

  const Result ok = run_cli("render --display " + good + " --method glc --reference --json");
  ASSERT_EQ(ok.status, 0) << ok.output;
  const nlohmann::json report = nlohmann::json::parse(ok.output);
  EXPECT_EQ(report["method"], "glc");
  EXPECT_GT(report["replicas"].get<int>(), 0);
  EXPECT_LE(report["reference"]["id_mismatch"].get<double>(), 1e-3);
  // The glc method casts the oracle's own rays: where the IDs differ at all (float rounding at an
  // edge), the exact edge lies within a fraction of a pixel; 0.25 px worst case.
  EXPECT_LE(report["reference"]["max_edge_px"].get<double>(), 0.25);
  EXPECT_EQ(report["reference"]["edge_beyond_window_pixels"].get<int>(), 0);
  // --material shades the GLC ray cast as every other method: the IDs, and so the mismatch, stay.
  const std::string shaded = (folder / "shaded").string();
  const Result styled =
      run_cli("render --display " + good +
              " --method glc --material pen-and-ink --reference --json --out " + shaded);
  ASSERT_EQ(styled.status, 0) << styled.output;
  EXPECT_EQ(nlohmann::json::parse(styled.output)["reference"]["id_mismatch"],
            report["reference"]["id_mismatch"]);
  EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(shaded) / "small.png"));

  const struct {
    std::string arguments, expected;
  } refused[] = {
      {"render --display " + bad + " --method glc",
       bad + ": field 'camera.generators[1].direction'"},
      {"render --display " + huge + " --method glc", huge + ": field 'camera.size'"},
      {"render --display " + good + " --method facets",
       "expected glc or glc-2pass for the GLC camera"},
      {"render --display builtin:dome180 --size 32x32 --method glc",
       "expected a GLC camera (FILE.glc.json) for --method glc"},
      {"render --display builtin:dome180 --size 32x32 --method glc-2pass",
       "expected a GLC camera (FILE.glc.json) for --method glc-2pass"},
      {"render --display " + bad + " --method glc-2pass",
       bad + ": field 'camera.generators[1].direction'"},
      {"render --display " + good + " --method glc --size 64x64", "expected the size of"},
      {"render --display " + good + " --method glc --material chalk",
       "field '--material': expected lit, solid-wireframe, pen-and-ink, procedural or a GLSL file"},
      {"run " + good + " --frames 1", "only the glc and glc-2pass render methods draw"},
  };
  for (const auto& [arguments, expected] : refused) {
    const Result result = run_cli(arguments);
    EXPECT_EQ(result.status, 2) << arguments << "\n" << result.output;
    EXPECT_NE(result.output.find(expected), std::string::npos) << arguments << "\n"
                                                               << result.output;
  }
  std::filesystem::remove_all(folder);
}

TEST(RenderCli, JsonHasTheReportedFieldsAndOutWritesImages) {
  const facet::test::TempFolder temp("facet_render_cli");
  const std::filesystem::path folder = temp / "out";
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
  // the ±45° band) not at all, so the ratio, over every scene triangle, may be below 1.
  const auto visible = report["triangles_visible"].get<std::uint64_t>();
  EXPECT_GT(visible, 0u);
  EXPECT_LE(visible, report["triangles_in"].get<std::uint64_t>());
  EXPECT_GE(report["replicas"].get<std::uint64_t>(), visible);
  EXPECT_GT(ratio, 0.0);
  EXPECT_LE(report["triangles_in"].get<std::uint64_t>(),
            report["triangles_scene"].get<std::uint64_t>());
  EXPECT_EQ(report["replicas"].get<double>(),
            std::round(ratio * report["triangles_scene"].get<double>()));
  EXPECT_TRUE(report["pass_ms"].contains("pass1 coverage"));
  EXPECT_TRUE(std::filesystem::is_regular_file(folder / "cylinder360.png"));
  EXPECT_TRUE(std::filesystem::is_regular_file(folder / "cylinder360.ids.exr"));
  EXPECT_TRUE(std::filesystem::is_regular_file(folder / "cylinder360.depth.exr"));
}

// --reference: the dome master at 0.25 px against the Embree ray cast of the same frame. The
// facets' geometric error is at most 0.25 px, so edges lie within that (plus 0.02 px for snapping
// and rounding, as in Facets.EdgesLieWithinTheToleranceOfTheReference). A pixel away from the
// reference image's edges can still differ where a sliver that meets no pixel centre passes
// within 0.25 px of it (measured: 1 pixel here), so id_mismatch is only bounded loosely.
TEST(RenderCli, ReferenceReportsTheEdgeDisplacement) {
  const facet::test::TempFolder temp("facet_render_ref");
  const std::filesystem::path folder = temp / "out";
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
}

#ifndef FACET_TEST_WITHOUT_INTEROP
// --reference compares what the display shows. A split tile screen's pieces are projectors on
// one window, each with a 0/1 blend map; facets that straddle the edge of a piece's coverage are
// drawn whole, reaching into the other piece's half (here up to about 55 px of the 100 px
// half), where the blend map hides them. Counted as drawn, they made 3,830 of 33,335 compared
// pixels mismatched (19.8% of the right piece's); compared where the blend shows them, none.
TEST(RenderCli, ReferenceComparesOnlyWhatTheBlendMapsShow) {
  const facet::test::TempFolder temp("facet_render_split");
  const std::filesystem::path folder = temp / "out";
  const std::filesystem::path tiles =
      std::filesystem::path(FACET_SOURCE_DIR) / "configs/tiles/split-tpts.json";
  const Result built = run_cli("tiles " + tiles.string() + " --size 200x100 --out " +
                               (folder / "display").string() + " --json");
  ASSERT_EQ(built.status, 0) << built.output;
  const Result result = run_cli("render --display " + (folder / "display/display.json").string() +
                                " --method facets --reference --json");
  ASSERT_EQ(result.status, 0) << result.output;
  const nlohmann::json report = nlohmann::json::parse(result.output);
  const nlohmann::json& reference = report["reference"];
  ASSERT_EQ(reference["outputs"].size(), 2u);
  std::uint64_t hidden = 0;
  for (const nlohmann::json& output : reference["outputs"]) {
    SCOPED_TRACE(output["name"].get<std::string>());
    EXPECT_LE(output["id_mismatch"].get<double>(), 1e-3);
    EXPECT_EQ(output["edge_beyond_window_pixels"].get<std::uint64_t>(), 0u);
    EXPECT_LE(output["max_edge_px"].get<double>(), 0.25 + 0.02);
    EXPECT_GT(output.value("compared_pixels", std::uint64_t(0)), 15000u);
    // Each piece's blend hides the other half: 100 of 200 columns.
    EXPECT_EQ(output.value("blend_hidden_pixels", std::uint64_t(0)), 100u * 100u);
    hidden += output.value("blend_hidden_pixels", std::uint64_t(0));
  }
  EXPECT_EQ(reference.value("blend_hidden_pixels", std::uint64_t(0)), hidden);
}
#endif

// A render of a million frames stopped by SIGINT once its handler is in place: exit 130, one line
// saying how far it got, and neither --out nor a temporary folder beside it.
TEST(RenderCli, SigintStopsBetweenFramesAndWritesNothing) {
  namespace fs = std::filesystem;
  const facet::test::TempFolder temp("facet_render_sigint");
  const fs::path& folder = temp.path();
  const fs::path out = folder / "out", log = folder / "log";
  const pid_t child =
      facet::test::start_facet({"render", "--display", "builtin:cylinder360", "--size", "64x32",
                                "--pieces", "8", "--frames", "1000000", "--out", out.string()},
                               log);
  ASSERT_GT(child, 0);
  const bool watching = facet::test::wait_until(
      [&] { return facet::test::catches_signal(child, SIGINT); }, std::chrono::seconds(60));
  ::kill(child, SIGINT);
  const int status = facet::test::wait_for_exit(child);
  const std::string output = facet::test::slurp(log);
  ASSERT_TRUE(watching) << output;
  EXPECT_EQ(status, 130) << output;
  EXPECT_NE(output.find("facet render: interrupted by SIGINT: stopped after "), std::string::npos)
      << output;
  EXPECT_NE(output.find("nothing written to " + out.string()), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out));
  for (const fs::directory_entry& entry : fs::directory_iterator(folder))
    EXPECT_NE(entry.path().filename().string().front(), '.') << entry.path();
}

}  // namespace
