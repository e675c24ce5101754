// Mode 2 (content through the exact warp) on llvmpipe, against the warp's exact forward map:
//  - a coordinate texture (each texel holds the content coordinates of its centre, float) read
//    back from a float target, turned into a direction by the content's map and projected by
//    the warp, lands on the pixel it was drawn at: worst and RMS distance in output pixels;
//  - a generated 8-bit dome master with dots on a known angular grid: each dot's centroid in the
//    output against the warp's projection of the dot's direction, in output pixels.
#include "facet/driver/content_pass.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <stop_token>
#include <vector>

#include "facet/driver/direction_cache.hpp"
#include "facet/driver/session.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "gl_test_context.hpp"

namespace facet::driver {
namespace {

constexpr double kPi = std::numbers::pi;

// dome4 (a real four-projector dome with measured warps), at a quarter of its size.
std::vector<OutputSpec> dome4_outputs() {
  SessionDisplay display =
      load_session_display(std::string(FACET_SOURCE_DIR) + "/configs/displays/dome4/display.json");
  scale_session_display(display, 0.25);
  std::vector<OutputSpec> outputs;
  for (const SessionOutput& output : display.outputs) outputs.push_back(output.spec);
  return outputs;
}

// RGBA32F texels holding (s, t) of their centres, or, for a cube strip, the point of the cube's
// surface a_m + (2s−1)·a_s + (2t−1)·a_t (bilinear in st, so filtering keeps it exact).
ContentImage coordinate_image(ContentFormat format, glm::ivec2 size) {
  ContentImage image;
  image.size = size;
  image.channels = 4;
  image.pixels = ContentImage::Pixels::linear_f32;
  image.values.resize(std::size_t(size.x) * size.y * 4);
  const int face = size.y;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      float* texel = &image.values[(std::size_t(y) * size.x + x) * 4];
      if (format == ContentFormat::cubemap) {
        const CubeFaceAxes& axes = kCubeFaces[std::size_t(x / face)];
        const double s = ((x % face) + 0.5) / face, t = (y + 0.5) / face;
        const glm::dvec3 p = axes.a_m + (2 * s - 1) * axes.a_s + (2 * t - 1) * axes.a_t;
        texel[0] = float(p.x), texel[1] = float(p.y), texel[2] = float(p.z), texel[3] = 1;
      } else {
        texel[0] = float((x + 0.5) / size.x), texel[1] = float((y + 0.5) / size.y);
        texel[2] = 0, texel[3] = 1;
      }
    }
  }
  return image;
}

struct ErrorStats {
  double worst_px = 0, rms_px = 0;
  std::size_t pixels = 0;
};

// Draws every output into an RGBA32F target and measures where each pixel's sample says it is.
// Pixels whose exact content point (through the warp inverse) lies within `border` texels of the
// image's edge (where filtering clamps), of a cube face's edge or of an equirect seam (where the
// coordinates jump) are skipped: the filter's reach, which grows with the mip level.
ErrorStats measure(const std::vector<OutputSpec>& outputs, const ContentProjection& projection,
                   glm::ivec2 image_size, const ResampleOptions& options, double border = 3.0) {
  test::shared_context();
  ContentPass pass(outputs, options);
  ContentTexture texture(projection.format, image_size, ContentImage::Pixels::linear_f32, "test",
                         true);
  texture.upload(coordinate_image(projection.format, image_size));
  double sum_sq = 0;
  ErrorStats stats;
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    const glm::ivec2 size = outputs[o].warp.output_size;
    const WarpInverse inverse(outputs[o].warp);
    Texture target = Texture::create_2d(GL_RGBA32F, size.x, size.y);
    Framebuffer framebuffer = Framebuffer::create();
    framebuffer.attach(GL_COLOR_ATTACHMENT0, target);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    const float clear[4] = {-1, -1, -1, 0};
    glClearNamedFramebufferfv(framebuffer.id(), GL_COLOR, 0, clear);
    pass.draw(o, texture, projection);
    std::vector<float> pixels(std::size_t(size.x) * size.y * 4);
    glReadPixels(0, 0, size.x, size.y, GL_RGBA, GL_FLOAT, pixels.data());
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    for (int gy = 0; gy < size.y; ++gy) {
      for (int x = 0; x < size.x; ++x) {
        const float* p = &pixels[(std::size_t(gy) * size.x + x) * 4];
        if (p[0] == -1.0f || p[3] == 0.0f) continue;  // not covered
        const glm::dvec2 q_pixel(x + 0.5, size.y - gy - 0.5);
        // Where the pixel's sample should come from: skip it near the image's edges and seam.
        const auto inverted = inverse.invert(q_pixel);
        if (!inverted) continue;
        const auto expected = projection.point_from_v_eye(inverted->v_eye);
        if (!expected) continue;
        const glm::dvec2 edge_texels =
            glm::min(expected->st, 1.0 - expected->st) *
            (projection.format == ContentFormat::cubemap ? glm::dvec2(image_size.y)
                                                         : glm::dvec2(image_size));
        if (std::min(edge_texels.x, edge_texels.y) < border) continue;
        if (projection.format == ContentFormat::fisheye &&
            glm::length(expected->st - glm::dvec2(0.5)) * image_size.x > image_size.x / 2 - border)
          continue;
        ContentPoint point;
        if (projection.format == ContentFormat::cubemap) {
          const glm::dvec3 surface(p[0], p[1], p[2]);
          point = *projection.point_from_v_eye(projection.R_eye_content * surface);
        } else {
          point.st = glm::dvec2(p[0], p[1]);
        }
        const glm::dvec3 v = projection.v_eye_from_point(point);
        const auto projected = outputs[o].warp.project(v);
        EXPECT_TRUE(projected);
        if (!projected) continue;
        const double error = glm::length(projected->q - q_pixel);
        stats.worst_px = std::max(stats.worst_px, error);
        sum_sq += error * error;
        ++stats.pixels;
      }
    }
  }
  stats.rms_px = stats.pixels ? std::sqrt(sum_sq / double(stats.pixels)) : 0;
  return stats;
}

