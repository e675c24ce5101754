// facet bench from the command line: --quick writes bench.json, bench.csv, bench.md and bench.png
// with every render method, the same rows in JSON, CSV and the tables, a readable plot, and
// facets-gs IDs identical to facets. Bad flags exit 2 and write nothing; --out replaces only an
// earlier bench. No timing assertions: times only have to exist.
#include "facet/driver/bench.hpp"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "support/facet_cli.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;
using test::names_in;
using test::slurp;

// RFC 4180 fields: quoted fields may hold commas and doubled quotes.
std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t k = 0; k < line.size(); ++k) {
    const char c = line[k];
    if (quoted) {
      if (c == '"' && k + 1 < line.size() && line[k + 1] == '"') {
        fields.back() += '"';
        ++k;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

TEST(BenchCli, QuickWritesJsonCsvAndPlotWithEveryMethod) {
  const fs::path folder = test::fresh_folder("facet_bench_cli_quick");
  const fs::path out = folder / "bench";
  ASSERT_EQ(test::run_facet("bench --quick --scenario cylinder --frames 1 --out " + out.string(),
                            folder / "log.txt"),
            0)
      << slurp(folder / "log.txt");

  const nlohmann::json json = nlohmann::json::parse(slurp(out / "bench.json"));
  ASSERT_TRUE(json.contains("rows"));
  ASSERT_TRUE(json.contains("notes"));
  ASSERT_TRUE(json.contains("scale_fits"));
  EXPECT_TRUE(json["scale_fits"].empty());  // no scale scenario ran
  EXPECT_FALSE(json["notes"].empty());
  const std::vector<std::string> methods = {"facets",  "facets-gs", "tessellated",
                                            "cubemap", "naive",     "vertex"};
  std::set<std::string> seen;
  for (const auto& row : json["rows"]) {
    ASSERT_FALSE(row.contains("error")) << row.dump();
    seen.insert(row["method"].get<std::string>());
    for (const char* field :
         {"scenario",    "setting",           "frames",           "frame_ms",
          "gpu_ms",      "pass_ms",           "facets",           "triangles_in",
          "replicas",    "replication_ratio", "id_mismatch",      "max_edge_px",
          "p99_edge_px", "geometric_max_px",  "geometric_rms_px", "geometric_source",
          "scene",       "triangles_scene",   "gpu_buffer_bytes", "gpu_buffer_mib"}) {
      EXPECT_TRUE(row.contains(field)) << field << " missing in " << row.dump();
    }
    EXPECT_EQ(row["scene"], "builtin:city");
    EXPECT_EQ(row["triangles_scene"].get<int>(), 34642);
    if (row["method"] != "vertex") {
      EXPECT_GT(row["gpu_buffer_bytes"].get<std::uint64_t>(), 0u);
    }
    EXPECT_GT(row["frame_ms"].get<double>(), 0.0);
    const double mismatch = row["id_mismatch"].get<double>();
    EXPECT_GE(mismatch, 0.0);
    EXPECT_LE(mismatch, 1.0);
    if (row["method"] == "facets") {
      EXPECT_GT(row["facets"].get<int>(), 0);
      EXPECT_TRUE(row["passes12_share"].is_number()) << row.dump();
      // Facets built to 1 px (or 16 strips of a 200-px cylinder, 1.44 px): the geometric error
      // must be the facet error, within a few px, and the image close to the reference.
      EXPECT_EQ(row["geometric_source"], "facet error");
      EXPECT_LT(row["geometric_max_px"].get<double>(), 2.0);
      EXPECT_LT(mismatch, 0.01);
    }
    if (row["method"] == "facets-gs" || row["method"] == "tessellated") {
      ASSERT_TRUE(row.contains("id_pixels_differing_from_facets"));
      EXPECT_EQ(row["id_pixels_differing_from_facets"].get<int>(), 0);
    }
  }
  for (const std::string& method : methods) EXPECT_TRUE(seen.contains(method)) << method;

  // The CSV: the header, then the JSON's rows in the same order.
  std::istringstream csv(slurp(out / "bench.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::vector<std::string> header = split_csv_line(line);
  auto column = [&](const std::string& name) {
    for (std::size_t k = 0; k < header.size(); ++k) {
      if (header[k] == name) return k;
    }
    ADD_FAILURE() << "no column " << name;
    return std::size_t(0);
  };
  const std::size_t c_method = column("method"), c_setting = column("setting"),
                    c_frame = column("frame_ms"), c_mismatch = column("id_mismatch");
  std::size_t rows = 0;
  while (std::getline(csv, line)) {
    const std::vector<std::string> fields = split_csv_line(line);
    ASSERT_EQ(fields.size(), header.size()) << line;
    ASSERT_LT(rows, json["rows"].size());
    const auto& row = json["rows"][rows];
    EXPECT_EQ(fields[c_method], row["method"].get<std::string>());
    EXPECT_EQ(fields[c_setting], row["setting"].get<std::string>());
    EXPECT_NEAR(std::stod(fields[c_frame]), row["frame_ms"].get<double>(),
                1e-5 * row["frame_ms"].get<double>());
    EXPECT_NEAR(std::stod(fields[c_mismatch]), row["id_mismatch"].get<double>(), 1e-6);
    ++rows;
  }
  EXPECT_EQ(rows, json["rows"].size());

  // The tables: a heading per scenario and a line per row, with its method, setting and frame
  // time as the JSON has them.
  const std::string tables = slurp(out / "bench.md");
  for (const auto& row : json["rows"]) {
    char frame[32];
    std::snprintf(frame, sizeof frame, "%.1f", row["frame_ms"].get<double>());
    const std::string table_line = "| " + row["method"].get<std::string>() + " | " +
                                   row["setting"].get<std::string>() + " | " + frame + " |";
    EXPECT_NE(tables.find(table_line), std::string::npos) << table_line;
    EXPECT_NE(tables.find("**" + row["scenario"].get<std::string>() + "**"), std::string::npos);
  }

  // The plot: a PNG that decodes, two panels wide, not blank.
  auto png = OIIO::ImageInput::open((out / "bench.png").string());
  ASSERT_TRUE(png) << OIIO::geterror();
  const OIIO::ImageSpec spec = png->spec();
  EXPECT_GE(spec.width, 800);
  EXPECT_GE(spec.height, 300);
  std::vector<unsigned char> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
  ASSERT_TRUE(png->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data()));
  std::size_t dark = 0;
  for (unsigned char v : pixels) dark += v < 128;
  EXPECT_GT(dark, pixels.size() / 1000);
  // No temporary folder is left beside the output.
  EXPECT_EQ(names_in(folder), (std::vector<std::string>{"bench", "log.txt"}));
}

// A report of two rows, enough for every file.
driver::BenchReport small_report(const std::string& renderer) {
  driver::BenchReport report;
  report.renderer = renderer;
  report.frames = 1;
  for (const char* method : {"facets", "cubemap"}) {
    driver::BenchRow row;
    row.scenario = "cylinder";
    row.method = method;
    row.setting = "s";
    row.frames = 1;
    row.frame_ms = 2;
    row.geometric_max_px = 0.5;
    report.rows.push_back(row);
  }
  return report;
}

OutputFolderRules bench_rules() {
  OutputFolderRules rules;
  rules.field = "--out";
  rules.is_own_output = driver::is_bench_output;
  return rules;
}

// bench's --out goes through the one folder writer: an earlier bench (with the log
// tools/gpu-bench keeps beside it) is replaced whole, a folder holding anything else is refused
// before writing, and a failure while writing leaves the earlier output and no temporary.
TEST(BenchFiles, ReplaceOnlyAnEarlierBenchAndLeaveNothingOnFailure) {
  const fs::path folder = test::fresh_folder("facet_bench_cli_files");
  const fs::path out = folder / "bench";
  driver::write_bench_files(small_report("first"), out, bench_rules());
  const std::vector<std::string> files = {"bench.csv", "bench.json", "bench.md", "bench.png"};
  EXPECT_EQ(names_in(out), files);
  EXPECT_TRUE(driver::is_bench_output(out));
  std::ofstream(out / "bench.log") << "log";
  EXPECT_TRUE(driver::is_bench_output(out));
  driver::write_bench_files(small_report("second"), out, bench_rules());
  EXPECT_EQ(names_in(out), files);
  EXPECT_EQ(nlohmann::json::parse(slurp(out / "bench.json"))["renderer"], "second");

  // JSON refuses a string that is not UTF-8: the write fails half way, after the temporary
  // folder exists.
  EXPECT_THROW(driver::write_bench_files(small_report("bad \xff"), out, bench_rules()),
               nlohmann::json::exception);
  EXPECT_EQ(nlohmann::json::parse(slurp(out / "bench.json"))["renderer"], "second");
  EXPECT_EQ(names_in(folder), std::vector<std::string>{"bench"});

  // Not a bench's folder: a stranger's file, a folder without bench.json, a link.
  const fs::path foreign = folder / "foreign";
  fs::create_directories(foreign);
  std::ofstream(foreign / "notes.txt") << "mine";
  const fs::path partial = folder / "partial";
  fs::create_directories(partial);
  std::ofstream(partial / "bench.csv") << "a,b";
  const fs::path linked = folder / "linked";
  fs::create_directories(linked);
  fs::create_symlink(out / "bench.json", linked / "bench.json");
  for (const fs::path& target : {foreign, partial, linked}) {
    EXPECT_FALSE(driver::is_bench_output(target)) << target;
    try {
      driver::write_bench_files(small_report("third"), target, bench_rules());
      ADD_FAILURE() << "no InputError for " << target;
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), target.string());
      EXPECT_EQ(e.field(), "--out");
    }
  }
  EXPECT_EQ(slurp(foreign / "notes.txt"), "mine");
  EXPECT_EQ(names_in(foreign), std::vector<std::string>{"notes.txt"});
  EXPECT_EQ(names_in(folder), (std::vector<std::string>{"bench", "foreign", "linked", "partial"}));
  fs::remove_all(folder);
}

TEST(BenchCli, BadFlagsExitTwoAndWriteNothing) {
  const fs::path folder = test::fresh_folder("facet_bench_cli_bad");
  for (const std::string& flags :
       {std::string("--scenario moon"), std::string("--frames 0"), std::string("--frames -1"),
        std::string("--frames 99999999"), std::string("--size-scale -1"),
        std::string("--scenario dome --rig /nonexistent.json")}) {
    const fs::path out = folder / "bench";
    EXPECT_EQ(
        test::run_facet("bench --quick " + flags + " --out " + out.string(), folder / "log.txt"), 2)
        << flags << ": " << slurp(folder / "log.txt");
    EXPECT_FALSE(fs::exists(out)) << flags;
  }
  // An --out that holds someone else's file is refused before any rendering, and kept.
  const fs::path foreign = folder / "foreign";
  fs::create_directories(foreign);
  std::ofstream(foreign / "notes.txt") << "mine";
  EXPECT_EQ(
      test::run_facet("bench --quick --scenario cylinder --frames 1 --out " + foreign.string(),
                      folder / "log.txt"),
      2)
      << slurp(folder / "log.txt");
  EXPECT_NE(slurp(folder / "log.txt").find("--out"), std::string::npos)
      << slurp(folder / "log.txt");
  EXPECT_EQ(names_in(foreign), std::vector<std::string>{"notes.txt"});
  EXPECT_EQ(slurp(foreign / "notes.txt"), "mine");
  // So is the cluster scenario's, before any node starts.
  EXPECT_EQ(test::run_facet("bench --quick --scenario cluster --out " + foreign.string(),
                            folder / "log.txt"),
            2)
      << slurp(folder / "log.txt");
  EXPECT_NE(slurp(folder / "log.txt").find("--out"), std::string::npos)
      << slurp(folder / "log.txt");
  EXPECT_EQ(names_in(foreign), std::vector<std::string>{"notes.txt"});
}

// Every scenario's outputs and settings, without rendering: the quick and the full sweeps name
// every method, the built-in view deformation is a valid warp that does not fold, and the dome rig
// gives one output per projector.
TEST(BenchScenarios, EveryScenarioHasValidOutputsAndEveryMethod) {
  for (const bool quick : {true, false}) {
    driver::BenchOptions options;
    options.quick = quick;
    options.size_scale = 0.125;
    // The full sweep takes the default rig, builtin:dome4, which needs no file in the working
    // folder (ctest runs this in the build tree); the quick one a rig file.
    if (quick) options.dome_rig = std::string(FACET_SOURCE_DIR) + "/configs/rigs/dome4.json";
    const auto scenarios = driver::make_bench_scenarios(options);
    std::set<std::string> names;
    for (const auto& scenario : scenarios) {
      names.insert(scenario.name);
      ASSERT_FALSE(scenario.outputs.empty()) << scenario.name;
      for (const auto& output : scenario.outputs) {
        EXPECT_NO_THROW(output.warp.validate(scenario.name)) << scenario.name;
        EXPECT_FALSE(output.warp.find_fold()) << scenario.name;
      }
      std::set<std::string> methods;
      for (const auto& setting : scenario.settings) methods.insert(setting.method);
      // One perspective image holds a projector or a view deformation, not a dome master or the
      // 360° cylinder.
      std::set<std::string> expected{"facets",  "facets-gs", "tessellated",
                                     "cubemap", "naive",     "vertex"};
      if (scenario.name.starts_with("deformation") || scenario.name == "dome4")
        expected.insert("perspective");
      EXPECT_EQ(methods, expected) << scenario.name;
    }
    EXPECT_TRUE(names.contains("cylinder"));
    EXPECT_TRUE(names.contains("deformation-80x60"));
    EXPECT_EQ(names.contains("deformation-128x128"), !quick);
    EXPECT_TRUE(names.contains("dome"));
    EXPECT_TRUE(names.contains("dome4"));
  }
  driver::BenchOptions options;
  options.scenarios = {"deformation-80x60"};
  const auto deformation = driver::make_bench_scenarios(options);
  ASSERT_EQ(deformation.size(), 1u);
  const Warp& warp = deformation[0].outputs.at(0).warp;
  EXPECT_EQ(warp.grid_size, glm::ivec2(81, 61));
  EXPECT_EQ(warp.output_size, glm::ivec2(1024, 768));
  // A real deformation: offsets of tens of pixels, at most about 3.5% of the width.
  double largest = 0;
  for (const glm::vec2& d : warp.offset_px) largest = std::max(largest, double(glm::length(d)));
  EXPECT_GT(largest, 10.0);
  EXPECT_LT(largest, 0.05 * 1024);
  options.scenarios = {"moon"};
  EXPECT_THROW(driver::make_bench_scenarios(options), InputError);
}

// Liu, Liu & Wu's comparison: the polygons and DPCIs of them at two sizes, every method, all from
// the DPCI's eye. A DPCI's mesh has two triangles per seen pixel at most, whatever the polygons;
// each row is checked against the oracle of the scene it draws.
TEST(BenchCli, DepthScenarioComparesPolygonsWithTheirDpcis) {
  const fs::path folder = test::fresh_folder("facet_bench_cli_depth");
  const fs::path out = folder / "bench";
  ASSERT_EQ(test::run_facet(
                "bench --quick --scenario depth --frames 1 --size-scale 0.5 --out " + out.string(),
                folder / "log.txt"),
            0)
      << slurp(folder / "log.txt");
  const nlohmann::json json = nlohmann::json::parse(slurp(out / "bench.json"));
  std::map<std::string, std::uint64_t> triangles;
  std::map<std::string, std::string> scenes;
  for (const auto& row : json["rows"]) {
    ASSERT_FALSE(row.contains("error")) << row.dump();
    const std::string scenario = row["scenario"].get<std::string>();
    triangles[scenario] = row["triangles_scene"].get<std::uint64_t>();
    scenes[scenario] = row["scene"].get<std::string>();
    if (row["method"] == "facets") {
      EXPECT_LE(row["id_mismatch"].get<double>(), 0.01) << row.dump();
    }
  }
  ASSERT_EQ(triangles.size(), 3u);
  EXPECT_EQ(scenes["depth:city"], "builtin:city from its DPCI's eye");
  EXPECT_EQ(scenes["depth:city@dpci64"], "DPCI 64x64 of builtin:city");
  EXPECT_EQ(scenes["depth:city@dpci32"], "DPCI 32x32 of builtin:city");
  // Cylinder W x H plus cap H x H pixels, two triangles each at most.
  EXPECT_GT(triangles["depth:city@dpci64"], 2000u);
  EXPECT_LE(triangles["depth:city@dpci64"], 2u * (64 * 64 + 64 * 64));
  EXPECT_LE(triangles["depth:city@dpci32"], 2u * (32 * 32 + 32 * 32));
  EXPECT_GT(triangles["depth:city@dpci64"], 3 * triangles["depth:city@dpci32"]);
  EXPECT_GT(triangles["depth:city"], triangles["depth:city@dpci64"]);
}

// The GLC paper cases: three scenarios of a glc and a glc-2pass row each; glc matches the
// oracle's GLC rays, glc-2pass (the paper's two-pass rasterization) comes close.
TEST(BenchCli, GlcScenarioHasARowPerPaperCase) {
  const fs::path folder = test::fresh_folder("facet_bench_cli_glc");
  const fs::path out = folder / "bench";
  ASSERT_EQ(test::run_facet("bench --quick --scenario glc --frames 1 --out " + out.string(),
                            folder / "log.txt"),
            0)
      << slurp(folder / "log.txt");
  const nlohmann::json json = nlohmann::json::parse(slurp(out / "bench.json"));
  std::set<std::string> scenarios;
  std::map<std::string, int> methods;
  for (const auto& row : json["rows"]) {
    ASSERT_FALSE(row.contains("error")) << row.dump();
    const std::string method = row["method"].get<std::string>();
    ++methods[method];
    if (method == "glc") {
      EXPECT_EQ(row["geometric_source"], "exact rays");
      EXPECT_LE(row["id_mismatch"].get<double>(), 1e-3) << row.dump();
    } else {
      EXPECT_EQ(method, "glc-2pass");
      EXPECT_LE(row["id_mismatch"].get<double>(), 2e-3) << row.dump();
    }
    EXPECT_GT(row["replicas"].get<double>(), 0) << row.dump();
    scenarios.insert(row["scenario"].get<std::string>());
  }
  EXPECT_EQ(scenarios, (std::set<std::string>{"glc-city", "glc-panorama", "glc-mirror"}));
  EXPECT_EQ(methods, (std::map<std::string, int>{{"glc", 3}, {"glc-2pass", 3}}));
}

// A depth image at @lod seen from an eye that circles the point it looks at (--eye, --look-at;
// 3° a frame, about 0.5 m here): the levels are chosen for each timed frame's eye, the scene
// rebuilt where they change, every method takes it, and each row reports the rebuilds and what
// they cost, outside its frame time.
TEST(BenchCli, DepthImageLevelOfDetailFollowsTheEyeOverTheTimedFrames) {
  const fs::path folder = test::fresh_folder("facet_bench_cli_depth_lod");
  const fs::path image = folder / "city.exr";
  ASSERT_EQ(
      test::run_facet("depth-image --scene builtin:city --size 128x64 --out " + image.string(),
                      folder / "image_log.txt"),
      0)
      << slurp(folder / "image_log.txt");
  const fs::path out = folder / "bench";
  ASSERT_EQ(test::run_facet("bench --quick --scenario cylinder --frames 3 --eye 0,4.7,-2 "
                            "--look-at 0,1.7,-12 --scene depth:" +
                                image.string() + "@lod=0.3 --out " + out.string(),
                            folder / "log.txt"),
            0)
      << slurp(folder / "log.txt");
  const nlohmann::json json = nlohmann::json::parse(slurp(out / "bench.json"));
  ASSERT_FALSE(json["rows"].empty());
  std::set<std::uint64_t> rebuilds;
  for (const auto& row : json["rows"]) {
    ASSERT_FALSE(row.contains("error")) << row.dump();
    ASSERT_TRUE(row.contains("scene_rebuilds")) << row.dump();
    rebuilds.insert(row["scene_rebuilds"].get<std::uint64_t>());
    EXPECT_GT(row["scene_rebuild_ms"].get<double>(), 0.0) << row.dump();
    EXPECT_GT(row["scene_replace_ms"].get<double>(), 0.0) << row.dump();
  }
  // One count for the scenario, shared by its rows, and at least one rebuild in 3 frames.
  ASSERT_EQ(rebuilds.size(), 1u);
  EXPECT_GE(*rebuilds.begin(), 1u);
  EXPECT_LE(*rebuilds.begin(), 3u);
  EXPECT_NE(slurp(folder / "log.txt").find("depth image level of detail"), std::string::npos);
}

// At equal error: the cylinder at quarter size runs 512² faces, so it gains a facets tolerance
// build at the cube map's error, rounded down; the quick sweep does not.
TEST(BenchScenarios, MatchedToleranceFollowsTheCubeMapsError) {
  driver::BenchOptions options;
  options.scenarios = {"cylinder"};
  options.size_scale = 0.25;
  const auto scenarios = driver::make_bench_scenarios(options);
  ASSERT_EQ(scenarios.size(), 1u);
  const auto settings = driver::with_matched_tolerance(scenarios[0], 0.41378);
  ASSERT_EQ(settings.size(), scenarios[0].settings.size() + 1);
  std::size_t last_facets = 0;
  for (std::size_t k = 0; k < settings.size(); ++k)
    if (settings[k].method == "facets") last_facets = k;
  const driver::BenchSetting& matched = settings[last_facets];
  EXPECT_EQ(matched.label, "tol=0.413px (cube 512)");
  ASSERT_TRUE(std::holds_alternative<FacetTolerance>(matched.settings.facets.layout));
  EXPECT_DOUBLE_EQ(std::get<FacetTolerance>(matched.settings.facets.layout).px, 0.413);
  EXPECT_EQ(settings[last_facets + 1].method, "facets-gs");
  options.quick = true;
  const auto quick = driver::make_bench_scenarios(options);
  EXPECT_EQ(driver::with_matched_tolerance(quick[0], 0.41378).size(), quick[0].settings.size());
  // The scene-size rows match their one cube map: 512 scaled to 128. (The facet-count and width
  // rows keep fixed strips.)
  options.quick = false;
  options.scenarios = {"scale-scenes"};
  for (const auto& scenario : driver::make_bench_scenarios(options)) {
    EXPECT_EQ(scenario.matched_cube_face, 128) << scenario.name;
    const auto scaled = driver::with_matched_tolerance(scenario, 1.6654);
    ASSERT_EQ(scaled.size(), scenario.settings.size() + 1) << scenario.name;
    EXPECT_EQ(scaled[1].label, "tol=1.665px (cube 128)") << scenario.name;
  }
}

// --scenario scale: every method at one setting on the cylinder and the dome, over growing
// tiled cities, ordered by scene; "all" leaves it out. Rows only: running it at the quick size
// takes minutes on llvmpipe.
TEST(BenchScenarios, ScaleBuildsItsRowsOverTheSceneSizes) {
  driver::BenchOptions options;
  options.quick = true;
  options.scenarios = {"scale"};
  options.dome_rig = std::string(FACET_SOURCE_DIR) + "/configs/rigs/dome4.json";
  const auto quick = driver::make_bench_scenarios(options);
  // builtin:city and builtin:city:2, each on both displays; the strip counts; two widths.
  ASSERT_EQ(quick.size(), 7u);
  const std::vector<std::string> scenes = {"builtin:city", "builtin:city", "builtin:city:2",
                                           "builtin:city:2"};
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    EXPECT_EQ(quick[k].scene, scenes[k]);
    EXPECT_EQ(quick[k].scale_group, k % 2 ? "scale-dome" : "scale-cylinder");
    EXPECT_EQ(quick[k].name, quick[k].scale_group + ":" + scenes[k].substr(8));
    std::vector<std::string> methods, labels;
    for (const auto& setting : quick[k].settings) {
      methods.push_back(setting.method);
      labels.push_back(setting.label);
    }
    EXPECT_EQ(methods, (std::vector<std::string>{"facets", "facets-gs", "tessellated", "naive",
                                                 "cubemap", "vertex"}));
    EXPECT_EQ(labels, (std::vector<std::string>{"tol=0.25px", "tol=0.25px", "tol=0.25px",
                                                "tol=0.25px", "face=64", "tess=1"}));
  }
  EXPECT_EQ(quick[0].outputs.at(0).warp.output_size, glm::ivec2(200, 150));
  EXPECT_EQ(quick[1].outputs.at(0).warp.output_size, glm::ivec2(256, 256));
  // The facet count: three facet methods over two strip counts, each method's rows under one
  // fit label.
  EXPECT_EQ(quick[4].scale_group, "scale-facets-cylinder");
  ASSERT_EQ(quick[4].settings.size(), 6u);
  for (const auto& setting : quick[4].settings) {
    EXPECT_EQ(setting.fit_label, "pieces=N") << setting.label;
    EXPECT_TRUE(setting.method != "facets-gs" || setting.same_ids_as == setting.label);
  }
  EXPECT_EQ(quick[4].settings[1].label, "pieces=40");
  // The output width: the same settings at two sizes of one aspect.
  EXPECT_EQ(quick[5].scale_group, "scale-width-cylinder");
  EXPECT_EQ(quick[5].outputs.at(0).warp.output_size, glm::ivec2(100, 75));
  EXPECT_EQ(quick[6].outputs.at(0).warp.output_size, glm::ivec2(200, 150));
  EXPECT_EQ(quick[5].settings.size(), quick[6].settings.size());
  // Each part alone.
  options.scenarios = {"scale-width"};
  EXPECT_EQ(driver::make_bench_scenarios(options).size(), 2u);
  options.scenarios = {"scale-facets"};
  EXPECT_EQ(driver::make_bench_scenarios(options).size(), 1u);
  options.scenarios = {"scale-scenes"};
  EXPECT_EQ(driver::make_bench_scenarios(options).size(), 4u);
  options.scenarios = {"scale"};
  options.quick = false;
  options.size_scale = 0.125;
  const auto full = driver::make_bench_scenarios(options);
  ASSERT_EQ(full.size(), 10u);
  EXPECT_EQ(full[4].scene, "builtin:city:8");
  EXPECT_NE(full[4].description.find("2175976 triangles"), std::string::npos)
      << full[4].description;
  options.scenarios.clear();
  for (const auto& scenario : driver::make_bench_scenarios(options))
    EXPECT_TRUE(scenario.scale_group.empty()) << scenario.name;
  options.scene = "builtin:village";
  EXPECT_THROW(driver::make_bench_scenarios(options), InputError);
}

TEST(BenchScaleFit, ExponentOfAPowerLaw) {
  std::vector<double> n, ms;
  for (const double x : {3.5e4, 5.5e5, 2.2e6, 1e7}) {
    n.push_back(x);
    ms.push_back(3 * std::pow(x, 0.9));
  }
  const auto b = driver::fit_power_exponent(n, ms);
  ASSERT_TRUE(b);
  EXPECT_NEAR(*b, 0.9, 1e-9);
  // A least-squares slope through noisy points: (1, 1), (10, 20), (100, 100) in logs.
  const auto noisy = driver::fit_power_exponent({1, 10, 100}, {1, 20, 100});
  ASSERT_TRUE(noisy);
  EXPECT_NEAR(*noisy, 1.0, 1e-12);  // symmetric about the middle point
  EXPECT_FALSE(driver::fit_power_exponent({5, 5, 5}, {1, 2, 3}));  // x does not vary
  EXPECT_FALSE(driver::fit_power_exponent({5}, {1}));
  EXPECT_FALSE(driver::fit_power_exponent({0, 10}, {1, 2}));  // only one usable point
}

TEST(BenchScaleFit, FitsEachGroupAndMethodAndSaysWhatDoesNotVary) {
  std::vector<driver::BenchRow> rows;
  for (const std::uint64_t triangles : {34642u, 545008u, 2175976u}) {
    for (const char* method : {"facets", "cubemap"}) {
      driver::BenchRow row;
      row.scenario = "scale-cylinder:" + std::to_string(triangles);
      row.scale_group = "scale-cylinder";
      row.method = method;
      row.setting = "s";
      row.output_size = "1600x1200";
      row.triangles_scene = triangles;
      row.facets = row.method == "facets" ? 400 : 0;
      row.frames = 5;
      row.frame_ms = (row.method == "facets" ? 2.0 : 0.5) *
                     std::pow(double(triangles), row.method == "facets" ? 0.8 : 1.1);
      rows.push_back(row);
    }
  }
  driver::BenchRow other;  // not in a scale group: left out
  other.scenario = "cylinder";
  other.method = "facets";
  other.frame_ms = 1;
  rows.push_back(other);
  const auto fits = driver::bench_scale_fits(rows);
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(fits[0].method, "facets");
  EXPECT_EQ(fits[0].rows, 3u);
  ASSERT_TRUE(fits[0].triangles_exponent);
  EXPECT_NEAR(*fits[0].triangles_exponent, 0.8, 1e-9);
  EXPECT_NEAR(*fits[1].triangles_exponent, 1.1, 1e-9);
  EXPECT_FALSE(fits[0].facets_exponent);  // 400 facets in every row
  EXPECT_FALSE(fits[0].width_exponent);   // 1600 px in every row
  EXPECT_EQ(fits[0].triangles_min, 34642u);
  EXPECT_EQ(fits[0].triangles_max, 2175976u);
  bool noted = false;
  for (const std::string& note : driver::bench_notes(rows, "test")) {
    if (note.starts_with("scale-cylinder: exponent")) {
      noted = true;
      EXPECT_NE(note.find("facets s: triangles 0.800 (34642 to 2175976);"), std::string::npos)
          << note;
      EXPECT_NE(note.find("cubemap s: triangles 1.100"), std::string::npos) << note;
      EXPECT_EQ(note.find("facets 0."), std::string::npos) << note;  // 400 in every row
    }
  }
  EXPECT_TRUE(noted);
}

// The facet-count rows of one method fit together under their fit label; the width rows of one
// setting over their output sizes.
TEST(BenchScaleFit, FitsFacetCountsUnderOneLabelAndWidthsOverSizes) {
  std::vector<driver::BenchRow> rows;
  for (const int pieces : {40, 80, 160, 320}) {
    driver::BenchRow row;
    row.scenario = row.scale_group = "scale-facets-cylinder";
    row.method = "facets";
    row.setting = "pieces=" + std::to_string(pieces);
    row.fit_label = "pieces=N";
    row.output_size = "400x300";
    row.triangles_scene = 34642;
    row.facets = std::uint64_t(2 * pieces);
    row.frames = 3;
    row.frame_ms = 5 * std::pow(double(row.facets), 0.3);
    rows.push_back(row);
  }
  for (const int width : {200, 283, 400}) {
    driver::BenchRow row;
    row.scale_group = "scale-width-cylinder";
    row.scenario = row.scale_group + ":" + std::to_string(width);
    row.method = "naive";
    row.setting = row.fit_label = "pieces=80";
    row.output_size = std::to_string(width) + "x" + std::to_string(width * 3 / 4);
    row.triangles_scene = 34642;
    row.facets = 160;
    row.frames = 3;
    row.frame_ms = 0.01 * std::pow(double(width), 1.7);
    rows.push_back(row);
  }
  const auto fits = driver::bench_scale_fits(rows);
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(fits[0].setting, "pieces=N");
  EXPECT_EQ(fits[0].rows, 4u);
  ASSERT_TRUE(fits[0].facets_exponent);
  EXPECT_NEAR(*fits[0].facets_exponent, 0.3, 1e-9);
  EXPECT_FALSE(fits[0].triangles_exponent);  // one scene
  EXPECT_FALSE(fits[0].width_exponent);      // one size
  EXPECT_EQ(fits[1].rows, 3u);
  ASSERT_TRUE(fits[1].width_exponent);
  EXPECT_NEAR(*fits[1].width_exponent, 1.7, 0.01);  // 283 stands in for 200·√2
  EXPECT_FALSE(fits[1].facets_exponent);
  std::string notes;
  for (const std::string& note : driver::bench_notes(rows, "test")) notes += note + "\n";
  EXPECT_NE(notes.find("facets pieces=N: facets 0.300 (80 to 640);"), std::string::npos) << notes;
  EXPECT_NE(notes.find("naive pieces=80: width 1.70"), std::string::npos) << notes;
}

// Each scenario's notes name the fastest row on the machine the bench ran on, at any error and
// within 1, 0.5 and 0.25 px of geometric max error; rows that could not be prepared are left out.
TEST(BenchNotes, NameTheFastestMethodWithinEachErrorBound) {
  std::vector<driver::BenchRow> rows;
  const auto add = [&](const char* method, const char* setting, double ms, double max_px) {
    driver::BenchRow row;
    row.scenario = "dome";
    row.method = method;
    row.setting = setting;
    row.frames = 3;
    row.frame_ms = ms;
    row.geometric_max_px = max_px;
    rows.push_back(row);
  };
  add("cubemap", "face=64", 10, 6.0);
  add("cubemap", "face=512", 30, 0.75);
  add("facets", "tol=1px", 20, 0.97);
  add("facets", "tol=0.25px", 40, 0.24);
  add("vertex", "tess=16", 25, 0.6);
  add("facets", "broken", 1, 0.0);
  rows.back().error = "could not be prepared";
  std::string fastest;
  for (const std::string& note : driver::bench_notes(rows, "llvmpipe"))
    if (note.starts_with("dome: fastest on llvmpipe")) fastest = note;
  ASSERT_FALSE(fastest.empty());
  EXPECT_NE(fastest.find("at any error: cubemap face=64, 10.0 ms"), std::string::npos) << fastest;
  EXPECT_NE(fastest.find("within 1 px: facets tol=1px, 20.0 ms"), std::string::npos) << fastest;
  EXPECT_NE(fastest.find("within 0.5 px: facets tol=0.25px, 40.0 ms"), std::string::npos)
      << fastest;
  EXPECT_NE(fastest.find("within 0.25 px: facets tol=0.25px"), std::string::npos) << fastest;
  EXPECT_EQ(fastest.find("broken"), std::string::npos) << fastest;
}

}  // namespace
}  // namespace facet
