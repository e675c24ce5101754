// facet play through the CLI: a generated video whose frames carry their number in binary
// blocks plays frame-accurately from the show clock (60 Hz output frames), loops, seeks, reports
// dropped frames, and bad input exits 2 with a message naming what is wrong.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "support/facet_cli.hpp"
#include "xorg_dummy.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

// facet play keeps its direction lookups under $XDG_CACHE_HOME: in a scratch folder of this
// process here, not in the user's cache.
const bool kScratchCache = [] {
  ::setenv("XDG_CACHE_HOME", test_paths::scratch_path("facet_play_cache").c_str(), 1);
  return true;
}();

constexpr int kSide = 128;  // a square dome master, shown 1:1 on builtin:dome180 at 128x128
constexpr int kBits = 8;
constexpr int kBlock = 16;

// The block of bit b: a 4 × 2 grid around the image centre (inside the fisheye circle).
cv::Point block_origin(int bit) { return {32 + (bit % 4) * kBlock, 48 + (bit / 4) * kBlock}; }

class PlayCli : public ::testing::Test {
 protected:
  // A video of `frames` frames at `fps` whose frame k shows k in binary blocks (white = 1).
  fs::path write_video(const std::string& name, int frames, double fps,
                       int fourcc = cv::VideoWriter::fourcc('M', 'J', 'P', 'G')) {
    const fs::path path = dir_ / name;
    cv::VideoWriter writer(path.string(), cv::CAP_FFMPEG, fourcc, fps, cv::Size(kSide, kSide));
    EXPECT_TRUE(writer.isOpened());
    for (int k = 0; k < frames; ++k) {
      cv::Mat frame(kSide, kSide, CV_8UC3, cv::Scalar(40, 40, 40));
      for (int b = 0; b < kBits; ++b) {
        const cv::Scalar colour = (k >> b) & 1 ? cv::Scalar(255, 255, 255) : cv::Scalar(0, 0, 0);
        cv::rectangle(frame, cv::Rect(block_origin(b), cv::Size(kBlock, kBlock)), colour,
                      cv::FILLED);
      }
      writer.write(frame);
    }
    writer.release();
    return path;
  }

  // The number an output frame shows.
  static int shown_number(const fs::path& png) {
    auto input = OIIO::ImageInput::open(png.string());
    EXPECT_TRUE(input) << png;
    if (!input) return -1;
    const OIIO::ImageSpec& spec = input->spec();
    std::vector<std::uint8_t> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
    input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data());
    int number = 0;
    for (int b = 0; b < kBits; ++b) {
      const cv::Point c = block_origin(b) + cv::Point(kBlock / 2, kBlock / 2);
      const std::uint8_t value = pixels[(std::size_t(c.y) * spec.width + c.x) * spec.nchannels];
      if (value > 128) number |= 1 << b;
    }
    return number;
  }

  static std::vector<nlohmann::json> stats(const fs::path& out) {
    std::vector<nlohmann::json> lines;
    std::ifstream file(out / "stats.jsonl");
    for (std::string line; std::getline(file, line);) lines.push_back(nlohmann::json::parse(line));
    return lines;
  }

  int play(const std::string& arguments) {
    return test::run_facet("play " + arguments + " --display builtin:dome180 --size 128x128",
                           dir_ / "log.txt");
  }
  std::string log() const { return test::slurp(dir_ / "log.txt"); }

  // The test's own folder, made for each test and removed after it.
  const test::TempFolder folder_{"facet_play_test"};
  const fs::path& dir_ = folder_.path();
};

TEST_F(PlayCli, VideoPlaysFrameAccuratelyOnTheShowClock) {
  const fs::path video = write_video("count.avi", 40, 30);
  const fs::path out = dir_ / "out";
  // 60 Hz output frames: video frame k is on screen for output frames 2k and 2k + 1; past the
  // end the last frame stays.
  ASSERT_EQ(play(video.string() + " --headless --frames 84 --out " + out.string()), 0) << log();
  const std::vector<nlohmann::json> lines = stats(out);
  ASSERT_EQ(lines.size(), 84u);
  for (int n = 0; n < 84; ++n) {
    const int expected = std::min(n / 2, 39);
    char name[16];
    std::snprintf(name, sizeof name, "%05d.png", n);
    EXPECT_EQ(shown_number(out / "dome180" / name), expected) << "output frame " << n;
    EXPECT_EQ(lines[std::size_t(n)]["source_frame"].get<int>(), expected);
    EXPECT_EQ(lines[std::size_t(n)]["dropped"].get<int>(), 0);
  }
}

