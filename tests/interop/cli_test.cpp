#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "facet/interop/mpcdi.hpp"
#include "facet/interop/pfm.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "test_util.hpp"

namespace facet::interop {
namespace {

namespace fs = std::filesystem;
const std::string kWarps = std::string(FACET_SHARED_DATA_DIR) + "/warps/";

using test::CliRun;
using test::run;

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(InteropCli, RealFilesFromOtherToolsImportToReadableDisplays) {
  test::TempFolder scratch("facet-interop-cli-real");
  for (const char* name : {"correction_mesh", "zero_distortion_mesh"}) {
    const fs::path out = scratch.path() / name;
    const CliRun r =
        run("mpcdi import " + kWarps + "sgct-mpcdi/" + name + ".mpcdi --out " + out.string(),
            scratch.path());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto display = projection_io::read_display_config(out / "display.json");
    ASSERT_EQ(display.projectors.size(), 1u);
    EXPECT_NO_THROW(read_warp(display.resolve(display.projectors[0].warp).string()));
    // The imported warp feeds `facet error --warp`.
    const CliRun error =
        run("error --warp " + display.resolve(display.projectors[0].warp).string() +
                " --tolerance 0.25 --json",
            scratch.path());
    EXPECT_EQ(error.status, 0) << error.output;
  }
  const fs::path mirror = scratch.path() / "mirror";
  const CliRun r =
      run("bourke import " + kWarps + "sgct-mesh/standard_16x9.data --out " + mirror.string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto display = projection_io::read_display_config(mirror / "display.json");
  EXPECT_NO_THROW(read_warp(display.resolve(display.projectors[0].warp).string()));
  ASSERT_TRUE(display.projectors[0].blend);
  // The mirror crowds many output pixels into a sliver of the fisheye at its top corners: a tensor
  // grid refining whole rows and columns there needs more than 2^20 cells for 0.25 px, bisection
  // refines the corners alone. Worst case over dense samples, output px.
  const std::string warp_path = display.resolve(display.projectors[0].warp).string();
  const CliRun error =
      run("error --warp " + warp_path + " --tolerance 0.25 --json", scratch.path());
  ASSERT_EQ(error.status, 0) << error.output;
  EXPECT_NE(error.output.find("\"layout\":\"tolerance 0.25 px, bisection\""), std::string::npos)
      << error.output;
  const std::size_t max_at = error.output.find("\"max_px\":");
  ASSERT_NE(max_at, std::string::npos) << error.output;
  EXPECT_LE(std::strtod(error.output.c_str() + max_at + 9, nullptr), 0.25) << error.output;
  EXPECT_EQ(run("error --warp " + warp_path + " --tolerance 0.25 --builder tensor", scratch.path())
                .status,
            2);
}

TEST(InteropCli, ExportImportRoundTripThroughTheCommands) {
  test::TempFolder scratch("facet-interop-cli-roundtrip");
  const Warp warp = test::calibrated_like_warp({320, 200}, {17, 11});
  write_warp((scratch.path() / "p0.warp.exr").string(), warp);
  write_file(scratch.path() / "display.json",
             R"({"format": "facet-display/1", "name": "t", "eye": [0, 0, 0],
                 "projectors": [{"name": "p0", "size": [320, 200], "warp": "p0.warp.exr",
                                 "output": {"window": [0, 0, 320, 200]}}]})");
  // Nodes every 2 px: the error of the PFM's bilinear interpolation shrinks with the square of
  // the spacing, and this small image bends faster per pixel than a full-size projector's.
  CliRun r = run("mpcdi export --node-spacing 2 " + (scratch.path() / "display.json").string() +
                     " --out " + (scratch.path() / "d.mpcdi").string(),
                 scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  r = run("mpcdi import " + (scratch.path() / "d.mpcdi").string() + " --out " +
              (scratch.path() / "back").string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  const Warp back = read_warp((scratch.path() / "back" / "p0.warp.exr").string());
  double worst = 0;
  for (int j = 0; j <= 50; ++j) {
    for (int i = 0; i <= 50; ++i) {
      const glm::dvec2 st{i / 50.0, j / 50.0};
      if (back.coverage_at(st) < 0.5) continue;
      worst = std::max(worst, glm::length(warp.q_from_st(st) - back.q_from_st(st)));
    }
  }
  EXPECT_LT(worst, 0.01);
  // Importing into a folder that holds files is refused.
  r = run("mpcdi import " + (scratch.path() / "d.mpcdi").string() + " --out " +
              (scratch.path() / "back").string(),
          scratch.path());
  EXPECT_EQ(r.status, 2) << r.output;
}

TEST(InteropCli, BadFilesExitWithStatus2AndLeaveNothingBehind) {
  test::TempFolder scratch("facet-interop-cli-bad");
  write_file(scratch.path() / "text.mpcdi", "not a zip at all");
  write_file(scratch.path() / "bad.data", "2\n3 2\n-1.5 -1 0 0 1\n");
  PfmImage pfm;
  pfm.width = pfm.height = 2;
  pfm.values.assign(12, std::numeric_limits<float>::quiet_NaN());
  MpcdiFiles files{{"mpcdi.xml",
                    "<MPCDI profile=\"3d\"><display><buffer xResolution=\"8\" yResolution=\"8\">"
                    "<region id=\"r\" x=\"0\" y=\"0\" xSize=\"1\" ySize=\"1\" xResolution=\"8\" "
                    "yResolution=\"8\"><frustum><yaw>0</yaw><pitch>0</pitch><roll>0</roll>"
                    "<rightAngle>10</rightAngle><leftAngle>-10</leftAngle><upAngle>10</upAngle>"
                    "<downAngle>-10</downAngle></frustum></region></buffer></display><files>"
                    "<fileset region=\"r\"><geometryWarpFile><path>w.pfm</path>"
                    "</geometryWarpFile></fileset></files></MPCDI>"},
                   {"w.pfm", format_pfm(pfm)}};  // every node NaN: a warp that shows nothing
  write_zip_file(scratch.path() / "collapsed.mpcdi", files);
  const std::vector<std::string> commands{
      "mpcdi import " + (scratch.path() / "text.mpcdi").string(),
      "mpcdi import " + (scratch.path() / "collapsed.mpcdi").string(),
      "mpcdi import " + (scratch.path() / "missing.mpcdi").string(),
      "bourke import " + (scratch.path() / "bad.data").string(),
      "bourke import " + kWarps + "sgct-mesh/standard_16x9.data --size 1000x1000",
      "sgct import " + (scratch.path() / "bad.data").string(),
      "sgct import " + kWarps + "sgct-dome/sciss/channel1_planar.sgc " +
          (scratch.path() / "bad.data").string(),
      "sgct import " + kWarps + "sgct-dome/sciss/channel1_planar.sgc --size 0x10",
      "sgct export " + (scratch.path() / "missing.json").string(),
      "sgct export " + std::string(FACET_SOURCE_DIR) +
          "/configs/displays/wall2x2/display.json --node-spacing 0",
  };
  for (const std::string& command : commands) {
    const fs::path out = scratch.path() / "out";
    const CliRun r = run(command + " --out " + out.string(), scratch.path());
    EXPECT_EQ(r.status, 2) << command << "\n" << r.output;
    EXPECT_NE(r.output.find("facet: error:"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out)) << command;
  }
  // Nothing but the inputs and the log: no temporary folders left over.
  int entries = 0;
  for (const auto& entry : fs::directory_iterator(scratch.path())) {
    (void)entry;
    ++entries;
  }
  EXPECT_EQ(entries, 4);
  const CliRun lookup = run("lookup --warp " + (scratch.path() / "none.warp.exr").string() +
                                " --out " + (scratch.path() / "l.exr").string(),
                            scratch.path());
  EXPECT_EQ(lookup.status, 2) << lookup.output;
  EXPECT_FALSE(fs::exists(scratch.path() / "l.exr"));
}

TEST(InteropCli, AnSgctDomeConfigurationAndBareSgcMeshesImport) {
  test::TempFolder scratch("facet-interop-cli-sgct");
  const fs::path dome = scratch.path() / "dome";
  CliRun r = run("sgct import " + kWarps + "sgct-dome/sciss/dome_alpha.xml --out " + dome.string(),
                 scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("6 projectors"), std::string::npos) << r.output;
  const auto display = projection_io::read_display_config(dome / "display.json");
  ASSERT_EQ(display.projectors.size(), 6u);
  for (const auto& projector : display.projectors) {
    EXPECT_EQ(projector.size, glm::ivec2(1920, 1200));
    ASSERT_TRUE(projector.blend);
    EXPECT_NO_THROW(read_warp(display.resolve(projector.warp).string()));
  }
  // The imported warps meet facet's default 0.25 px with facets (worst case, output px).
  const CliRun error =
      run("error --warp " + display.resolve(display.projectors[0].warp).string() + " --json",
          scratch.path());
  ASSERT_EQ(error.status, 0) << error.output;
  const std::size_t max_at = error.output.find("\"max_px\":");
  ASSERT_NE(max_at, std::string::npos) << error.output;
  EXPECT_LE(std::strtod(error.output.c_str() + max_at + 9, nullptr), 0.25) << error.output;

  // SimCAD's dome as shipped: the cluster file names no meshes; the .simcad files beside it hold
  // them.
  const fs::path simcad = scratch.path() / "simcad";
  r = run("sgct import " + kWarps + "sgct-dome/simcad/dome_bravo.xml --out " + simcad.string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("6 projectors"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("took \"channel6_warp.simcad\""), std::string::npos) << r.output;
  const auto simcad_display = projection_io::read_display_config(simcad / "display.json");
  ASSERT_EQ(simcad_display.projectors.size(), 6u);
  for (const auto& projector : simcad_display.projectors) {
    EXPECT_EQ(projector.size, glm::ivec2(4096, 2160));
  }

  const fs::path meshes = scratch.path() / "meshes";
  r = run("sgct import " + kWarps + "sgct-dome/simcad/channel1_warp_u2.sgc " + kWarps +
              "sgct-dome/simcad/channel2_warp_u3.sgc --size 1024x640 --out " + meshes.string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto bare = projection_io::read_display_config(meshes / "display.json");
  ASSERT_EQ(bare.projectors.size(), 2u);
  EXPECT_EQ(bare.projectors[1].output.window, glm::ivec4(1024, 0, 1024, 640));
  EXPECT_FALSE(bare.projectors[0].blend);

  // A facet display out to SGCT and back.
  const fs::path exported = scratch.path() / "exported";
  r = run("sgct export " + std::string(FACET_SOURCE_DIR) +
              "/configs/displays/wall2x2/display.json --node-spacing 8 --out " + exported.string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* name : {"cluster.xml", "wall_r0c0.sgc", "wall_r1c1_mask.png"}) {
    EXPECT_TRUE(fs::exists(exported / name)) << name;
  }
  r = run("sgct import " + (exported / "cluster.xml").string() + " --out " +
              (scratch.path() / "back").string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  const projection_io::DisplayConfig back =
      projection_io::read_display_config(scratch.path() / "back" / "display.json");
  EXPECT_EQ(back.projectors.size(), 4u);
  // One SGCT node per projector, all on 127.0.0.1: a cluster section facet run --node takes.
  ASSERT_TRUE(back.cluster.has_value());
  ASSERT_EQ(back.cluster->nodes.size(), 4u);
  EXPECT_EQ(back.cluster->master, "node0");
  EXPECT_EQ(back.cluster->nodes[3].address, "tcp://127.0.0.1:7406");
  EXPECT_EQ(back.cluster->nodes[3].projectors, std::vector<std::string>{back.projectors[3].name});
}

#ifndef FACET_TEST_WITHOUT_DRIVER
// The first projector's warp of FOLDER/display.json.
Warp first_warp(const fs::path& folder) {
  const auto display = projection_io::read_display_config(folder / "display.json");
  return read_warp(display.resolve(display.projectors.at(0).warp).string());
}

// The angle between two directions, radians.
double angle_between(glm::dvec3 a, glm::dvec3 b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// A fisheye master (Bourke's mirror mesh, builtin:dome180) puts its image centre overhead by
// default; --zenith front puts it straight ahead; --tilt and --orientation then place the dome
// around the viewer (eye frame: x right, y up, −z ahead). Rotations are written as doubles, so the
// directions hold within 1e-9 rad.
TEST(InteropCli, DomesTakeTheirZenithTiltAndOrientation) {
  test::TempFolder scratch("facet-interop-cli-orientation");
  const std::string mirror =
      "bourke import " + kWarps + "sgct-mesh/standard_16x9.data --size 480x270";
  const glm::dvec2 centre{0.5, 0.5}, bottom_middle{0.5, 1.0};  // of the fisheye master
  const double half = 0.5, root3_2 = std::sqrt(3.0) / 2;
  struct Case {
    std::string flags;
    glm::dvec3 zenith;  // where the master's centre points
  };
  const std::vector<Case> cases = {
      {"", {0, 1, 0}},
      {"--zenith centre", {0, 1, 0}},
      {"--zenith front", {0, 0, -1}},
      {"--tilt 30", {0, root3_2, -half}},
      {"--tilt 30 --orientation 90", {half, root3_2, 0}},
  };
  int k = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.flags);
    const fs::path out = scratch.path() / ("mirror" + std::to_string(k++));
    const CliRun r = run(mirror + " " + c.flags + " --out " + out.string(), scratch.path());
    ASSERT_EQ(r.status, 0) << r.output;
    const Warp warp = first_warp(out);
    EXPECT_LE(angle_between(warp.v_eye_from_st(centre), c.zenith), 1e-9);
    if (c.flags.empty()) {
      // A dome master's bottom edge is the front.
      EXPECT_LE(angle_between(warp.v_eye_from_st(bottom_middle), {0, 0, -1}), 1e-9);
    }
  }
  // The analytic built-in dome, written out by facet display.
  for (const Case& c : {cases[0], cases[3], cases[4]}) {
    SCOPED_TRACE(c.flags);
    const fs::path out = scratch.path() / ("builtin" + std::to_string(k++));
    const CliRun r =
        run("display builtin:dome180 --size 64x64 " + c.flags + " --out " + out.string(),
            scratch.path());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_LE(angle_between(first_warp(out).v_eye_from_st(centre), c.zenith), 1e-9);
  }
  // An SGCT import turned by 90°: every direction turns from ahead (−z) toward the right (+x).
  const std::string bravo = "sgct import " + kWarps + "sgct-dome/simcad/dome_bravo.xml";
  CliRun r = run(bravo + " --out " + (scratch.path() / "bravo").string(), scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  r = run(bravo + " --orientation 90 --out " + (scratch.path() / "bravo90").string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  const glm::dvec3 v = first_warp(scratch.path() / "bravo").v_eye_from_st(centre);
  EXPECT_LE(
      angle_between(first_warp(scratch.path() / "bravo90").v_eye_from_st(centre), {-v.z, v.y, v.x}),
      1e-9);

  // Bad values exit 2 naming the flag, writing nothing.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {mirror + " --tilt 200", "--tilt"},
      {mirror + " --zenith sideways", "--zenith"},
      {mirror + " --orientation east", "--orientation"},
      {bravo + " --tilt -91", "--tilt"},
      {"mpcdi import " + kWarps + "sgct-mpcdi/correction_mesh.mpcdi --orientation 400",
       "--orientation"},
      {"display builtin:cylinder360 --tilt 10", "--tilt"},
  };
  for (const auto& [command, flag] : bad) {
    const fs::path out = scratch.path() / "bad";
    const CliRun failed = run(command + " --out " + out.string(), scratch.path());
    EXPECT_EQ(failed.status, 2) << command << "\n" << failed.output;
    EXPECT_NE(failed.output.find("'" + flag + "'"), std::string::npos) << failed.output;
    EXPECT_FALSE(fs::exists(out)) << command;
  }
}
#endif

TEST(InteropCli, ProfileA3ThroughTheCommands) {
  test::TempFolder scratch("facet-interop-cli-a3");
  const std::string dome = std::string(FACET_SOURCE_DIR) + "/configs/displays/dome4";
  const fs::path container = scratch.path() / "dome4.mpcdi";
  CliRun r =
      run("mpcdi export " + dome + " --profile a3 --node-spacing 8 --out " + container.string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  r = run("mpcdi import " + container.string() + " --eye 0,0,0 --out " +
              (scratch.path() / "back").string(),
          scratch.path());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto display = projection_io::read_display_config(scratch.path() / "back" / "display.json");
  EXPECT_EQ(display.projectors.size(), 4u);
  // Bad options and a bad unit: status 2 naming what is wrong, nothing written.
  r = run("mpcdi export " + dome + " --profile 2d --out " + (scratch.path() / "x.mpcdi").string(),
          scratch.path());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--profile"), std::string::npos) << r.output;
  r = run(
      "mpcdi import " + container.string() + " --eye 1,2 --out " + (scratch.path() / "y").string(),
      scratch.path());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--eye"), std::string::npos) << r.output;
  MpcdiFiles files = read_zip_file(container);
  const std::string unit = "<geometricUnit>m</geometricUnit>";
  std::string& xml = files.at("mpcdi.xml");
  ASSERT_NE(xml.find(unit), std::string::npos) << xml;
  xml.replace(xml.find(unit), unit.size(), "<geometricUnit>parsec</geometricUnit>");
  write_zip_file(scratch.path() / "bad_unit.mpcdi", files);
  r = run("mpcdi import " + (scratch.path() / "bad_unit.mpcdi").string() + " --out " +
              (scratch.path() / "z").string(),
          scratch.path());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("geometryWarpFile/geometricUnit"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(scratch.path() / "x.mpcdi"));
  EXPECT_FALSE(fs::exists(scratch.path() / "y"));
  EXPECT_FALSE(fs::exists(scratch.path() / "z"));
}

TEST(InteropCli, LookupOfAWarp) {
  test::TempFolder scratch("facet-interop-cli-lookup");
  write_warp((scratch.path() / "w.warp.exr").string(),
             test::calibrated_like_warp({64, 40}, {5, 5}));
  const CliRun r = run("lookup --warp " + (scratch.path() / "w.warp.exr").string() + " --out " +
                           (scratch.path() / "l.exr").string(),
                       scratch.path());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(scratch.path() / "l.exr"));
  // Never over its input, nor over something that is not a regular file.
  const auto size_before = fs::file_size(scratch.path() / "w.warp.exr");
  for (const std::string& out :
       {(scratch.path() / "w.warp.exr").string(), (scratch.path() / "." / "w.warp.exr").string(),
        std::string("/dev/null")}) {
    const CliRun over =
        run("lookup --warp " + (scratch.path() / "w.warp.exr").string() + " --out " + out,
            scratch.path());
    EXPECT_EQ(over.status, 2) << over.output;
    EXPECT_NE(over.output.find(out), std::string::npos) << over.output;
  }
  EXPECT_EQ(fs::file_size(scratch.path() / "w.warp.exr"), size_before);
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

#ifndef FACET_TEST_WITHOUT_DRIVER
TEST(InteropCli, LookupOfADisplayWritesNothingWhenOneWarpIsBad) {
  test::TempFolder scratch("facet-interop-cli-lookup-display");
  const fs::path wall = scratch.path() / "wall", lookups = scratch.path() / "lookups";
  const CliRun made = run("display builtin:wall2x2 --out " + wall.string(), scratch.path());
  ASSERT_EQ(made.status, 0) << made.output;
  std::ofstream(wall / "wall_r1c1.warp.exr") << "not an EXR";
  const CliRun r =
      run("lookup --display " + (wall / "display.json").string() + " --out " + lookups.string(),
          scratch.path());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("wall_r1c1.warp.exr"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(lookups));
}

// A display's lookups go into --out as one folder: a second run replaces an earlier lookup
// folder; a folder holding anything else, or the display's own folder, is refused with exit 2 and
// left as it was.
TEST(InteropCli, LookupOfADisplayReplacesOnlyAnEarlierLookupFolder) {
  test::TempFolder scratch("facet-interop-cli-lookup-folder");
  const fs::path wall = scratch.path() / "wall", lookups = scratch.path() / "lookups";
  ASSERT_EQ(run("display builtin:wall2x2 --out " + wall.string(), scratch.path()).status, 0);
  const std::string command = "lookup --display " + (wall / "display.json").string() + " --out ";
  for (int round = 0; round < 2; ++round) {
    const CliRun r = run(command + lookups.string(), scratch.path());
    ASSERT_EQ(r.status, 0) << r.output;
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(lookups)) {
      EXPECT_TRUE(entry.path().filename().string().ends_with(".lookup.exr")) << entry.path();
      ++files;
    }
    EXPECT_EQ(files, 4u);
  }
  const fs::path mine = scratch.path() / "mine";
  fs::create_directories(mine);
  std::ofstream(mine / "notes.txt") << "keep me";
  const CliRun foreign = run(command + mine.string(), scratch.path());
  EXPECT_EQ(foreign.status, 2) << foreign.output;
  EXPECT_NE(foreign.output.find("--out"), std::string::npos) << foreign.output;
  EXPECT_EQ(std::distance(fs::directory_iterator(mine), fs::directory_iterator{}), 1);
  const CliRun over_input = run(command + wall.string(), scratch.path());
  EXPECT_EQ(over_input.status, 2) << over_input.output;
  EXPECT_TRUE(fs::exists(wall / "display.json"));
}
#endif

#ifndef FACET_TEST_WITHOUT_CALIBRATION
// A FIFO where a file is expected blocked the reader until killed; every reader now refuses a
// path that is not a regular file (require_regular_file). Each run is limited to 20 s by
// timeout(1), whose status 124 would fail the test.
TEST(InteropCli, InputsThatAreNotRegularFilesAreRefused) {
  test::TempFolder scratch("facet-interop-cli-fifo");
  const fs::path fifo_dir = scratch.path() / "fifos";
  fs::create_directories(fifo_dir);
  const auto fifo = [&](const std::string& name) {
    const fs::path path = fifo_dir / name;
    EXPECT_EQ(::mkfifo(path.c_str(), 0600), 0) << path;
    return path.string();
  };
  const std::string out = (scratch.path() / "out").string();
  const std::string folder = fifo_dir.string();
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"lookup --warp " + fifo("a.warp.exr") + " --out " + out + ".exr", "a.warp.exr"},
      {"lookup --display " + fifo("display.json") + " --out " + out, "display.json"},
      {"mpcdi import " + fifo("a.mpcdi") + " --out " + out, "a.mpcdi"},
      {"sgct import " + fifo("cluster.xml") + " --out " + out, "cluster.xml"},
      {"sgct import " + fifo("mesh.sgc") + " --out " + out, "mesh.sgc"},
      {"bourke import " + fifo("mesh.data") + " --out " + out, "mesh.data"},
      {"error --warp " + fifo("b.warp.exr"), "b.warp.exr"},
      {"calibrate " + fifo("capture.json") + " --out " + out, "capture.json"},
      {"lookup --warp " + folder + " --out " + out + ".exr", "fifos"},
  };
  for (const auto& [arguments, named] : runs) {
    const CliRun r = run(arguments, scratch.path(), 20);
    EXPECT_EQ(r.status, 2) << arguments << ": " << r.output;
    EXPECT_NE(r.output.find(named), std::string::npos) << arguments << ": " << r.output;
    EXPECT_FALSE(fs::exists(out)) << arguments;
    EXPECT_FALSE(fs::exists(out + ".exr")) << arguments;
  }
}
#endif

#ifndef FACET_TEST_WITHOUT_DRIVER
TEST(InteropCli, AbsurdSizesAndGridsAreRefusedUpFront) {
  test::TempFolder scratch("facet-interop-cli-sizes");
  const std::string out = (scratch.path() / "out").string();
  for (const std::string& arguments :
       {"display builtin:cylinder360 --size 100000x100000 --out " + out,
        "display builtin:cylinder360 --size 16385x2 --out " + out,
        "display builtin:wall2x2 --grid 65536x1 --out " + out,
        std::string("error --base fisheye --size 9000x9000")}) {
    const CliRun r = run(arguments, scratch.path(), 20);
    EXPECT_EQ(r.status, 2) << arguments << ": " << r.output;
    EXPECT_FALSE(fs::exists(out)) << arguments;
  }
}
#endif

TEST(InteropCli, DevicesListsOrSaysThereAreNone) {
  test::TempFolder scratch("facet-interop-cli-devices");
  CliRun r = run("devices", scratch.path());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(r.output.find("no USB devices") != std::string::npos ||
              r.output.find("VID:PID") != std::string::npos)
      << r.output;
  r = run("devices --watch --for 1", scratch.path());
  EXPECT_EQ(r.status, 0) << r.output;
  // It says how it follows hotplug.
  EXPECT_TRUE(r.output.find("(libusb hotplug events)") != std::string::npos ||
              r.output.find("(polling)") != std::string::npos)
      << r.output;
  r = run("devices --find camera0", scratch.path());
  EXPECT_EQ(r.status, 2) << r.output;
}

}  // namespace
}  // namespace facet::interop