void expect_mode2_accuracy(const ErrorStats& stats, const char* what) {
  EXPECT_GT(stats.pixels, 10000u) << what;
  EXPECT_LE(stats.worst_px, 0.5) << what << ": worst, output pixels";
  EXPECT_LE(stats.rms_px, 0.1) << what << ": RMS, output pixels";
  std::printf("%s: %zu pixels, worst %.4f px, RMS %.4f px\n", what, stats.pixels, stats.worst_px,
              stats.rms_px);
}

TEST(ContentPass, FisheyeThroughDome4MatchesTheExactWarp) {
  const std::vector<OutputSpec> outputs = dome4_outputs();
  const ContentProjection master = fisheye_content(220, DomeOrientation{10, 30});
  // Coarser than the outputs (bicubic) and finer (mip levels, anisotropic).
  expect_mode2_accuracy(measure(outputs, master, {200, 200}, {}), "fisheye 200² (magnified)");
  expect_mode2_accuracy(measure(outputs, master, {2048, 2048}, {}), "fisheye 2048² (minified)");
}

TEST(ContentPass, EquirectAndCubeMapThroughACylinderMatchTheExactWarp) {
  const OutputSpec cylinder{
      "cylinder",
      Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {400, 200}, {9, 5})};
  const std::vector<OutputSpec> outputs{cylinder};
  const ContentProjection panorama = equirect_content(DomeOrientation{15, 0});
  expect_mode2_accuracy(measure(outputs, panorama, {512, 256}, {}), "equirect 512×256");
  // About 5 texels an output pixel across: the mip levels and taps reach some 16 texels.
  expect_mode2_accuracy(measure(outputs, panorama, {2048, 1024}, {}, 24.0), "equirect 2048×1024");
  const ContentProjection cube = cubemap_content(DomeOrientation{0, 20});
  expect_mode2_accuracy(measure(outputs, cube, {6 * 256, 256}, {}), "cube map 256² faces");
}

TEST(ContentPass, PerspectiveContentInTheProjectorsFrustum) {
  const std::vector<OutputSpec> outputs = dome4_outputs();
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    const Frustum frustum = covering_frustum(outputs[o].warp, outputs[o].name);
    const std::vector<OutputSpec> one{outputs[o]};
    const ErrorStats stats = measure(one, frustum.content(), {512, 512}, {});
    EXPECT_GT(stats.pixels, 5000u);
    EXPECT_LE(stats.worst_px, 0.5) << outputs[o].name;
    EXPECT_LE(stats.rms_px, 0.1) << outputs[o].name;
  }
}

double srgb_decode(double e) {
  return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
}