TEST_F(PlayCli, LoopsAndStartsAtAFrame) {
  const fs::path video = write_video("count.avi", 40, 30);
  const fs::path out = dir_ / "out";
  ASSERT_EQ(play(video.string() + " --headless --loop --start-frame 30 --frames 40 --out " +
                 out.string()),
            0)
      << log();
  for (int n = 0; n < 40; ++n) {
    char name[16];
    std::snprintf(name, sizeof name, "%05d.png", n);
    EXPECT_EQ(shown_number(out / "dome180" / name), (30 + n / 2) % 40) << "output frame " << n;
  }
}

TEST_F(PlayCli, AFasterVideoDropsFramesAndSaysSo) {
  // 120 frames a second on a 60 Hz show clock: every other source frame is never on screen.
  const fs::path video = write_video("fast.avi", 40, 120);
  const fs::path out = dir_ / "out";
  ASSERT_EQ(play(video.string() + " --headless --out " + out.string()), 0) << log();
  const std::vector<nlohmann::json> lines = stats(out);
  ASSERT_EQ(lines.size(), 20u) << "one pass of the video by default";
  for (int n = 0; n < 20; ++n) {
    char name[16];
    std::snprintf(name, sizeof name, "%05d.png", n);
    EXPECT_EQ(shown_number(out / "dome180" / name), 2 * n) << "output frame " << n;
    EXPECT_EQ(lines[std::size_t(n)]["dropped"].get<int>(), n == 0 ? 0 : 1);
  }
  EXPECT_EQ(lines.back()["dropped_total"].get<int>(), 19);
}

TEST_F(PlayCli, BadInputExitsTwoWithAClearMessage) {
  const fs::path out = dir_ / "out";
  EXPECT_EQ(play((dir_ / "missing.mp4").string() + " --headless --out " + out.string()), 2);
  EXPECT_NE(log().find("no such file"), std::string::npos) << log();

  std::ofstream(dir_ / "text.mp4") << "not a video at all\n";
  EXPECT_EQ(play((dir_ / "text.mp4").string() + " --headless --out " + out.string()), 2);
  EXPECT_NE(log().find("video"), std::string::npos) << log();

  // A real video cut after its header: no frame can be decoded.
  const fs::path video = write_video("count.avi", 40, 30);
  const std::string bytes = test::slurp(video);
  std::ofstream(dir_ / "cut.avi", std::ios::binary) << bytes.substr(0, 600);
  EXPECT_EQ(play((dir_ / "cut.avi").string() + " --headless --out " + out.string()), 2);
  EXPECT_NE(log().find("cut.avi"), std::string::npos) << log();

  const cv::Mat wide(100, 160, CV_8UC3, cv::Scalar(10, 20, 30));
  cv::imwrite((dir_ / "wide.png").string(), wide);
  EXPECT_EQ(
      play((dir_ / "wide.png").string() + " --format fisheye --headless --out " + out.string()), 2);
  EXPECT_NE(log().find("square dome master"), std::string::npos) << log();
  EXPECT_EQ(
      play((dir_ / "wide.png").string() + " --format equirect --headless --out " + out.string()),
      2);
  EXPECT_NE(log().find("twice as wide as high"), std::string::npos) << log();
  EXPECT_EQ(play((dir_ / "wide.png").string() + " --headless --out " + out.string()), 2);
  EXPECT_NE(log().find("field '--format': a square dome master (fisheye)"), std::string::npos)
      << log();

  EXPECT_EQ(play(video.string() + " --start-frame 40 --headless --out " + out.string()), 2);
  EXPECT_NE(log().find("--start-frame"), std::string::npos) << log();
  EXPECT_FALSE(fs::exists(out)) << "nothing is written on bad input";
}

