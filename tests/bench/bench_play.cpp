// Playback timing for the README: decode ms per 4K video frame (OpenCV's VideoCapture, FFmpeg)
// and the upload and resample ms of facet play's pass on this machine's GL.
//
//   bench_play [FRAMES] [FOLDER]
//
// Writes two H.264 videos of FRAMES frames (default 24) under FOLDER (default a temporary
// folder, removed afterwards): a 4096×4096 dome master and a 3840×1920 panorama, each frame a
// moving pattern with fine detail; then decodes every frame in order and shows them on dome4
// (four 1024×768 projectors with their blends) headless. Prints the median per frame, and how
// long the first frame took, started as facet play starts (the direction lookups on a thread of
// their own while FFmpeg opens the file): the dome master computes the lookups (the warp inverse
// at every output pixel) into FOLDER/directions, the panorama reads them back from there.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <future>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <thread>
#include <vector>

#include "facet/driver/content_player.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/projection/statistics.hpp"

namespace fs = std::filesystem;
using namespace facet;

namespace {

// Frame k: rings and spokes that move, over a texture of fine lines, so the encoder has work.
cv::Mat pattern_frame(cv::Size size, int k) {
  cv::Mat frame(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y) {
    auto* row = frame.ptr<cv::Vec3b>(y);
    for (int x = 0; x < size.width; ++x) {
      const double u = double(x) / size.width, v = double(y) / size.height;
      const double wave = std::sin(40 * u + 0.3 * k) * std::cos(30 * v - 0.2 * k);
      row[x] = cv::Vec3b(std::uint8_t(128 + 100 * wave), std::uint8_t((x * 7 + y * 3 + k) & 255),
                         std::uint8_t(((x ^ y) + 4 * k) & 255));
    }
  }
  cv::circle(frame, {size.width / 2, size.height / 2}, (k * 37) % (size.height / 2),
             cv::Scalar(255, 255, 255), 24);
  return frame;
}

fs::path write_video(const fs::path& folder, const std::string& name, cv::Size size, int frames) {
  const fs::path path = folder / name;
  cv::VideoWriter writer(path.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('a', 'v', 'c', '1'),
                         30, size);
  if (!writer.isOpened()) {
    std::fprintf(stderr, "bench_play: no H.264 encoder; using MPEG-4 part 2\n");
    writer.open(path.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 30,
                size);
  }
  for (int k = 0; k < frames; ++k) writer.write(pattern_frame(size, k));
  return path;
}

void measure(const fs::path& video, ContentProjection projection, int frames,
             const fs::path& direction_cache) {
  // Decoding alone, every frame in order.
  std::vector<double> decode_ms;
  double first_frame_ms = 0;
  double decode_cpu_ms = 0;  // the process's CPU time per frame, every thread's
  {
    auto media = driver::ContentMedia::open(video);
    const std::clock_t cpu_start = std::clock();
    for (int k = 1; k < frames; ++k) decode_ms.push_back(media->frame(k).decode_ms);
    decode_cpu_ms = 1000.0 * double(std::clock() - cpu_start) / CLOCKS_PER_SEC / (frames - 1);
  }
  // The player: decode, upload with mip levels, resample and blend every output.
  driver::SessionDisplay display = driver::load_session_display(
      std::string(FACET_SOURCE_DIR) + "/configs/displays/dome4/display.json");
  driver::PlaybackOptions options;
  options.projection = projection;
  options.resample.direction_cache = direction_cache;
  // As facet play starts: the direction lookups on a thread of their own while FFmpeg opens the
  // file.
  const auto start = std::chrono::steady_clock::now();
  driver::PendingLookups lookups = driver::start_content_lookups(display, options.resample);
  std::unique_ptr<driver::ContentMedia> media = driver::ContentMedia::open(video);
  driver::ContentPlayer player(display, std::move(media), options, std::move(lookups));
  const double prepare_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::vector<double> upload_ms, resample_ms, frame_cpu_ms;
  for (int k = 0; k < frames; ++k) {
    driver::FrameState state;
    state.frame = std::uint64_t(k);
    state.time_s = k / 30.0;
    const std::clock_t cpu_start = std::clock();
    const driver::PlayFrameStats stats = player.render(state, true);
    const double cpu_ms = 1000.0 * double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    if (k == 0) {
      // Opening, the direction lookups of every output, shaders, the first frame on screen.
      first_frame_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      continue;
    }
    upload_ms.push_back(stats.upload_ms);
    // The frame's CPU time: decoding, upload, mip levels, resample and blend on llvmpipe's
    // threads (a GPU's work would not be in it).
    frame_cpu_ms.push_back(cpu_ms);
    resample_ms.push_back(stats.resample_ms);
  }
  const glm::ivec2 size = player.media().size();
  std::printf(
      "%s %dx%d: decode %.1f ms/frame (%.1f CPU ms), upload+mips %.1f ms, "
      "resample+blend of dome4 (4 x 1024x768) %.1f ms, a whole frame %.1f CPU ms "
      "(medians of %d frames); first frame %.0f ms after opening (%.0f ms preparing, "
      "%zu of %zu direction lookups from the cache)\n",
      video.filename().c_str(), size.x, size.y, median(decode_ms), decode_cpu_ms, median(upload_ms),
      median(resample_ms), median(frame_cpu_ms), frames - 1, first_frame_ms, prepare_ms,
      player.pass().lookups_from_cache(), player.pass().output_count());
}

}  // namespace

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::max(2, std::atoi(argv[1])) : 24;
  const bool own_folder = argc <= 2;
  const fs::path folder =
      own_folder ? fs::temp_directory_path() / ("bench_play_" + std::to_string(::getpid()))
                 : fs::path(argv[2]);
  fs::create_directories(folder);
  auto context = driver::create_headless_context();
  std::printf("bench_play: %s, %u hardware threads\n", context->info().renderer.c_str(),
              std::max(1u, std::thread::hardware_concurrency()));
  const fs::path dome = write_video(folder, "dome4096.mp4", {4096, 4096}, frames);
  const fs::path panorama = write_video(folder, "equirect3840.mp4", {3840, 1920}, frames);
  // The dome master computes dome4's direction lookups and keeps them in the folder; the
  // panorama, on the same display, reads them back, as a second start of facet play would.
  const fs::path cache = folder / "directions";
  fs::remove_all(cache);
  measure(dome, fisheye_content(), frames, cache);
  measure(panorama, equirect_content(), frames, cache);
  if (own_folder) fs::remove_all(folder);
  return 0;
}