TEST(ContentPass, DomeMasterDotsLandWhereTheWarpSays) {
  test::shared_context();
  const std::vector<OutputSpec> outputs = dome4_outputs();
  // A 1024² 180° dome master with Gaussian dots (σ = 5 texels, linear light) every 30° of
  // azimuth on the circles 15°, 35° and 55° above the spring line, every 90° on the 75° one.
  const int n = 1024;
  const double sigma = 5;
  const ContentProjection master = fisheye_content();
  std::vector<glm::dvec3> dots;
  for (double elevation : {15.0, 35.0, 55.0, 75.0})
    for (double azimuth = 0; azimuth < 360; azimuth += elevation < 70 ? 30 : 90) {
      const double e = elevation * kPi / 180, a = azimuth * kPi / 180;
      dots.emplace_back(std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a));
    }
  std::vector<double> linear(std::size_t(n) * n, 0.0);
  for (const glm::dvec3& dot : dots) {
    const glm::dvec2 c = master.point_from_v_eye(dot)->st * double(n);
    for (int y = int(c.y) - 20; y <= int(c.y) + 20; ++y)
      for (int x = int(c.x) - 20; x <= int(c.x) + 20; ++x) {
        const double d2 = (x + 0.5 - c.x) * (x + 0.5 - c.x) + (y + 0.5 - c.y) * (y + 0.5 - c.y);
        linear[std::size_t(y) * n + x] += std::exp(-d2 / (2 * sigma * sigma));
      }
  }
  ContentImage image;
  image.size = {n, n};
  image.channels = 1;
  image.bytes.resize(linear.size());
  for (std::size_t i = 0; i < linear.size(); ++i) {
    const double l = std::min(1.0, linear[i]);
    const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055;
    image.bytes[i] = std::uint8_t(std::lround(e * 255));
  }
  ContentPass pass(outputs);
  ContentTexture texture(ContentFormat::fisheye, image.size, image.pixels, "dots");
  texture.upload(image);

  int found = 0;
  double worst_px = 0;
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    const Warp& warp = outputs[o].warp;
    OutputTarget target = OutputTarget::create(warp.output_size);
    target.clear(glm::vec4(0, 0, 0, 0));  // alpha 0 marks pixels the warp does not cover
    target.bind();
    pass.draw(o, texture, master);
    const std::vector<std::uint8_t> rgba = target.read_colour_rgba8();
    const glm::ivec2 size = warp.output_size;
    for (const glm::dvec3& dot : dots) {
      const auto projected = warp.project(dot);
      if (!projected || !projected->covered) continue;
      const glm::dvec2 q = projected->q;
      const int r = 9;  // window half-size in output pixels
      if (q.x < r + 1 || q.y < r + 1 || q.x > size.x - r - 1 || q.y > size.y - r - 1) continue;
      glm::dvec2 moment(0.0);
      double mass = 0;
      bool whole = true;
      for (int y = int(q.y) - r; y <= int(q.y) + r; ++y)
        for (int x = int(q.x) - r; x <= int(q.x) + r; ++x) {
          whole = whole && rgba[(std::size_t(y) * size.x + x) * 4 + 3] != 0;
          const double l = srgb_decode(rgba[(std::size_t(y) * size.x + x) * 4] / 255.0);
          moment += l * glm::dvec2(x + 0.5, y + 0.5);
          mass += l;
        }
      if (!whole) continue;  // the coverage's edge cuts the window
      ASSERT_GT(mass, 1.0) << outputs[o].name << ": no dot near " << q.x << ", " << q.y;
      const double error = glm::length(moment / mass - q);
      EXPECT_LE(error, 0.5) << outputs[o].name << ": dot at " << q.x << ", " << q.y;
      worst_px = std::max(worst_px, error);
      ++found;
    }
  }
  EXPECT_GE(found, 24);
  std::printf("dome master dots: %d measured, worst centroid error %.3f px\n", found, worst_px);
}

// The direction cache hands back exactly what the inverse computes, rereads it on the next call,
// and ignores a file that does not match (a damaged payload, another warp).
TEST(DirectionCache, ReadsBackTheComputedLookupAndIgnoresADamagedFile) {
  const std::filesystem::path folder = test_paths::scratch_path("facet_direction_cache");
  std::filesystem::remove_all(folder);
  const Warp warp = dome4_outputs().at(1).warp;
  const std::vector<glm::vec3> computed = WarpInverse(warp).v_eye_at_pixel_centres();
  auto same_bits = [&](const std::vector<glm::vec3>& v) {
    return v.size() == computed.size() &&
           std::memcmp(v.data(), computed.data(), v.size() * sizeof(glm::vec3)) == 0;
  };

  const DirectionLookup first = direction_lookup(warp, folder);
  EXPECT_FALSE(first.from_cache);
  EXPECT_TRUE(same_bits(first.v_eye));
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) files.push_back(entry);
  ASSERT_EQ(files.size(), 1u);  // the file alone: no temporary left behind

  const DirectionLookup second = direction_lookup(warp, folder);
  EXPECT_TRUE(second.from_cache);
  EXPECT_TRUE(same_bits(second.v_eye));

  // One payload byte changed: not trusted, computed again and rewritten.
  {
    std::fstream file(files[0], std::ios::in | std::ios::out | std::ios::binary);
    file.seekg(-5, std::ios::end);
    const char byte = char(file.get() ^ 0x55);
    file.seekp(-5, std::ios::end);
    file.put(byte);
  }
  const DirectionLookup damaged = direction_lookup(warp, folder);
  EXPECT_FALSE(damaged.from_cache);
  EXPECT_TRUE(same_bits(damaged.v_eye));
  EXPECT_TRUE(direction_lookup(warp, folder).from_cache);

  // Another warp (one node moved by a thousandth of a pixel) has a file of its own.
  Warp moved = warp;
  moved.offset_px[moved.offset_px.size() / 2].x += 1e-3f;
  EXPECT_NE(direction_cache_key(moved), direction_cache_key(warp));
  EXPECT_FALSE(direction_lookup(moved, folder).from_cache);
  // No folder: computed, nothing written.
  EXPECT_FALSE(direction_lookup(warp, {}).from_cache);
  std::filesystem::remove_all(folder);
}