// A second start reads the direction lookups back from --direction-cache; the pictures are the
// same bytes as with the lookups computed.
TEST_F(PlayCli, DirectionCacheGivesTheSamePictures) {
  cv::Mat dome(96, 96, CV_8UC3);
  cv::randu(dome, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::imwrite((dir_ / "dome.png").string(), dome);
  const fs::path cache = dir_ / "directions";
  const std::string still = (dir_ / "dome.png").string() + " --headless";
  ASSERT_EQ(play(still + " --no-direction-cache --out " + (dir_ / "computed").string()), 0)
      << log();
  EXPECT_FALSE(fs::exists(cache));
  for (const char* run : {"first", "second"}) {
    ASSERT_EQ(
        play(still + " --direction-cache " + cache.string() + " --out " + (dir_ / run).string()), 0)
        << log();
  }
  ASSERT_EQ(std::distance(fs::directory_iterator(cache), fs::directory_iterator()), 1);
  const std::string computed = test::slurp(dir_ / "computed" / "dome180" / "00000.png");
  EXPECT_FALSE(computed.empty());
  EXPECT_EQ(test::slurp(dir_ / "first" / "dome180" / "00000.png"), computed);
  EXPECT_EQ(test::slurp(dir_ / "second" / "dome180" / "00000.png"), computed);
  EXPECT_EQ(play(still + " --no-direction-cache --direction-cache " + cache.string() + " --out " +
                 (dir_ / "both").string()),
            2);
  EXPECT_NE(log().find("--no-direction-cache"), std::string::npos) << log();
}

// --direction-cache-budget bounds the cache folder: after writing its lookup, play removes the
// least recently used files beyond the budget (here a stale 2 MiB file against 1 MiB), and the
// default budget (1 GiB) keeps them.
TEST_F(PlayCli, DirectionCacheBudgetBoundsTheFolder) {
  cv::Mat dome(96, 96, CV_8UC3, cv::Scalar(90, 120, 150));
  cv::imwrite((dir_ / "dome.png").string(), dome);
  const std::string still = (dir_ / "dome.png").string() + " --headless";
  const auto stale_cache = [&](const std::string& name) {
    const fs::path cache = dir_ / name;
    fs::create_directories(cache);
    const fs::path stale = cache / "0123456789abcdef.dirs";
    std::ofstream(stale, std::ios::binary) << std::string(2 << 20, '\0');
    fs::last_write_time(stale, fs::file_time_type::clock::now() - std::chrono::hours(24));
    return stale;
  };
  const fs::path kept = stale_cache("default");
  ASSERT_EQ(play(still + " --direction-cache " + kept.parent_path().string() + " --out " +
                 (dir_ / "a").string()),
            0)
      << log();
  EXPECT_TRUE(fs::exists(kept));
  EXPECT_EQ(std::distance(fs::directory_iterator(kept.parent_path()), fs::directory_iterator()), 2);

  const fs::path trimmed = stale_cache("small");
  ASSERT_EQ(play(still + " --direction-cache " + trimmed.parent_path().string() +
                 " --direction-cache-budget 1 --out " + (dir_ / "b").string()),
            0)
      << log();
  EXPECT_FALSE(fs::exists(trimmed));
  EXPECT_EQ(std::distance(fs::directory_iterator(trimmed.parent_path()), fs::directory_iterator()),
            1);

  // Bad budgets exit 2 naming the flag, before any work.
  for (const char* bad : {"0", "-1", "1048577", "lots"}) {
    EXPECT_EQ(play(still + " --direction-cache-budget " + bad + " --out " + (dir_ / "c").string()),
              2)
        << bad;
    EXPECT_NE(log().find("--direction-cache-budget"), std::string::npos) << log();
    EXPECT_FALSE(fs::exists(dir_ / "c"));
  }
  EXPECT_EQ(play(still + " --no-direction-cache --direction-cache-budget 64 --out " +
                 (dir_ / "c").string()),
            2);
  EXPECT_NE(log().find("field '--direction-cache-budget'"), std::string::npos) << log();
}

TEST_F(PlayCli, StillEquirectOnACylinder) {
  // A 2:1 panorama, white above the horizon and black below: the cylinder's top half is lit.
  cv::Mat panorama(64, 128, CV_8UC3, cv::Scalar(0, 0, 0));
  panorama(cv::Rect(0, 0, 128, 32)).setTo(cv::Scalar(255, 255, 255));
  cv::imwrite((dir_ / "sky.png").string(), panorama);
  const fs::path out = dir_ / "out";
  ASSERT_EQ(test::run_facet("play " + (dir_ / "sky.png").string() +
                                " --display builtin:cylinder360 --size 160x120 --headless --out " +
                                out.string(),
                            dir_ / "log.txt"),
            0)
      << log();
  auto input = OIIO::ImageInput::open((out / "cylinder360" / "00000.png").string());
  ASSERT_TRUE(input);
  std::vector<std::uint8_t> pixels(160 * 120 * 4);
  input->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, pixels.data());
  EXPECT_GT(pixels[(std::size_t(20) * 160 + 80) * 4], 250);  // above the horizon
  EXPECT_LT(pixels[(std::size_t(100) * 160 + 80) * 4], 5);   // below
}

