// facet run from the command line: a headless session renders the same pixels as facet render,
// writes non-empty frames for every sample display, and rejects bad displays with exit status 2;
// --frames outside 1..1,000,000 and windows without a display server are exit 2; SIGINT and
// SIGTERM stop a headless run with 130 and 143, leaving nothing; a long run keeps a flat resident
// set.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/facet_cli.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;
using test::slurp;

struct Png {
  int width = 0, height = 0, channels = 0;
  std::vector<unsigned char> pixels;
};

Png read_png(const fs::path& path) {
  Png png;
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return png;
  const OIIO::ImageSpec& spec = in->spec();
  png.width = spec.width;
  png.height = spec.height;
  png.channels = spec.nchannels;
  png.pixels.resize(std::size_t(spec.width) * spec.height * spec.nchannels);
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, png.pixels.data());
  return png;
}

// The share of pixels that are not black.
double lit_fraction(const Png& png) {
  if (png.channels < 3 || png.pixels.empty()) return 0;
  std::size_t lit = 0;
  for (std::size_t i = 0; i < png.pixels.size(); i += std::size_t(png.channels))
    lit += png.pixels[i] > 0 || png.pixels[i + 1] > 0 || png.pixels[i + 2] > 0;
  return double(lit) / double(png.pixels.size() / std::size_t(png.channels));
}

TEST(RunCli, HeadlessSessionRendersTheSamePixelsAsRender) {
  const fs::path folder = test::fresh_folder("facet_run_cli_same");
  const std::string common =
      "--size 160x120 --scene builtin:city --method facets --tolerance 0.25 --frames 1";
  ASSERT_EQ(test::run_facet("run builtin:cylinder360 --headless " + common + " --out " +
                                (folder / "session").string(),
                            folder / "run.log"),
            0)
      << slurp(folder / "run.log");
  ASSERT_EQ(test::run_facet("render --display builtin:cylinder360 " + common + " --out " +
                                (folder / "render").string(),
                            folder / "render.log"),
            0)
      << slurp(folder / "render.log");
  const Png session = read_png(folder / "session" / "cylinder360" / "00000.png");
  const Png render = read_png(folder / "render" / "cylinder360.png");
  ASSERT_EQ(session.width, 160);
  ASSERT_EQ(session.height, 120);
  ASSERT_EQ(render.width, session.width);
  ASSERT_EQ(render.height, session.height);
  ASSERT_EQ(render.channels, session.channels);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < session.pixels.size(); ++i)
    differing += session.pixels[i] != render.pixels[i];
  EXPECT_EQ(differing, 0u) << "the session and facet render disagree on " << differing << " bytes";
  // Not a blank image: the city covers the view.
  EXPECT_GT(lit_fraction(session), 0.5);
}

TEST(RunCli, EverySampleDisplayRunsHeadlessWithNonEmptyFrames) {
  const fs::path folder = test::fresh_folder("facet_run_cli_samples");
  int displays = 0;
  for (const auto& entry :
       fs::directory_iterator(fs::path(FACET_SOURCE_DIR) / "configs/displays")) {
    const fs::path display = entry.path() / "display.json";
    if (!entry.is_directory() || !fs::exists(display)) continue;
    ++displays;
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    const fs::path out = folder / name;
    // A sixteenth of the resolution keeps llvmpipe quick; the displays' geometry, blends and
    // sessions, rendered by the default facet pipeline, are what this checks.
    ASSERT_EQ(test::run_facet("run " + display.string() +
                                  " --headless --frames 1 --scale 0.0625 --out " + out.string(),
                              folder / (name + ".log")),
              0)
        << slurp(folder / (name + ".log"));
    int images = 0;
    for (const auto& output : fs::directory_iterator(out)) {
      if (!output.is_directory()) continue;
      const Png png = read_png(output.path() / "00000.png");
      ASSERT_GT(png.width, 0) << output.path();
      EXPECT_GT(lit_fraction(png), 0.0) << output.path() << " is black";
      ++images;
    }
    EXPECT_GT(images, 0);
  }
  EXPECT_GE(displays, 3) << "configs/displays holds fewer sample displays than expected";
}