namespace fs = std::filesystem;

void write_bytes(const fs::path& path, std::size_t size) {
  std::ofstream(path, std::ios::binary) << std::string(size, 'x');
}

void set_age(const fs::path& path, int seconds_ago) {
  fs::last_write_time(path, fs::file_time_type::clock::now() - std::chrono::seconds(seconds_ago));
}

// The folder is trimmed to its budget by removing the least recently modified cache files, and
// nothing that is not one: other names, other kinds of entries and links are neither counted nor
// removed.
// Asked to stop, the lookups return nothing and cache nothing: an incomplete inverse never
// reaches a texture or the cache folder (facet play stops them when the content cannot play).
TEST(DirectionCache, AStoppedLookupReturnsNothingAndWritesNoFile) {
  const std::filesystem::path folder = test_paths::scratch_path("facet_direction_cache_stop");
  std::filesystem::remove_all(folder);
  const std::vector<OutputSpec> outputs = dome4_outputs();
  const Warp& warp = outputs.at(1).warp;
  std::stop_source stop;
  stop.request_stop();

  const std::vector<glm::vec3> inverse =
      WarpInverse(warp).v_eye_at_pixel_centres(0, stop.get_token());
  ASSERT_EQ(inverse.size(), std::size_t(warp.output_size.x) * warp.output_size.y);
  std::size_t solved = 0;
  for (const glm::vec3& v : inverse) solved += std::isnan(v.x) ? 0 : 1;
  EXPECT_EQ(solved, 0u) << "rows were solved after the stop";

  const DirectionLookup stopped =
      direction_lookup(warp, folder, kDefaultDirectionCacheBudget, stop.get_token());
  EXPECT_TRUE(stopped.stopped);
  EXPECT_TRUE(stopped.v_eye.empty());
  EXPECT_FALSE(std::filesystem::exists(folder)) << "a stopped lookup wrote into the cache";

  ResampleOptions options;
  options.direction_cache = folder;
  const ContentLookups none = prepare_content_lookups(outputs, options, stop.get_token());
  EXPECT_TRUE(none.stopped);
  EXPECT_TRUE(none.sizes.empty() && none.texels.empty());
  EXPECT_FALSE(std::filesystem::exists(folder));

  // Not stopped: every output, each written to the cache.
  const ContentLookups all =
      prepare_content_lookups(outputs, options, std::stop_source().get_token());
  EXPECT_FALSE(all.stopped);
  EXPECT_EQ(all.sizes.size(), outputs.size());
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(folder),
                          std::filesystem::directory_iterator()),
            std::ptrdiff_t(outputs.size()));
  std::filesystem::remove_all(folder);
}