TEST_F(PlayCli, BlendsLikeASession) {
  // White everywhere on the 2 × 2 wall: the top-left projector is full white at its top-left
  // corner and blended down to a weight of about 0.02 at its right edge, inside the overlap.
  const cv::Mat white(64, 128, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::imwrite((dir_ / "white.png").string(), white);
  const fs::path out = dir_ / "out";
  ASSERT_EQ(test::run_facet("play " + (dir_ / "white.png").string() +
                                " --display builtin:wall2x2 --size 160x100 --headless --out " +
                                out.string(),
                            dir_ / "log.txt"),
            0)
      << log();
  auto input = OIIO::ImageInput::open((out / "wall_r0c0" / "00000.png").string());
  ASSERT_TRUE(input);
  std::vector<std::uint8_t> pixels(160 * 100 * 4);
  input->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, pixels.data());
  EXPECT_GT(pixels[(std::size_t(5) * 160 + 5) * 4], 250);
  EXPECT_LT(pixels[(std::size_t(5) * 160 + 157) * 4], 60);
  const std::vector<nlohmann::json> lines = stats(out);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_GT(lines[0]["blend_tiles"][0].get<int>(), 0);
}

// A cluster of dome4 over ipc:// sockets (node a: p0 and p1, the master; b: p2 and p3): every
// node shows the video frame the master's show clock says, and its images are the one-process
// run's, byte for byte.
TEST_F(PlayCli, ClusterNodesShowTheSameVideoFrame) {
  const fs::path video = write_video("count.avi", 40, 30);
  const fs::path source = fs::path(FACET_SOURCE_DIR) / "configs/displays/dome4";
  const fs::path folder = dir_ / "dome4";
  fs::create_directories(folder);
  for (const auto& entry : fs::directory_iterator(source))
    if (entry.path().extension() == ".exr")
      fs::copy_file(entry.path(), folder / entry.path().filename());
  nlohmann::json display = nlohmann::json::parse(test::slurp(source / "display.json"));
  auto address = [&](const char* node) { return "ipc://" + (dir_ / node).string() + ".sock"; };
  display["cluster"] = {
      {"nodes",
       {{{"name", "a"}, {"address", address("a")}, {"projectors", {"p0", "p1"}}},
        {{"name", "b"}, {"address", address("b")}, {"projectors", {"p2", "p3"}}}}},
      {"master", "a"},
      {"deadline_ms", 5000}};
  std::ofstream(folder / "display.json") << display.dump(2);
  const std::string common = "play " + video.string() + " --display " +
                             (folder / "display.json").string() + " --headless --scale 0.125";
  ASSERT_EQ(
      test::run_facet(common + " --frames 12 --out " + (dir_ / "one").string(), dir_ / "one.log"),
      0)
      << test::slurp(dir_ / "one.log");
  auto node_arguments = [&](const std::string& node, std::vector<std::string> extra) {
    std::vector<std::string> arguments = {"play",
                                          video.string(),
                                          "--display",
                                          (folder / "display.json").string(),
                                          "--headless",
                                          "--scale",
                                          "0.125",
                                          "--node",
                                          node,
                                          "--out",
                                          (dir_ / node).string()};
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    return arguments;
  };
  const std::vector<std::string> b_arguments = node_arguments("b", {});
  const std::vector<std::string> a_arguments = node_arguments("a", {"--frames", "12"});
  const pid_t b = test::start_facet(b_arguments, dir_ / "b.log");
  const pid_t a = test::start_facet(a_arguments, dir_ / "a.log");
  auto finish = [](pid_t pid) {
    int status = 0;
    if (!test::wait_until([&] { return ::waitpid(pid, &status, WNOHANG) == pid; },
                          std::chrono::seconds(120))) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -2;
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(finish(a), 0) << test::slurp(dir_ / "a.log");
  EXPECT_EQ(finish(b), 0) << test::slurp(dir_ / "b.log");

  const std::vector<nlohmann::json> one = stats(dir_ / "one");
  ASSERT_EQ(one.size(), 12u);
  for (const char* node : {"a", "b"}) {
    const std::vector<nlohmann::json> lines = stats(dir_ / node);
    ASSERT_EQ(lines.size(), 12u) << node;
    for (std::size_t n = 0; n < lines.size(); ++n) {
      EXPECT_EQ(lines[n]["source_frame"], one[n]["source_frame"]) << node << " frame " << n;
      EXPECT_EQ(lines[n]["cluster"]["swapped"], true) << node << " frame " << n;
    }
  }
  const std::map<std::string, std::string> node_of = {
      {"p0", "a"}, {"p1", "a"}, {"p2", "b"}, {"p3", "b"}};
  for (const auto& [projector, node] : node_of) {
    for (int n = 0; n < 12; ++n) {
      char name[16];
      std::snprintf(name, sizeof name, "%05d.png", n);
      const std::string expected = test::slurp(dir_ / "one" / projector / name);
      ASSERT_FALSE(expected.empty()) << projector << "/" << name;
      EXPECT_TRUE(test::slurp(dir_ / node / projector / name) == expected)
          << projector << "/" << name << " differs";
    }
  }
}

// Windows on an X server (Xorg's dummy driver): the same video in a window for 12 frames on the
// wall clock. Leak checking is off as for facet run's windowed tests (Mesa's GLX driver is
// unloaded before LeakSanitizer runs).
TEST_F(PlayCli, PlaysInAWindowOnAnXServer) {
  test::XorgDummyServer server;
  const std::string display = ":" + std::to_string(230 + ::getpid() % 20);
  const std::string reason = server.start(dir_, display, 1024, 768, 32000);
  if (!reason.empty()) GTEST_SKIP() << reason;
  const fs::path video = write_video("count.avi", 40, 30);
  const int status = test::run_shell("ASAN_OPTIONS=detect_leaks=0 DISPLAY=" + display + " " +
                                     FACET_CLI + " play " + video.string() +
                                     " --display builtin:dome180 --size 128x128 --windowed "
                                     "--frames 12 --stats " +
                                     (dir_ / "stats.jsonl").string() + " > " +
                                     (dir_ / "log.txt").string() + " 2>&1");
  server.stop();
  EXPECT_EQ(status, 0) << log();
  EXPECT_NE(log().find("first frame after"), std::string::npos) << log();
  EXPECT_NE(log().find("12 frames shown"), std::string::npos) << log();
  // The wall clock: frames in order, each no earlier than the one before.
  const std::vector<nlohmann::json> lines = stats(dir_);
  ASSERT_EQ(lines.size(), 12u);
  for (std::size_t n = 1; n < lines.size(); ++n)
    EXPECT_GE(lines[n]["source_frame"].get<int>(), lines[n - 1]["source_frame"].get<int>());
}

// A video coded with predicted frames (MPEG-4 part 2, a key frame every 12): a start frame
// between key frames is still the exact frame.
TEST_F(PlayCli, SeeksExactlyInAVideoWithPredictedFrames) {
  const fs::path video =
      write_video("count.mp4", 40, 30, cv::VideoWriter::fourcc('m', 'p', '4', 'v'));
  const fs::path out = dir_ / "out";
  ASSERT_EQ(play(video.string() + " --headless --start-frame 17 --frames 10 --loop --out " +
                 out.string()),
            0)
      << log();
  for (int n = 0; n < 10; ++n) {
    char name[16];
    std::snprintf(name, sizeof name, "%05d.png", n);
    EXPECT_EQ(shown_number(out / "dome180" / name), 17 + n / 2) << "output frame " << n;
  }
}

}  // namespace
}  // namespace facet