#ifndef FACET_TEST_WITHOUT_INTEROP
// Runs `import_command` with --out FOLDER/display, then renders one headless frame of the
// imported display.json into FOLDER/frames (with `run_options`).
void import_then_run(const fs::path& folder, const std::string& import_command,
                     const std::string& run_options = "") {
  ASSERT_EQ(test::run_facet(import_command + " --out " + (folder / "display").string(),
                            folder / "import.log"),
            0)
      << slurp(folder / "import.log");
  ASSERT_EQ(test::run_facet("run " + (folder / "display" / "display.json").string() +
                                " --headless --frames 1" + run_options + " --out " +
                                (folder / "frames").string(),
                            folder / "run.log"),
            0)
      << slurp(folder / "run.log");
}

TEST(RunCli, AnImportedSphericalMirrorMeshRendersAtItsDefaultTolerance) {
  // A real Paul Bourke mesh from another tool, imported as is: display.json asks for 0.25 px, which
  // only the bisection builder reaches at the mirror's crowded top corners.
  const fs::path folder = test::fresh_folder("facet_run_cli_mirror");
  ASSERT_NO_FATAL_FAILURE(
      import_then_run(folder, "bourke import " + std::string(FACET_SHARED_DATA_DIR) +
                                  "/warps/sgct-mesh/standard_16x9.data --size 480x270"));
  const Png png = read_png(folder / "frames" / "standard_16x9" / "00000.png");
  ASSERT_EQ(png.width, 480);
  // The city fills most of the mirror's image; its black sky the rest.
  EXPECT_GT(lit_fraction(png), 0.5);
}

TEST(RunCli, AnImportedMpcdiFileOfAnotherToolRenders) {
  // SGCT's real MPCDI 3d container: one 512×540 region whose frustum looks up and to the left.
  const fs::path folder = test::fresh_folder("facet_run_cli_mpcdi");
  ASSERT_NO_FATAL_FAILURE(import_then_run(folder,
                                          "mpcdi import " + std::string(FACET_SHARED_DATA_DIR) +
                                              "/warps/sgct-mpcdi/correction_mesh.mpcdi",
                                          " --scale 0.5"));
  const fs::path frames = folder / "frames";
  fs::path frame;
  for (const auto& entry : fs::directory_iterator(frames)) {
    if (entry.is_directory()) frame = entry.path() / "00000.png";
  }
  ASSERT_TRUE(fs::exists(frame)) << slurp(folder / "run.log");
  const Png png = read_png(frame);
  EXPECT_EQ(png.width, 256);
  EXPECT_EQ(png.height, 270);
  EXPECT_GT(lit_fraction(png), 0.1);
}

TEST(RunCli, AnImportedScissDomeRendersEveryChannel) {
  // The real six-channel SGCT dome configuration, with its windows made 240×150 so that the test
  // stays quick: the meshes are normalised, the masks are resampled to the output.
  const fs::path folder = test::fresh_folder("facet_run_cli_sciss");
  const fs::path source = fs::path(FACET_SHARED_DATA_DIR) / "warps" / "sgct-dome" / "sciss";
  fs::create_directories(folder / "config");
  for (const auto& entry : fs::directory_iterator(source)) {
    fs::copy_file(entry.path(), folder / "config" / entry.path().filename());
  }
  std::string xml = slurp(folder / "config" / "dome_alpha.xml");
  const std::string full_size = "x=\"1920\" y=\"1200\"", small_size = "x=\"240\" y=\"150\"";
  for (std::size_t at; (at = xml.find(full_size)) != std::string::npos;) {
    xml.replace(at, full_size.size(), small_size);
  }
  std::ofstream(folder / "config" / "dome_alpha.xml") << xml;
  ASSERT_NO_FATAL_FAILURE(
      import_then_run(folder, "sgct import " + (folder / "config" / "dome_alpha.xml").string()));
  for (int channel = 1; channel <= 6; ++channel) {
    const Png png =
        read_png(folder / "frames" / ("Channel_" + std::to_string(channel)) / "00000.png");
    ASSERT_EQ(png.width, 240);
    ASSERT_EQ(png.height, 150);
    // Every channel sees the city's towers from the dome's eye, inside its soft-edge mask.
    EXPECT_GT(lit_fraction(png), 0.1) << channel;
  }
}