TEST(DirectionCache, TrimRemovesTheOldestCacheFilesBeyondTheBudgetAndNothingElse) {
  const fs::path folder = test_paths::scratch_path("facet_direction_cache_trim");
  fs::remove_all(folder);
  fs::create_directories(folder / "0000000000000000.dirs");  // a folder named like a file
  write_bytes(folder / "0000000000000000.dirs" / "inner", 10);
  const std::vector<std::string> cache = {"00000000000000a1.dirs", "00000000000000a2.dirs",
                                          "00000000000000a3.dirs", "00000000000000a4.dirs",
                                          "00000000000000a5.dirs"};
  for (std::size_t k = 0; k < cache.size(); ++k) {
    write_bytes(folder / cache[k], 1000);
    set_age(folder / cache[k], 100 - 10 * int(k));  // a5 the newest
  }
  const std::vector<std::string> others = {"notes.txt",
                                           "00000000000000A1.dirs",
                                           "00000000000000a1.dirs.bak",
                                           "0000000000000a1.dirs",
                                           ".00000000000000a6.tmp42-0.dirs",
                                           "00000000000000a7.dir"};
  for (const std::string& name : others) {
    write_bytes(folder / name, 5000);
    set_age(folder / name, 1000);
  }
  write_bytes(folder.parent_path() / "facet_direction_cache_trim_target", 5000);
  fs::create_symlink(folder.parent_path() / "facet_direction_cache_trim_target",
                     folder / "00000000000000b1.dirs");

  // 2500 bytes: the two newest cache files (2000 bytes) stay, the third would exceed it.
  EXPECT_EQ(trim_direction_cache(folder, 2500), 3u);
  for (std::size_t k = 0; k < cache.size(); ++k)
    EXPECT_EQ(fs::exists(folder / cache[k]), k >= 3) << cache[k];
  for (const std::string& name : others) EXPECT_TRUE(fs::exists(folder / name)) << name;
  EXPECT_TRUE(fs::exists(folder / "0000000000000000.dirs" / "inner"));
  EXPECT_TRUE(fs::is_symlink(folder / "00000000000000b1.dirs"));
  EXPECT_TRUE(fs::exists(folder.parent_path() / "facet_direction_cache_trim_target"));

  // The kept file stays whatever its age, and counts first.
  EXPECT_EQ(trim_direction_cache(folder, 1500, folder / cache[3]), 1u);
  EXPECT_TRUE(fs::exists(folder / cache[3]));
  EXPECT_FALSE(fs::exists(folder / cache[4]));
  // A missing folder: nothing to do.
  EXPECT_EQ(trim_direction_cache(folder / "missing", 0), 0u);
  fs::remove_all(folder);
  fs::remove(folder.parent_path() / "facet_direction_cache_trim_target");
}

// Through direction_lookup: writing a lookup trims the folder; reading one marks it used, so the
// lookup read last outlives one written earlier; and a reader that has the file open when it is
// removed still reads every byte of it.
TEST(DirectionCache, WritingTrimsToTheBudgetAndReadingCountsAsUse) {
  const fs::path folder = test_paths::scratch_path("facet_direction_cache_budget");
  fs::remove_all(folder);
  const std::vector<OutputSpec> outputs = dome4_outputs();
  const Warp& a = outputs.at(0).warp;
  const Warp& b = outputs.at(1).warp;
  const Warp& c = outputs.at(2).warp;
  const fs::path file_a = folder / direction_cache_file_name(direction_cache_key(a));
  const fs::path file_b = folder / direction_cache_file_name(direction_cache_key(b));
  const fs::path file_c = folder / direction_cache_file_name(direction_cache_key(c));
  const std::uint64_t unlimited = std::uint64_t(1) << 40;

  EXPECT_FALSE(direction_lookup(a, folder, unlimited).from_cache);
  EXPECT_FALSE(direction_lookup(b, folder, unlimited).from_cache);
  const std::uintmax_t file_size = fs::file_size(file_a);
  ASSERT_EQ(fs::file_size(file_b), file_size);  // outputs of one size
  // a written first, then b; reading a makes it the most recently used.
  set_age(file_a, 200);
  set_age(file_b, 100);
  const DirectionLookup reread = direction_lookup(a, folder, unlimited);
  EXPECT_TRUE(reread.from_cache);
  EXPECT_GT(fs::last_write_time(file_a), fs::last_write_time(file_b));

  // A reader holding b open while c's write removes it (room for two files: c and a).
  std::ifstream reader(file_b, std::ios::binary);
  ASSERT_TRUE(reader.is_open());
  EXPECT_FALSE(direction_lookup(c, folder, 2 * file_size).from_cache);
  EXPECT_TRUE(fs::exists(file_c));
  EXPECT_TRUE(fs::exists(file_a));
  EXPECT_FALSE(fs::exists(file_b));
  std::string bytes((std::istreambuf_iterator<char>(reader)), std::istreambuf_iterator<char>());
  EXPECT_EQ(bytes.size(), file_size);

  // A budget smaller than one file keeps the one just written.
  EXPECT_FALSE(direction_lookup(b, folder, 1).from_cache);
  EXPECT_TRUE(fs::exists(file_b));
  EXPECT_FALSE(fs::exists(file_a));
  EXPECT_FALSE(fs::exists(file_c));
  fs::remove_all(folder);
}

}  // namespace
}  // namespace facet::driver