TEST(RunCli, TheRealSimcadDomeImportsAsShippedAndRendersEveryChannel) {
  // SimCAD's six-channel dome as shipped: its cluster file names no meshes, the .simcad files
  // beside it are found by their frustum tables. A sixteenth of 4096×2160 keeps llvmpipe quick.
  const fs::path folder = test::fresh_folder("facet_run_cli_simcad");
  ASSERT_NO_FATAL_FAILURE(import_then_run(folder,
                                          "sgct import " + std::string(FACET_SHARED_DATA_DIR) +
                                              "/warps/sgct-dome/simcad/dome_bravo.xml",
                                          " --scale 0.0625"));
  EXPECT_NE(slurp(folder / "import.log").find("6 projectors"), std::string::npos)
      << slurp(folder / "import.log");
  for (int channel = 1; channel <= 6; ++channel) {
    const Png png =
        read_png(folder / "frames" / ("channel" + std::to_string(channel) + "_warp") / "00000.png");
    ASSERT_EQ(png.width, 256) << channel;
    ASSERT_EQ(png.height, 135) << channel;
    EXPECT_GT(lit_fraction(png), 0.1) << channel;
  }
}
#endif

TEST(RunCli, BadDisplaysExitWithStatusTwoNamingTheProblem) {
  const fs::path folder = test::fresh_folder("facet_run_cli_bad");
  struct Case {
    std::string name, json, expected;
  };
  const std::vector<Case> cases = {
      {"missing_warp",
       R"({"format": "facet-display/1", "name": "d", "eye": [0, 0, 0], "projectors": [{"name": "p", "size": [64, 48],
          "warp": "nowhere.warp.exr", "output": {"window": [0, 0, 64, 48]}}]})",
       "nowhere.warp.exr"},
      {"wrong_type",
       R"({"format": "facet-display/1", "name": "d", "eye": [0, 0, 0], "projectors": [{"name": "p", "size": "64x48",
          "warp": "p.warp.exr", "output": {"window": [0, 0, 64, 48]}}]})",
       "projectors[0].size"},
      {"nan", R"({"format": "facet-display/1", "name": "d", "eye": [0, NaN, 0], "projectors": []})",
       "expected valid JSON"},
      {"infinite",
       R"({"format": "facet-display/1", "name": "d", "eye": [0, 1e999, 0], "projectors": []})",
       "1e999"},
      {"bad_gamma",
       R"({"format": "facet-display/1", "name": "d", "eye": [0, 0, 0], "projectors": [{"name": "p", "size": [64, 48],
          "warp": "p.warp.exr", "gamma": "linear", "output": {"window": [0, 0, 64, 48]}}]})",
       "gamma"},
      {"misspelled_key",
       R"({"format": "facet-display/1", "name": "d", "eye": [0, 0, 0], "projectors": [{"name": "p", "size": [64, 48],
          "warp": "p.warp.exr", "blnd": "p.blend.exr", "output": {"window": [0, 0, 64, 48]}}]})",
       "display.json: field 'projectors[0].blnd': unknown field 'blnd'; did you mean 'blend'?"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path dir = folder / c.name;
    fs::create_directories(dir);
    std::ofstream(dir / "display.json") << c.json;
    const fs::path out = dir / "frames";
    EXPECT_EQ(test::run_facet("run " + (dir / "display.json").string() +
                                  " --headless --frames 1 --out " + out.string(),
                              dir / "log"),
              2);
    const std::string log = slurp(dir / "log");
    EXPECT_NE(log.find(c.expected), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(out)) << "a failed run left output behind";
  }
}

// The same limit as facet render and bench (render_cli_test, bench_test), named in the message.
TEST(RunCli, FramesOutsideOneToAMillionExitWithStatusTwo) {
  const fs::path folder = test::fresh_folder("facet_run_cli_frames");
  for (const char* frames : {"-1", "0", "99999999"}) {
    SCOPED_TRACE(frames);
    const fs::path out = folder / "out";
    EXPECT_EQ(test::run_facet("run builtin:cylinder360 --headless --size 64x32 --frames " +
                                  std::string(frames) + " --out " + out.string(),
                              folder / "log"),
              2);
    const std::string log = slurp(folder / "log");
    EXPECT_NE(
        log.find("'--frames': a number of frames from 1 to 1000000, got " + std::string(frames)),
        std::string::npos)
        << log;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(RunCli, WindowsWithoutADisplayServerExitWithStatusTwo) {
  const fs::path folder = test::fresh_folder("facet_run_cli_no_display");
  for (const std::string& command :
       {std::string("run builtin:cylinder360 --windowed --frames 1 --size 64x32"),
        std::string("run --monitors")}) {
    SCOPED_TRACE(command);
    // No display server named, and one named that does not exist.
    for (const std::string& environment : {std::string("env -u DISPLAY -u WAYLAND_DISPLAY"),
                                           std::string("env -u WAYLAND_DISPLAY DISPLAY=:4711")}) {
      std::string output;
      EXPECT_EQ(test::run_shell(environment + " " + FACET_CLI + " " + command, &output), 2)
          << environment << "\n"
          << output;
      EXPECT_NE(output.find("display server"), std::string::npos) << output;
      if (command.find("--windowed") != std::string::npos) {
        EXPECT_NE(output.find("use --headless"), std::string::npos) << output;
      }
      EXPECT_EQ(output.find("internal error"), std::string::npos) << output;
    }
  }
}

// A long headless run stopped by SIGINT, then one by SIGTERM over an earlier run: the documented
// status (128 + the signal), one line saying how far it got, no output folder (or the earlier run
// untouched) and no temporary folder beside it.
TEST(RunCli, SigintAndSigtermStopAHeadlessRunAndLeaveNothing) {
  const fs::path folder = test::fresh_folder("facet_run_cli_signals");
  const fs::path earlier = folder / "earlier";
  ASSERT_EQ(test::run_facet("run builtin:cylinder360 --headless --size 64x32 --frames 1 --out " +
                                earlier.string(),
                            folder / "earlier.log"),
            0)
      << slurp(folder / "earlier.log");
  for (const int signal : {SIGINT, SIGTERM}) {
    const std::string name = signal == SIGINT ? "SIGINT" : "SIGTERM";
    SCOPED_TRACE(name);
    const fs::path out = signal == SIGINT ? folder / "new" : earlier;
    const fs::path log = folder / (name + ".log");
    const pid_t child = test::start_facet({"run", "builtin:cylinder360", "--headless", "--size",
                                           "64x32", "--frames", "1000000", "--out", out.string()},
                                          log);
    ASSERT_GT(child, 0);
    // The second frame in the temporary folder: the handlers are in place and frames are running.
    const fs::path second = folder /
                            ("." + out.filename().string() + ".tmp" + std::to_string(child)) /
                            "cylinder360" / "00001.png";
    const bool running =
        test::wait_until([&] { return fs::exists(second); }, std::chrono::seconds(60));
    ::kill(child, signal);
    const int status = test::wait_for_exit(child);
    ASSERT_TRUE(running) << slurp(log);
    EXPECT_EQ(status, 128 + signal) << slurp(log);
    const std::string output = slurp(log);
    EXPECT_NE(output.find("facet run: interrupted by " + name + ": stopped after "),
              std::string::npos)
        << output;
    EXPECT_NE(output.find(" of 1000000 frames; nothing written to " + out.string()),
              std::string::npos)
        << output;
    if (signal == SIGINT) {
      EXPECT_FALSE(fs::exists(out));
    } else {
      // The earlier run is as it was: one frame and its statistics.
      EXPECT_TRUE(fs::exists(earlier / "cylinder360" / "00000.png"));
      EXPECT_FALSE(fs::exists(earlier / "cylinder360" / "00001.png"));
      EXPECT_EQ(slurp(earlier / "stats.jsonl").find('\n') + 1,
                slurp(earlier / "stats.jsonl").size());
    }
    for (const fs::directory_entry& entry : fs::directory_iterator(folder))
      EXPECT_NE(entry.path().filename().string().front(), '.') << entry.path();
  }
}

// A long headless run keeps what it holds bounded: its resident set after frame 100 grows by at
// most 4 MiB by frame 299 (a leak of 20 KiB per frame or more fails), every frame is in
// stats.jsonl, and --save-every writes the images of frames 0, 100, 200 and the last only. The
// 10,000-frame run of the README is the same command with more frames.
TEST(RunCli, ALongHeadlessRunKeepsAFlatResidentSet) {
  const fs::path folder = test::fresh_folder("facet_run_cli_soak");
  // ASan's quarantine of freed memory grows the resident set by design; without it what stays
  // resident is what the process holds, as in the normal build.
  const char* asan = std::getenv("ASAN_OPTIONS");
  const std::string asan_options = (asan ? std::string(asan) + ":" : std::string()) +
                                   "quarantine_size_mb=0:thread_local_quarantine_size_kb=0";
  ::setenv("ASAN_OPTIONS", asan_options.c_str(), 1);
  const fs::path out = folder / "out";
  const int status = test::run_facet(
      "run " + (fs::path(FACET_SOURCE_DIR) / "configs/displays/dome4/display.json").string() +
          " --headless --scale 0.125 --frames 300 --save-every 100 --out " + out.string(),
      folder / "log");
  if (asan)
    ::setenv("ASAN_OPTIONS", asan, 1);
  else
    ::unsetenv("ASAN_OPTIONS");
  ASSERT_EQ(status, 0) << slurp(folder / "log");
  std::ifstream stats(out / "stats.jsonl");
  std::vector<std::uint64_t> rss_kib;
  for (std::string line; std::getline(stats, line);) {
    const auto frame_at = line.find("\"frame\":");
    const auto rss_at = line.find("\"rss_kib\":");
    ASSERT_NE(frame_at, std::string::npos) << line;
    ASSERT_NE(rss_at, std::string::npos) << line;
    EXPECT_EQ(std::stoull(line.substr(frame_at + 8)), rss_kib.size());
    rss_kib.push_back(std::stoull(line.substr(rss_at + 10)));
  }
  ASSERT_EQ(rss_kib.size(), 300u);
  EXPECT_GT(rss_kib[40], 0u);
  // From frame 40 on (start-up's allocations settled), the least-squares slope of the resident
  // set against the frame number stays under 0.25 KiB/frame, and the whole growth under 256 KiB.
  // Without a leak both are 0 (the set does not change after frame 40). A leak first fills the
  // heap's free pages, which are resident already: one injected at 4 KiB/frame showed a slope of
  // 0.32 KiB/frame and 148 KiB of growth (it fails the slope), one at 20 KiB/frame 24 KiB/frame;
  // 2 KiB/frame stayed hidden in the free pages for these 300 frames.
  double mean_frame = 0, mean_rss = 0;
  for (std::size_t frame = 40; frame < 300; ++frame) {
    mean_frame += static_cast<double>(frame) / 260;
    mean_rss += static_cast<double>(rss_kib[frame]) / 260;
  }
  double covariance = 0, variance = 0;
  for (std::size_t frame = 40; frame < 300; ++frame) {
    const double x = static_cast<double>(frame) - mean_frame;
    covariance += x * (static_cast<double>(rss_kib[frame]) - mean_rss);
    variance += x * x;
  }
  const double slope_kib_per_frame = covariance / variance;
  const double growth_kib = static_cast<double>(rss_kib[299]) - static_cast<double>(rss_kib[40]);
  std::cout << "resident set " << rss_kib[40] << " KiB after frame 40, " << rss_kib[299]
            << " KiB after frame 299: growth " << growth_kib << " KiB, slope "
            << slope_kib_per_frame << " KiB/frame\n";
  EXPECT_LT(slope_kib_per_frame, 0.25) << "KiB/frame from frame 40 to 299";
  EXPECT_LT(growth_kib, 256.0) << "KiB from frame 40 to 299";
  std::vector<std::string> images;
  for (const auto& entry : fs::recursive_directory_iterator(out))
    if (entry.path().extension() == ".png")
      images.push_back(entry.path().parent_path().filename().string() + "/" +
                       entry.path().filename().string());
  std::sort(images.begin(), images.end());
  std::vector<std::string> expected;
  for (const char* projector : {"p0", "p1", "p2", "p3"})
    for (const char* frame : {"00000", "00100", "00200", "00299"})
      expected.push_back(std::string(projector) + "/" + frame + ".png");
  EXPECT_EQ(images, expected);
  // An interval below one frame is refused before anything is rendered.
  EXPECT_EQ(
      test::run_facet("run builtin:cylinder360 --headless --size 64x32 --save-every 0 --out " +
                          (folder / "zero").string(),
                      folder / "log"),
      2);
  EXPECT_NE(slurp(folder / "log").find("'--save-every'"), std::string::npos)
      << slurp(folder / "log");
  EXPECT_FALSE(fs::exists(folder / "zero"));
  fs::remove_all(folder);
}

// facet preview of the shipped dome4 about its 30°-tilted zenith: every direction above the spring
// line covered, blends summing to 1 within 0.005; bad flags are exit 2 with nothing written.
TEST(PreviewCli, Dome4IsCoveredAndBadFlagsWriteNothing) {
  const fs::path folder = test::fresh_folder("facet_run_cli_preview");
  const std::string dome4 =
      (fs::path(FACET_SOURCE_DIR) / "configs/displays/dome4/display.json").string();
  const fs::path image = folder / "dome4.png";
  ASSERT_EQ(test::run_facet("preview " + dome4 +
                                " --tilt 30 --preview-size 128 --show blend --json --out " +
                                image.string(),
                            folder / "log"),
            0)
      << slurp(folder / "log");
  const std::string log = slurp(folder / "log");
  const auto json = nlohmann::json::parse(log.substr(log.find('{')));
  EXPECT_EQ(json["view"], "fisheye");
  EXPECT_EQ(json["uncovered_sr"], 0.0);
  EXPECT_LE(json["blend_sum_worst_error"].get<double>(), 0.005);
  EXPECT_EQ(json["projectors"].size(), 4u);
  const Png png = read_png(image);
  EXPECT_EQ(png.width, 128);
  EXPECT_EQ(png.height, 128);
  for (const std::string flags :
       {"--show colours", "--view cube", "--preview-size 4", "--fov 400"}) {
    SCOPED_TRACE(flags);
    const fs::path bad = folder / "bad.png";
    EXPECT_EQ(test::run_facet("preview " + dome4 + " " + flags + " --out " + bad.string(),
                              folder / "log"),
              2);
    EXPECT_NE(slurp(folder / "log").find(flags.substr(0, flags.find(' '))), std::string::npos)
        << slurp(folder / "log");
    EXPECT_FALSE(fs::exists(bad));
  }
  fs::remove_all(folder);
}

// --pattern shows a test pattern instead of the scene; an unknown one is exit 2 naming the flag,
// with nothing written.
TEST(RunCli, APatternReplacesTheScene) {
  const fs::path folder = test::fresh_folder("facet_run_cli_pattern");
  const fs::path out = folder / "out";
  ASSERT_EQ(test::run_facet(
                "run builtin:wall2x2 --size 96x64 --headless --frames 1 --pattern projector-ids "
                "--out " +
                    out.string(),
                folder / "log"),
            0)
      << slurp(folder / "log");
  const Png png = read_png(out / "wall_r1c1" / "00000.png");
  ASSERT_EQ(png.width, 96);
  EXPECT_EQ(lit_fraction(png), 1.0);
  EXPECT_EQ(test::run_facet(
                "run builtin:wall2x2 --size 96x64 --headless --frames 1 --pattern stripes --out " +
                    (folder / "bad").string(),
                folder / "log"),
            2);
  EXPECT_NE(slurp(folder / "log").find("'--pattern'"), std::string::npos) << slurp(folder / "log");
  EXPECT_FALSE(fs::exists(folder / "bad"));
  fs::remove_all(folder);
}

}  // namespace
}  // namespace facet
