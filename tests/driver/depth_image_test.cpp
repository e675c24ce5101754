// Depth images (driver/depth_image.hpp): the file format, bad input, the grid mesh on a background
// sphere, and the DPCI of the city drawn forward against the polygon city through the reference.
#include "facet/driver/depth_image.hpp"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <tuple>

#include "facet/driver/city.hpp"
#include "facet/driver/display_outputs.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/reference.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/driver/scene_view.hpp"
#include "facet/driver/session.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "gl_test_context.hpp"
#include "support/facet_cli.hpp"
#include "test_scenes.hpp"

namespace facet::driver {
namespace {

namespace fs = std::filesystem;

// A DPCI with every channel filled from a seeded generator, a quarter of the pixels seeing
// nothing, and a pose that turns and moves.
DepthImage random_dpci(glm::ivec2 size) {
  DepthImage image = make_dpci(size, 0.8, -1.2);
  image.T_world_image = glm::translate(glm::dmat4(1.0), glm::dvec3(3.5, 1.25, -7.0)) *
                        glm::rotate(glm::dmat4(1.0), 0.7, glm::dvec3(0, 1, 0));
  std::mt19937 random(17);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (DepthImagePart& part : image.parts) {
    part.source_id.resize(part.distance_m.size());
    for (std::size_t k = 0; k < part.distance_m.size(); ++k) {
      if (unit(random) < 0.25f) continue;
      part.distance_m[k] = 0.5f + 100.0f * unit(random);
      part.colour[k] = {unit(random), unit(random), unit(random)};
      part.normal[k] = glm::normalize(glm::vec3(unit(random) - 0.5f, unit(random) - 0.5f, 1.0f));
      part.source_id[k] = std::uint32_t(random());  // beyond 2^24: must survive exactly
    }
  }
  return image;
}

TEST(DepthImage, FileRoundTripKeepsEveryValue) {
  const facet::test::TempFolder scratch("facet_depth_image_round_trip");
  const DepthImage written = random_dpci({24, 10});
  const fs::path file = scratch.path() / "image.exr";
  write_depth_image(file, written);
  const DepthImage read = read_depth_image(file);
  EXPECT_EQ(read.kind, DepthImageKind::dpci);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_EQ(read.T_world_image[c][r], written.T_world_image[c][r]);
  ASSERT_EQ(read.parts.size(), 2u);
  for (std::size_t p = 0; p < 2; ++p) {
    const DepthImagePart &a = written.parts[p], &b = read.parts[p];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.size, a.size);
    EXPECT_EQ(b.base.kind, a.base.kind);
    EXPECT_EQ(b.base.tan_extent, a.base.tan_extent);
    EXPECT_EQ(b.base.tan_elevation, a.base.tan_elevation);
    EXPECT_EQ(b.R_image_part, a.R_image_part);
    EXPECT_EQ(b.distance_m, a.distance_m);
    EXPECT_EQ(b.colour, a.colour);
    EXPECT_EQ(b.normal, a.normal);
    EXPECT_EQ(b.source_id, a.source_id);
  }
  EXPECT_EQ(read.parts[1].size, glm::ivec2(10, 10));  // the cap is H × H
  // A planar image, without IDs.
  DepthImage planar = make_planar({8, 6}, 70.0);
  planar.parts[0].distance_m[5] = 2.0f;
  planar.parts[0].normal[5] = {0, 0, 1};
  write_depth_image(scratch.path() / "planar.exr", planar);
  const DepthImage planar_read = read_depth_image(scratch.path() / "planar.exr");
  EXPECT_EQ(planar_read.kind, DepthImageKind::planar);
  EXPECT_TRUE(planar_read.parts[0].source_id.empty());
  EXPECT_EQ(planar_read.parts[0].distance_m, planar.parts[0].distance_m);
  EXPECT_EQ(planar_read.parts[0].base.tan_extent, planar.parts[0].base.tan_extent);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

TEST(DepthImage, BadInputIsRefusedNamingTheField) {
  const facet::test::TempFolder scratch("facet_depth_image_bad");
  DepthImage image = make_planar({6, 4});
  image.parts[0].distance_m[9] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(error_of([&] { image.validate("x.exr"); }).find("'Z'"), std::string::npos);
  EXPECT_NE(error_of([&] { image.validate("x.exr"); }).find("pixel (3, 1)"), std::string::npos);
  image.parts[0].distance_m[9] = 3.0f;  // seen, but its normal is 0
  EXPECT_NE(error_of([&] { image.validate("x.exr"); }).find("N.x"), std::string::npos);
  image.parts[0].normal[9] = {0, 1, 0};
  EXPECT_NO_THROW(image.validate("x.exr"));
  image.parts[0].distance_m[2] = -1.0f;
  EXPECT_NE(error_of([&] { write_depth_image(scratch.path() / "neg.exr", image); }).find("'Z'"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(scratch.path() / "neg.exr"));
  image.parts[0].distance_m[2] = 1.0f;
  image.parts[0].normal[2] = {1, 0, 0};

  // Absurd sizes are refused from the size alone, before any pixel is looked at.
  DepthImage huge = make_planar({1, 1});
  huge.parts[0].size = {100000, 100000};
  EXPECT_NE(error_of([&] { huge.validate("x.exr"); }).find("planar.size"), std::string::npos);
  // A DPCI needs its cap; a pose must be rigid.
  DepthImage no_cap = make_dpci({8, 4});
  no_cap.parts.pop_back();
  EXPECT_NE(error_of([&] { no_cap.validate("x.exr"); }).find("'parts'"), std::string::npos);
  DepthImage scaled = make_planar({4, 4});
  scaled.T_world_image = glm::scale(glm::dmat4(1.0), glm::dvec3(2.0));
  EXPECT_NE(error_of([&] { scaled.validate("x.exr"); }).find("T_world_image"), std::string::npos);

  // A file without the normals: its channels named.
  const fs::path valid = scratch.path() / "valid.exr";
  write_depth_image(valid, image);
  auto input = OIIO::ImageInput::open(valid.string());
  ASSERT_TRUE(input);
  OIIO::ImageSpec spec(6, 4, 4, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B", "Z"};
  spec.attribute("facet:depth_image", input->spec().get_string_attribute("facet:depth_image"));
  input.reset();
  const fs::path no_normals = scratch.path() / "no_normals.exr";
  {
    std::vector<float> pixels(6 * 4 * 4, 1.0f);
    auto output = OIIO::ImageOutput::create("openexr");
    ASSERT_TRUE(output->open(no_normals.string(), spec));
    ASSERT_TRUE(output->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    ASSERT_TRUE(output->close());
  }
  const std::string missing = error_of([&] { read_depth_image(no_normals); });
  EXPECT_NE(missing.find("no_normals.exr"), std::string::npos) << missing;
  EXPECT_NE(missing.find("missing N.x, N.y, N.z"), std::string::npos) << missing;
  // A header claiming 100000 × 4 pixels (its data window edited): refused by size, not read.
  const fs::path wide = scratch.path() / "wide.exr";
  {
    std::string bytes = facet::test::slurp(valid);
    for (const std::string window : {"dataWindow", "displayWindow"}) {
      const std::size_t at = bytes.find(window + std::string(1, '\0') + "box2i");
      ASSERT_NE(at, std::string::npos);
      const std::size_t x_max = at + window.size() + 1 + 6 + 4 + 8;  // name, type, size, min
      const std::int32_t value = 99999;
      std::memcpy(&bytes[x_max], &value, 4);
    }
    std::ofstream(wide, std::ios::binary) << bytes;
  }
  const std::string wide_error = error_of([&] { read_depth_image(wide); });
  EXPECT_NE(wide_error.find("wide.exr"), std::string::npos) << wide_error;
  EXPECT_NE(wide_error.find("size"), std::string::npos) << wide_error;

  // Every channel there, one distance NaN.
  const fs::path nan_depth = scratch.path() / "nan_depth.exr";
  {
    OIIO::ImageSpec full(6, 4, 7, OIIO::TypeDesc::FLOAT);
    full.channelnames = {"R", "G", "B", "Z", "N.x", "N.y", "N.z"};
    full.attribute("facet:depth_image", spec.get_string_attribute("facet:depth_image"));
    std::vector<float> pixels;
    for (int k = 0; k < 24; ++k)
      pixels.insert(pixels.end(), {0.5f, 0.5f, 0.5f, k == 13 ? NAN : 4.0f, 0.0f, 0.0f, 1.0f});
    auto output = OIIO::ImageOutput::create("openexr");
    ASSERT_TRUE(output->open(nan_depth.string(), full));
    ASSERT_TRUE(output->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    ASSERT_TRUE(output->close());
  }
  EXPECT_NE(error_of([&] { read_depth_image(nan_depth); }).find("pixel (1, 2)"), std::string::npos);

  // The CLI: exit 2, the file and field named, nothing written.
  const fs::path log = scratch.path() / "log.txt";
  for (const auto& [file, expected] : {std::pair{no_normals, "missing N.x"},
                                       std::pair{nan_depth, "'Z'"}, std::pair{wide, "size"}}) {
    EXPECT_EQ(facet::test::run_facet(
                  "render --display builtin:dome180 --size 32x32 --scene depth:" + file.string() +
                      " --out " + (scratch.path() / "out").string(),
                  log),
              2)
        << file;
    const std::string said = facet::test::slurp(log);
    EXPECT_NE(said.find(expected), std::string::npos) << said;
    EXPECT_NE(said.find(file.filename().string()), std::string::npos) << said;
    EXPECT_FALSE(fs::exists(scratch.path() / "out"));
  }
  const fs::path out = scratch.path() / "city.exr";
  EXPECT_EQ(facet::test::run_facet(
                "depth-image --scene builtin:city --size 0x64 --out " + out.string(), log),
            2);
  EXPECT_NE(facet::test::slurp(log).find("--size"), std::string::npos) << facet::test::slurp(log);
  EXPECT_EQ(facet::test::run_facet("depth-image --kind sphere --out " + out.string(), log), 2);
  EXPECT_NE(facet::test::slurp(log).find("--kind"), std::string::npos) << facet::test::slurp(log);
  EXPECT_EQ(facet::test::run_facet("depth-image --size 16384x16384 --out " + out.string(), log), 2);
  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(scratch.path()))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
}

using facet::test::background_sphere;

std::vector<std::uint32_t> render_ids(const Scene& scene, const std::vector<OutputSpec>& outputs,
                                      const glm::dmat4& T_eye_world,
                                      std::string_view method_name = "facets") {
  const GpuScene gpu = upload_scene(scene);
  auto method = make_render_method(method_name);
  method->prepare(scene, gpu, outputs, RenderSettings{});
  std::vector<OutputTarget> targets;
  targets.push_back(OutputTarget::create(outputs[0].warp.output_size));
  method->render(T_eye_world, targets);
  return targets[0].read_ids();
}

// Pixels of `scene` drawn with facets onto the 128² 180° dome seen from T_eye_world that show
// nothing, counted inside the dome circle less a 1 px rim; and how many pixels that circle holds.
struct DomeHoles {
  std::size_t holes = 0, inside = 0;
};
DomeHoles dome_holes(const std::vector<std::uint32_t>& ids, glm::ivec2 size) {
  DomeHoles count;
  for (int j = 0; j < size.y; ++j)
    for (int i = 0; i < size.x; ++i) {
      const double dx = i + 0.5 - size.x / 2.0, dy = j + 0.5 - size.y / 2.0;
      if (std::hypot(dx, dy) >= size.x / 2.0 - 1.0) continue;
      ++count.inside;
      count.holes += ids[std::size_t(j * size.x + i)] == 0;
    }
  return count;
}
DomeHoles dome_holes(const Scene& scene, const glm::dmat4& T_eye_world) {
  const glm::ivec2 size{128, 128};
  const std::vector<OutputSpec> outputs = load_display_outputs("builtin:dome180", size);
  return dome_holes(render_ids(scene, outputs, T_eye_world), size);
}

// The 128×64 DPCI (and its cap) that render_depth_image makes of a background sphere of 20 m
// about the image's eye. Needs a current context.
DepthImage rendered_sphere_dpci() {
  DepthImageRequest request;
  request.size = {128, 64};
  return render_depth_image(background_sphere(64, 32, 20.0f), request);
}

TEST(DepthImage, DpciOfABackgroundSphereLeavesNoHoleOnTheDome) {
  test::shared_context();
  const DepthImage image = rendered_sphere_dpci();
  // Every pixel sees the sphere, at most its chord sag nearer than the radius.
  const double sag = 20.0 * (1 - std::cos(M_PI / 32));
  for (const DepthImagePart& part : image.parts)
    for (float d : part.distance_m) {
      ASSERT_LE(d, 20.0f + 1e-3f) << part.name;
      ASSERT_GE(d, 20.0 - sag - 1e-3) << part.name;
    }
  const DepthMesh mesh = depth_image_mesh(image);
  EXPECT_EQ(mesh.dropped_triangles, 0u);
  for (const double tilt : {0.0, 40.0}) {
    const DomeHoles count = dome_holes(
        mesh.scene, glm::rotate(glm::dmat4(1.0), glm::radians(tilt), glm::dvec3(1, 0, 0)));
    EXPECT_EQ(count.holes, 0u) << "tilt " << tilt << ", of " << count.inside;
  }
}

// Watertightness of one part's triangles in the image grid (node (x, y) from the vertex's uv):
// every edge inside the part is shared by exactly two triangles and every edge on its border by
// one (a T-junction leaves an edge once inside), and the triangles' areas in the grid add up to
// the part's (W - 1 or W at a wrapping cylinder) × (H - 1) without one turned over.
struct GridCover {
  std::size_t inner_edges_not_twice = 0, border_edges_not_once = 0, turned = 0;
  double area = 0;
};

GridCover grid_cover(const Scene& scene, std::size_t object, glm::ivec2 size, int last_x) {
  const Primitive& primitive = scene.primitives[scene.objects[object].first_primitive];
  const auto node = [&](std::uint32_t v) {
    return glm::ivec2(int(std::lround(double(scene.uvs[v].x) * size.x - 0.5)),
                      int(std::lround(double(scene.uvs[v].y) * size.y - 0.5)));
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  std::map<std::uint32_t, glm::ivec2> nodes;
  GridCover cover;
  for (std::uint32_t t = 0; t < primitive.index_count; t += 3) {
    std::array<std::uint32_t, 3> v{};
    for (std::uint32_t c = 0; c < 3; ++c) v[c] = scene.indices[primitive.first_index + t + c];
    const glm::ivec2 a = node(v[0]), b = node(v[1]), c = node(v[2]);
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t u = v[std::size_t(e)], w = v[std::size_t((e + 1) % 3)];
      ++uses[{std::min(u, w), std::max(u, w)}];
      nodes[u] = node(u);
    }
    const double twice = double(b.x - a.x) * (c.y - a.y) - double(b.y - a.y) * (c.x - a.x);
    cover.area += std::abs(twice) / 2;
    cover.turned += twice == 0;
  }
  for (const auto& [edge, count] : uses) {
    const glm::ivec2 a = nodes[edge.first], b = nodes[edge.second];
    const bool border = (a.x == b.x && (a.x == 0 || a.x == last_x)) ||
                        (a.y == b.y && (a.y == 0 || a.y == size.y - 1));
    if (border)
      cover.border_edges_not_once += count != 1;
    else
      cover.inner_edges_not_twice += count != 2;
  }
  return cover;
}

// A 150×90 planar image (100° wide, sizes not a multiple of the block) of a plane 5 m ahead.
DepthImage plane_image() {
  DepthImage plane = make_planar({150, 90}, 100.0);
  for (int j = 0; j < 90; ++j)
    for (int i = 0; i < 150; ++i) {
      const std::size_t k = plane.parts[0].pixel_index(i, j);
      plane.parts[0].distance_m[k] = float(5.0 / -plane.parts[0].v_image(i, j).z);
      plane.parts[0].normal[k] = {0, 0, 1};
    }
  return plane;
}

// A 200×100 DPCI (and its cap) of a sphere of 20 m around its eye.
DepthImage sphere_dpci() {
  DepthImage sphere = make_dpci({200, 100});
  for (DepthImagePart& part : sphere.parts)
    for (int j = 0; j < part.size.y; ++j)
      for (int i = 0; i < part.size.x; ++i) {
        const std::size_t k = part.pixel_index(i, j);
        part.distance_m[k] = 20.0f;
        part.normal[k] = -glm::vec3(part.v_image(i, j));
      }
  return sphere;
}

// Whether every part of `mesh` is watertight in its image grid (grid_cover).
void expect_watertight(const DepthImage& image, const Scene& mesh, const std::string& where) {
  for (std::size_t p = 0; p < image.parts.size(); ++p) {
    const DepthImagePart& part = image.parts[p];
    const int last_x = part.base.wraps_horizontally() ? part.size.x : part.size.x - 1;
    const GridCover cover = grid_cover(mesh, p, part.size, last_x);
    EXPECT_EQ(cover.inner_edges_not_twice, 0u) << where << " " << part.name;
    EXPECT_EQ(cover.border_edges_not_once, 0u) << where << " " << part.name;
    EXPECT_EQ(cover.turned, 0u) << where << " " << part.name;
    EXPECT_EQ(cover.area, double(last_x) * (part.size.y - 1)) << where << " " << part.name;
  }
}

TEST(DepthImage, LodMeshHasNoCrackWhereBlocksChangeStep) {
  // The checker itself: two cells of step 1 beside one of step 2 without the middle node on the
  // shared side (a T-junction) are found, and with it (a fan) are not.
  {
    Scene t;
    const auto at = [&](int x, int y) {
      t.positions.push_back({float(x), float(y), 0});
      t.uvs.push_back({(float(x) + 0.5f) / 5, (float(y) + 0.5f) / 3});
      return std::uint32_t(t.positions.size() - 1);
    };
    // Nodes of a 5 × 3 grid: the left 2 × 2 cells at step 1, the right cell (x 2..4) at step 2.
    std::vector<std::uint32_t> n;
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x) n.push_back(at(x, y));
    const auto id = [&](int x, int y) { return n[std::size_t(y * 5 + x)]; };
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x)
        t.indices.insert(t.indices.end(), {id(x, y), id(x, y + 1), id(x + 1, y + 1), id(x, y),
                                           id(x + 1, y + 1), id(x + 1, y)});
    const std::size_t fine = t.indices.size();
    t.indices.insert(t.indices.end(), {id(2, 0), id(2, 2), id(4, 2), id(2, 0), id(4, 2), id(4, 0)});
    t.primitives.push_back({0, std::uint32_t(t.indices.size()), 0});
    t.objects.push_back(Object{});
    t.objects[0].primitive_count = 1;
    const GridCover cracked = grid_cover(t, 0, {5, 3}, 4);
    EXPECT_EQ(cracked.area, 8.0);
    EXPECT_EQ(cracked.inner_edges_not_twice, 3u);  // (2,0)-(2,1), (2,1)-(2,2), (2,0)-(2,2)
    t.indices.resize(fine);
    for (const auto& [p, q] : std::vector<std::pair<glm::ivec2, glm::ivec2>>{{{2, 0}, {2, 1}},
                                                                             {{2, 1}, {2, 2}},
                                                                             {{2, 2}, {4, 2}},
                                                                             {{4, 2}, {4, 0}},
                                                                             {{4, 0}, {2, 0}}})
      t.indices.insert(t.indices.end(), {id(3, 1), id(p.x, p.y), id(q.x, q.y)});
    t.primitives[0].index_count = std::uint32_t(t.indices.size());
    const GridCover fan = grid_cover(t, 0, {5, 3}, 4);
    EXPECT_EQ(fan.area, 8.0);
    EXPECT_EQ(fan.inner_edges_not_twice, 0u);
    EXPECT_EQ(fan.border_edges_not_once, 0u);
  }
  // A plane 5 m ahead of a planar image (sizes not a multiple of the block), and a sphere of
  // 20 m around a DPCI's eye, every pixel seen; level of detail from an eye near the plane's
  // corner and 12 m off the sphere's centre, so that the blocks take several steps.
  const DepthImage plane = plane_image(), sphere = sphere_dpci();
  for (const auto& [image, eye, angle] : {std::tuple{&plane, glm::dvec3(-4.0, 2.5, -4.0), 0.05},
                                          std::tuple{&sphere, glm::dvec3(12.0, 3.0, 0.0), 0.08}}) {
    const DepthMesh mesh = depth_image_mesh(*image, {.lod_angle_rad = angle, .lod_eye_world = eye});
    const DepthMesh full = depth_image_mesh(*image);
    EXPECT_EQ(mesh.dropped_triangles, 0u);
    ASSERT_EQ(mesh.lod_blocks_by_level.size(), 5u);
    std::size_t levels = 0;
    std::string histogram;
    for (std::size_t n : mesh.lod_blocks_by_level) {
      levels += n > 0;
      histogram += std::to_string(n) + " ";
    }
    std::printf("%s: blocks by step 1, 2, 4, 8, 16: %s; %zu triangles, step 1 %zu\n",
                image->parts[0].name.c_str(), histogram.c_str(), mesh.scene.triangle_count(),
                full.scene.triangle_count());
    EXPECT_GE(levels, 3u) << histogram;
    EXPECT_LT(mesh.scene.triangle_count(), full.scene.triangle_count() / 2);
    expect_watertight(*image, mesh.scene, "lod");
  }
  // The level of detail's own bad values.
  EXPECT_NE(
      error_of([&] { depth_image_mesh(plane, {.step = 2, .lod_angle_rad = 0.01}); }).find("lod"),
      std::string::npos);
  EXPECT_NE(error_of([&] { depth_image_mesh(plane, {.lod_angle_rad = -1.0}); }).find("lod"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              depth_image_mesh(plane, {.lod_angle_rad = 0.05, .lod_levels = DepthLodLevels{{1}}});
            }).find("lod"),
            std::string::npos);
  EXPECT_NE(error_of([&] { DepthLodChooser(plane, {}); }).find("lod"), std::string::npos);
}

// The level choice for a moving eye: DepthLodChooser gives what depth_image_mesh chooses for
// each eye, a block refines as the eye approaches it and coarsens as it leaves, every mesh built
// from the chosen levels is watertight, and a DepthMeshBuilder kept along the path gives each
// fresh mesh while remaking only some blocks.
TEST(DepthImage, LodLevelsFollowTheEye) {
  const DepthImage plane = plane_image();
  const DepthMeshOptions options{.lod_angle_rad = 0.05};
  const DepthLodChooser chooser(plane, options);
  // The block holding the image's centre pixel (75, 45): blocks of 16, 10 across.
  const std::size_t centre = 2 * 10 + 4;
  std::vector<int> centre_levels;
  std::size_t distinct = 0;
  DepthLodLevels last;
  // One builder along the whole path, as a moving view keeps it.
  DepthMeshBuilder builder(plane, options);
  std::size_t partial_builds = 0;
  // From the image's eye straight towards the plane (5 m ahead, image -z) to 1 m before it,
  // then back and 6 m further away.
  for (const double z : {0.0, -1.0, -2.0, -3.0, -4.0, -2.0, 0.0, 3.0, 6.0}) {
    const glm::dvec3 eye(0.0, 0.0, z);
    const DepthLodLevels levels = chooser.levels(eye);
    ASSERT_EQ(levels.size(), 1u);
    ASSERT_EQ(levels[0].size(), 60u);
    centre_levels.push_back(levels[0][centre]);
    distinct += levels != last;
    last = levels;
    const DepthMesh chosen = depth_image_mesh(plane, {.lod_angle_rad = 0.05, .lod_eye_world = eye});
    const DepthMesh given = depth_image_mesh(plane, {.lod_angle_rad = 0.05, .lod_levels = levels});
    EXPECT_EQ(chosen.scene.indices, given.scene.indices) << "eye z " << z;
    EXPECT_EQ(chosen.scene.positions, given.scene.positions) << "eye z " << z;
    expect_watertight(plane, given.scene, "eye z " + std::to_string(z));
    // The builder remakes only the blocks whose neighbourhood changed, and its mesh is the fresh
    // build's, vertex for vertex.
    const DepthMesh rebuilt = builder.build(levels);
    EXPECT_EQ(rebuilt.scene.indices, given.scene.indices) << "eye z " << z;
    EXPECT_EQ(rebuilt.scene.positions, given.scene.positions) << "eye z " << z;
    EXPECT_EQ(rebuilt.scene.normals, given.scene.normals) << "eye z " << z;
    EXPECT_EQ(rebuilt.scene.uvs, given.scene.uvs) << "eye z " << z;
    EXPECT_EQ(rebuilt.source_id, given.source_id) << "eye z " << z;
    EXPECT_EQ(rebuilt.dropped_triangles, given.dropped_triangles) << "eye z " << z;
    EXPECT_EQ(rebuilt.lod_blocks_by_level, given.lod_blocks_by_level) << "eye z " << z;
    ASSERT_EQ(builder.block_count(), 60u);
    partial_builds += builder.blocks_made() > 0 && builder.blocks_made() < builder.block_count();
    builder.build(levels);
    EXPECT_EQ(builder.blocks_made(), 0u) << "eye z " << z;
  }
  EXPECT_GE(partial_builds, 3u);
  std::string text;
  for (int l : centre_levels) text += std::to_string(l) + " ";
  std::printf("centre block's level, eye z 0 -1 -2 -3 -4 -2 0 3 6 m: %s\n", text.c_str());
  // Nearer never coarser, farther never finer; 1 m from the plane step 1, from 11 m coarser than
  // from the image's own eye.
  for (std::size_t k = 1; k < 5; ++k) EXPECT_LE(centre_levels[k], centre_levels[k - 1]) << k;
  for (std::size_t k = 5; k < centre_levels.size(); ++k)
    EXPECT_GE(centre_levels[k], centre_levels[k - 1]) << k;
  EXPECT_EQ(centre_levels[4], 0);
  EXPECT_GT(centre_levels[0], 0);
  EXPECT_EQ(centre_levels[6], centre_levels[0]);
  EXPECT_GT(centre_levels[8], centre_levels[0]);
  EXPECT_GE(distinct, 5u);
}

TEST(DepthImage, LodDpciOfABackgroundSphereLeavesNoHoleOnTheDome) {
  test::shared_context();
  const DepthImage image = rendered_sphere_dpci();
  // An eye 8 m off the centre: the near side at 12 m keeps step 1, the far side at 28 m does not.
  const glm::dvec3 eye(8.0, 0.0, 0.0);
  const DepthMesh mesh = depth_image_mesh(image, {.lod_angle_rad = 0.1, .lod_eye_world = eye});
  EXPECT_EQ(mesh.dropped_triangles, 0u);
  std::size_t levels = 0;
  for (std::size_t n : mesh.lod_blocks_by_level) levels += n > 0;
  EXPECT_GE(levels, 2u);
  EXPECT_LT(mesh.scene.triangle_count(), depth_image_mesh(image).scene.triangle_count());
  for (const double tilt : {0.0, 40.0}) {
    const DomeHoles count = dome_holes(
        mesh.scene,
        glm::inverse(glm::translate(glm::dmat4(1.0), eye) *
                     glm::rotate(glm::dmat4(1.0), glm::radians(tilt), glm::dvec3(1, 0, 0))));
    EXPECT_EQ(count.holes, 0u) << "tilt " << tilt << ", of " << count.inside;
  }
}

// One method drawing a ViewDependentScene along a path of eyes: the scene rebuilt where the
// levels change, its buffers replaced (replace_geometry) and the method's scene state with them
// (RenderMethod::replace_scene). Per frame the ID image, and whether the scene was rebuilt
// before it.
struct MovingFrame {
  std::vector<std::uint32_t> ids;
  bool rebuilt = false;
};
std::vector<MovingFrame> render_moving(ViewDependentScene& lod,
                                       const std::vector<OutputSpec>& outputs,
                                       const std::vector<glm::dmat4>& T_world_eyes,
                                       std::string_view method_name,
                                       const std::function<void(std::size_t)>& after_frame = {}) {
  GpuScene gpu = upload_scene(lod.scene());
  auto method = make_render_method(method_name);
  method->prepare(lod.scene(), gpu, outputs, RenderSettings{});
  std::vector<OutputTarget> targets;
  targets.push_back(OutputTarget::create(outputs[0].warp.output_size));
  std::vector<MovingFrame> frames;
  for (std::size_t k = 0; k < T_world_eyes.size(); ++k) {
    MovingFrame& frame = frames.emplace_back();
    frame.rebuilt = lod.update(glm::dvec3(T_world_eyes[k][3]));
    if (frame.rebuilt) {
      replace_geometry(gpu, lod.scene());
      method->replace_scene(lod.scene(), gpu, outputs, RenderSettings{});
    }
    method->render(glm::inverse(T_world_eyes[k]), targets);
    frame.ids = targets[0].read_ids();
    if (after_frame) after_frame(k);
  }
  return frames;
}

// The sphere's LOD DPCI seen from an eye that moves 8 m out from the centre, turning and tilting:
// the scene is rebuilt as the levels change, every frame leaves no hole on the dome, and every
// frame's IDs are those of a method prepared afresh for that frame's scene (the facets pipeline,
// which keeps its facets across the rebuilds, and the cube map, which prepares anew).
TEST(DepthImage, LodSceneRebuiltAsTheEyeMovesLeavesNoHoleOnTheDome) {
  test::shared_context();
  const facet::test::TempFolder scratch("facet_depth_image_moving_eye");
  const fs::path file = scratch.path() / "sphere.exr";
  write_depth_image(file, rendered_sphere_dpci());
  const SceneName name = parse_scene_name("depth:" + file.string() + "@lod=0.1");
  const glm::ivec2 size{128, 128};
  const std::vector<OutputSpec> outputs = load_display_outputs("builtin:dome180", size);
  std::vector<glm::dmat4> T_world_eyes;
  for (int k = 0; k < 6; ++k) {
    const double turn = 0.3 * k;
    const glm::dvec3 eye = 1.6 * k * glm::dvec3(std::cos(turn), 0.0, std::sin(turn));
    T_world_eyes.push_back(glm::translate(glm::dmat4(1.0), eye) * glm::rotate(glm::dmat4(1.0),
                                                                              glm::radians(8.0 * k),
                                                                              glm::dvec3(1, 0, 0)));
  }
  for (const std::string_view method : {"facets", "cubemap"}) {
    ViewDependentScene lod(name, glm::dvec3(T_world_eyes[0][3]));
    std::vector<std::size_t> triangles;
    std::vector<std::vector<std::uint32_t>> fresh;
    const std::vector<MovingFrame> frames =
        render_moving(lod, outputs, T_world_eyes, method, [&](std::size_t k) {
          triangles.push_back(lod.scene().triangle_count());
          fresh.push_back(render_ids(lod.scene(), outputs, glm::inverse(T_world_eyes[k]), method));
        });
    std::size_t rebuilds = 0;
    std::string text;
    for (std::size_t k = 0; k < frames.size(); ++k) {
      rebuilds += frames[k].rebuilt;
      const DomeHoles count = dome_holes(frames[k].ids, size);
      EXPECT_EQ(count.holes, 0u) << method << " frame " << k << ", of " << count.inside;
      EXPECT_EQ(frames[k].ids, fresh[k]) << method << " frame " << k;
      text += std::to_string(triangles[k]) + (frames[k].rebuilt ? "* " : " ");
    }
    std::printf("%.*s: triangles per frame (* rebuilt): %s\n", int(method.size()), method.data(),
                text.c_str());
    EXPECT_FALSE(frames[0].rebuilt);
    EXPECT_GE(rebuilds, 1u) << method;
  }
}

// `facet run`'s Session with a view-dependent scene: each frame's eye chooses the levels, the
// session's scene is the LOD mesh for that eye, and the dome shows no hole.
TEST(DepthImage, SessionRebuildsTheLodSceneForEachFramesEye) {
  test::shared_context();
  const DepthImage image = rendered_sphere_dpci();
  const facet::test::TempFolder scratch("facet_depth_image_session");
  const fs::path file = scratch.path() / "sphere.exr";
  write_depth_image(file, image);
  const SceneName name = parse_scene_name("depth:" + file.string() + "@lod=0.1");
  const glm::ivec2 size{128, 128};
  Session session(load_session_display("builtin:dome180", size), load_scene(name));
  session.set_view_dependent_scene(std::make_unique<ViewDependentScene>(name, glm::dvec3(0.0)));
  std::size_t rebuilds = 0;
  for (int k = 0; k < 4; ++k) {
    FrameState state;
    state.frame = std::uint64_t(k);
    const glm::dvec3 eye(2.5 * k, 0.0, 0.0);
    state.T_world_eye = glm::translate(glm::dmat4(1.0), eye);
    const FrameStats stats = session.render(state, true);
    rebuilds += stats.scene_rebuilt;
    EXPECT_EQ(session.scene().indices,
              depth_image_mesh(image, {.lod_angle_rad = 0.1, .lod_eye_world = eye}).scene.indices)
        << "frame " << k;
    const DomeHoles count = dome_holes(session.targets()[0].read_ids(), size);
    EXPECT_EQ(count.holes, 0u) << "frame " << k << ", of " << count.inside;
  }
  EXPECT_GE(rebuilds, 1u);
}

// The DPCI of the city, drawn forward onto the dome, against the polygon city's reference IDs
// (Embree): mesh triangle IDs map back to the city triangle each came from (the id channel).
struct CityComparison {
  IdComparison ids;
  EdgeDisplacement edges;
  double holes = 0;  // share of pixels the polygons cover and the depth image does not
};

// `tested`: the IDs drawn on the dome of `size`, mapped to the city's triangles.
CityComparison compare_with_city(const Scene& city, const std::vector<std::uint32_t>& tested,
                                 const glm::dmat4& T_eye_world, glm::ivec2 size) {
  std::vector<OutputSpec> outputs = load_display_outputs("builtin:dome180", size);
  const ReferenceRaycaster raycaster(city);
  const WarpInverse inverse(outputs[0].warp);
  const std::vector<std::uint32_t> reference = raycaster.ids(inverse, T_eye_world);
  CityComparison result;
  result.ids = compare_ids(reference, tested, size);
  result.edges = raycaster.edge_displacement(inverse, T_eye_world, reference, tested, {});
  std::size_t covered = 0, holes = 0;
  for (std::size_t k = 0; k < tested.size(); ++k) {
    covered += reference[k] != 0;
    holes += reference[k] != 0 && tested[k] == 0;
  }
  result.holes = double(holes) / double(std::max<std::size_t>(covered, 1));
  return result;
}

CityComparison compare_with_city(const Scene& city, const DepthMesh& mesh,
                                 const glm::dmat4& T_eye_world, glm::ivec2 size) {
  std::vector<OutputSpec> outputs = load_display_outputs("builtin:dome180", size);
  const std::vector<std::uint32_t> mesh_ids = render_ids(mesh.scene, outputs, T_eye_world);
  std::vector<std::uint32_t> tested(mesh_ids.size());
  for (std::size_t k = 0; k < tested.size(); ++k)
    tested[k] = mesh_ids[k] == 0 ? 0 : mesh.source_id[mesh_ids[k] - 1];
  return compare_with_city(city, tested, T_eye_world, size);
}

// The city's DPCI of 512×256 (and its cap) from the first eye of its camera path.
DepthImageRequest city_dpci_request() {
  DepthImageRequest request;
  request.size = {512, 256};
  request.T_world_image =
      glm::translate(glm::dmat4(1.0), glm::dvec3(CityCameraPath().T_world_eye(0.0)[3]));
  return request;
}

TEST(DepthImage, CityDpciWarpedOntoTheDomeMatchesThePolygons) {
  test::shared_context();
  const Scene city = build_city();
  const DepthImageRequest request = city_dpci_request();
  const DepthImage image = render_depth_image(city, request);
  const DepthMesh mesh = depth_image_mesh(image);
  const glm::ivec2 size{192, 192};
  // From the image's own eye: a resampling of what the image saw.
  const glm::dmat4 T_eye_world = glm::inverse(request.T_world_image);
  const CityComparison same = compare_with_city(city, mesh, T_eye_world, size);
  std::printf(
      "same eye: id_mismatch %.5f, edge max %.2f px p99 %.2f px (%zu beyond %.0f px), "
      "holes %.5f, %zu triangles dropped\n",
      same.ids.id_mismatch, same.edges.max_px, same.edges.p99_px, same.edges.beyond_window,
      EdgeDisplacementOptions{}.window_px, same.holes, mesh.dropped_triangles);
  // Measured: id_mismatch 0.00006, edges max 1.15 px, p99 0.81 px, holes 0.0175 (the mesh ends
  // at the last pixel centre seen: half an image pixel short at every silhouette against the sky).
  EXPECT_LE(same.ids.id_mismatch, 0.002);
  EXPECT_LE(same.edges.p99_px, 1.5);
  EXPECT_LE(same.edges.max_px, 2.0);
  EXPECT_LE(same.holes, 0.03);
  // From an eye 1 m to the side and 0.5 m up: the warp itself at work, disocclusions showing
  // where the image saw nothing.
  const glm::dmat4 T_moved_world =
      glm::inverse(glm::translate(request.T_world_image, glm::dvec3(1.0, 0.5, 0.0)));
  const CityComparison moved = compare_with_city(city, mesh, T_moved_world, size);
  std::printf("moved eye: id_mismatch %.5f, edge max %.2f px p99 %.2f px, holes %.5f\n",
              moved.ids.id_mismatch, moved.edges.max_px, moved.edges.p99_px, moved.holes);
  // Measured: id_mismatch 0.00096, edges p99 1.65 px, holes 0.0195.
  EXPECT_LE(moved.ids.id_mismatch, 0.005);
  EXPECT_LE(moved.edges.p99_px, 3.0);
  EXPECT_LE(moved.holes, 0.03);
  // A wrong warp (every distance 50% long) fails the bound from the moved eye.
  DepthImage wrong = image;
  for (DepthImagePart& part : wrong.parts)
    for (float& d : part.distance_m) d *= 1.5f;
  const CityComparison broken =
      compare_with_city(city, depth_image_mesh(wrong), T_moved_world, size);
  std::printf("distances x1.5, moved eye: id_mismatch %.5f\n", broken.ids.id_mismatch);
  EXPECT_GT(broken.ids.id_mismatch, 0.005);
}

// Level of detail on the city's DPCI against the full grid, each mesh built for the eye it is
// seen from: the image's own eye, and an eye 3 m up and 4 m back where the city lies farther.
TEST(DepthImage, CityDpciWithLodKeepsAccuracyWithFewerTriangles) {
  test::shared_context();
  const Scene city = build_city();
  const DepthImageRequest request = city_dpci_request();
  const DepthImage image = render_depth_image(city, request);
  const DepthMesh full = depth_image_mesh(image);
  const glm::ivec2 size{192, 192};
  for (const glm::dvec3 offset : {glm::dvec3(0.0), glm::dvec3(0.0, 3.0, 4.0)}) {
    const glm::dmat4 T_world_eye = glm::translate(request.T_world_image, offset);
    const DepthMesh lod = depth_image_mesh(
        image, {.lod_angle_rad = 0.02, .lod_eye_world = glm::dvec3(T_world_eye[3])});
    const CityComparison a = compare_with_city(city, full, glm::inverse(T_world_eye), size);
    const CityComparison b = compare_with_city(city, lod, glm::inverse(T_world_eye), size);
    std::string histogram;
    for (std::size_t n : lod.lod_blocks_by_level) histogram += std::to_string(n) + " ";
    std::printf(
        "eye +(%.0f, %.0f, %.0f) m: step 1 %zu triangles id_mismatch %.5f p99 %.2f px holes "
        "%.5f; lod 0.02 rad %zu triangles (blocks by step 1..16: %s) id_mismatch %.5f p99 "
        "%.2f px holes %.5f\n",
        offset.x, offset.y, offset.z, full.scene.triangle_count(), a.ids.id_mismatch,
        a.edges.p99_px, a.holes, lod.scene.triangle_count(), histogram.c_str(), b.ids.id_mismatch,
        b.edges.p99_px, b.holes);
    // Measured: 222,697 of 334,218 triangles from the image's eye, 197,810 from the far one;
    // id_mismatch as the full grid's (0.00006, 0.01933), p99 +0.05 px and -0.07 px, holes
    // +0.0008 and +0.0004.
    EXPECT_LT(lod.scene.triangle_count(), full.scene.triangle_count() * 3 / 4);
    EXPECT_LE(b.ids.id_mismatch, a.ids.id_mismatch + 0.002);
    EXPECT_LE(b.edges.p99_px, a.edges.p99_px + 0.5);
    EXPECT_LE(b.holes, a.holes + 0.005);
  }
}

// The city's DPCI with level of detail drawn by one `facets` method as the eye moves from the
// image's own eye to 3 m up and 4 m back, the scene rebuilt where the levels change: every frame
// draws the IDs of the static LOD mesh built for its eye, and the last frame keeps the static
// test's margins against the full grid.
TEST(DepthImage, CityDpciLodFollowsAMovingEyeAsAStaticOneDoes) {
  test::shared_context();
  const Scene city = build_city();
  const DepthImageRequest request = city_dpci_request();
  const DepthImage image = render_depth_image(city, request);
  const facet::test::TempFolder scratch("facet_depth_image_city_moving");
  const fs::path file = scratch.path() / "city.exr";
  write_depth_image(file, image);
  const glm::ivec2 size{192, 192};
  const std::vector<OutputSpec> outputs = load_display_outputs("builtin:dome180", size);
  std::vector<glm::dmat4> T_world_eyes;
  for (int k = 0; k <= 4; ++k)
    T_world_eyes.push_back(
        glm::translate(request.T_world_image, glm::dvec3(0.0, 3.0, 4.0) * (k / 4.0)));
  ViewDependentScene lod(parse_scene_name("depth:" + file.string() + "@lod=0.02"),
                         glm::dvec3(T_world_eyes[0][3]));
  std::vector<std::uint32_t> last_tested;
  std::string text;
  const std::vector<MovingFrame> frames =
      render_moving(lod, outputs, T_world_eyes, "facets", [&](std::size_t k) {
        const DepthMesh fixed = depth_image_mesh(
            image, {.lod_angle_rad = 0.02, .lod_eye_world = glm::dvec3(T_world_eyes[k][3])});
        EXPECT_EQ(lod.scene().indices, fixed.scene.indices) << "frame " << k;
        EXPECT_EQ(lod.scene().triangle_count(), fixed.scene.triangle_count()) << "frame " << k;
        text += std::to_string(fixed.scene.triangle_count()) + " ";
        if (k + 1 == T_world_eyes.size()) {
          const std::vector<std::uint32_t> ids =
              render_ids(fixed.scene, outputs, glm::inverse(T_world_eyes[k]));
          last_tested = ids;
        }
      });
  std::size_t rebuilds = 0;
  for (const MovingFrame& frame : frames) rebuilds += frame.rebuilt;
  std::printf("moving eye: %zu rebuilds, triangles per frame %s\n", rebuilds, text.c_str());
  EXPECT_GE(rebuilds, 1u);
  // The last frame: the moving method's IDs are the static mesh's, and against the polygon city
  // within the static test's margins of the full grid.
  EXPECT_EQ(frames.back().ids, last_tested);
  std::vector<std::uint32_t> tested = frames.back().ids;
  for (std::uint32_t& id : tested) id = lod.source_ids()[id];
  const glm::dmat4 T_eye_world = glm::inverse(T_world_eyes.back());
  const CityComparison moving = compare_with_city(city, tested, T_eye_world, size);
  const CityComparison full = compare_with_city(city, depth_image_mesh(image), T_eye_world, size);
  std::printf(
      "last eye: moving lod id_mismatch %.5f p99 %.2f px holes %.5f; full grid id_mismatch "
      "%.5f p99 %.2f px holes %.5f\n",
      moving.ids.id_mismatch, moving.edges.p99_px, moving.holes, full.ids.id_mismatch,
      full.edges.p99_px, full.holes);
  EXPECT_LE(moving.ids.id_mismatch, full.ids.id_mismatch + 0.002);
  EXPECT_LE(moving.edges.p99_px, full.edges.p99_px + 0.5);
  EXPECT_LE(moving.holes, full.holes + 0.005);
}

TEST(DepthImage, SceneNamesTakeDepthImagesAloneAndHybrid) {
  const SceneName alone = parse_scene_name("depth:a.exr+depth:b.exr");
  EXPECT_EQ(alone.kind, SceneName::Kind::depth_images);
  ASSERT_EQ(alone.depth_images.size(), 2u);
  EXPECT_EQ(alone.depth_images[1].file, fs::path("b.exr"));
  EXPECT_EQ(alone.depth_images[1].step, 1);
  const SceneName coarse = parse_scene_name("depth:a.exr@4");
  EXPECT_EQ(coarse.depth_images[0].file, fs::path("a.exr"));
  EXPECT_EQ(coarse.depth_images[0].step, 4);
  EXPECT_THROW(parse_scene_name("depth:a.exr@0"), InputError);
  EXPECT_THROW(parse_scene_name("depth:a.exr@x"), InputError);
  EXPECT_EQ(parse_scene_name("depth:a.exr@lod").depth_images[0].lod_angle_rad, kDepthLodDefaultRad);
  const SceneName lod = parse_scene_name("builtin:city+depth:a.exr@lod=0.03");
  EXPECT_EQ(lod.depth_images[0].lod_angle_rad, 0.03);
  EXPECT_EQ(lod.depth_images[0].step, 1);
  EXPECT_TRUE(uses_depth_lod(lod));
  EXPECT_FALSE(uses_depth_lod(coarse));
  for (const char* bad :
       {"depth:a.exr@lod=0", "depth:a.exr@lod=-0.1", "depth:a.exr@lod=2", "depth:a.exr@lod=x",
        "depth:a.exr@lod=", "depth:a.exr@lod=nan", "depth:a.exr@lods"})
    EXPECT_NE(error_of([&] { parse_scene_name(bad); }).find("scene"), std::string::npos) << bad;
  EXPECT_NE(error_of([&] { parse_scene_name("depth:a.exr@lod=2"); }).find("lod angle"),
            std::string::npos);
  EXPECT_FALSE(alone.builtin_city());
  const SceneName hybrid = parse_scene_name("builtin:city+depth:a.exr");
  EXPECT_EQ(hybrid.kind, SceneName::Kind::city);
  EXPECT_EQ(hybrid.depth_images.size(), 1u);
  EXPECT_THROW(parse_scene_name("depth:a.png"), InputError);
  EXPECT_THROW(parse_scene_name("builtin:town+depth:a.exr"), InputError);

  // A hybrid scene: the mesh's triangles numbered after the city's, its eye the default view.
  const facet::test::TempFolder scratch("facet_depth_image_names");
  DepthImage image = make_planar({4, 3});
  image.T_world_image = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 2, 0));
  for (std::size_t k = 0; k < 12; ++k) {
    image.parts[0].distance_m[k] = 5.0f;
    image.parts[0].normal[k] = {0, 0, 1};
  }
  write_depth_image(scratch.path() / "a.exr", image);
  CityOptions small;
  small.blocks_per_side = 1;
  const Scene city = build_city(small);
  const Scene mesh = depth_image_mesh(image).scene;
  EXPECT_EQ(mesh.triangle_count(), 12u);  // 3 × 2 cells, two triangles each
  // Every second pixel and the last: columns 0, 2, 3 and rows 0, 2.
  EXPECT_EQ(depth_image_mesh(image, {.step = 2}).scene.triangle_count(), 4u);
  const Scene merged = merge_scenes(city, mesh);
  EXPECT_EQ(merged.triangle_count(), city.triangle_count() + 12);
  const SceneView view = choose_scene_view(merged, {}, true);
  EXPECT_FALSE(view.follows_city_path);
  EXPECT_EQ(glm::dvec3(view.T_world_eye[3]), glm::dvec3(0, 2, 0));
}

// The command line end to end: facet depth-image of the city, then facet render of the depth image
// with the reference ray cast into the polygon city (--reference-scene).
TEST(DepthImage, CliRendersTheCityDpciAgainstThePolygonCity) {
  const facet::test::TempFolder scratch("facet_depth_image_cli");
  const fs::path image = scratch.path() / "city.exr", log = scratch.path() / "log.txt";
  ASSERT_EQ(facet::test::run_facet(
                "depth-image --scene builtin:city --size 256x128 --out " + image.string(), log),
            0)
      << facet::test::slurp(log);
  ASSERT_TRUE(fs::is_regular_file(image));
  // The JSON report of the image (with `suffix`, e.g. "@lod=0.05") on the 96² dome against the
  // polygon city; null when the render does not exit 0.
  const auto render_report = [&](const std::string& suffix) {
    const int status = facet::test::run_facet(
        "render builtin:dome180 --size 96x96 --scene depth:" + image.string() + suffix +
            " --reference --reference-scene builtin:city --json",
        log);
    const std::string text = facet::test::slurp(log);
    EXPECT_EQ(status, 0) << text;
    return status == 0 ? nlohmann::json::parse(text.substr(text.find('{'))) : nlohmann::json();
  };
  const nlohmann::json report = render_report("");
  ASSERT_FALSE(report.is_null());
  const nlohmann::json& reference = report["reference"];
  std::printf("facet render --scene depth: against builtin:city: id_mismatch %.5f, p99 %.2f px\n",
              reference["id_mismatch"].get<double>(), reference["p99_edge_px"].get<double>());
  EXPECT_LE(reference["id_mismatch"].get<double>(), 0.005);
  EXPECT_LE(reference["p99_edge_px"].get<double>(), 2.0);
  // With level of detail: fewer triangles, the same bounds.
  const nlohmann::json lod = render_report("@lod=0.05");
  ASSERT_FALSE(lod.is_null());
  std::printf("@lod=0.05: %llu of %llu triangles, id_mismatch %.5f, p99 %.2f px\n",
              lod["triangles_scene"].get<unsigned long long>(),
              report["triangles_scene"].get<unsigned long long>(),
              lod["reference"]["id_mismatch"].get<double>(),
              lod["reference"]["p99_edge_px"].get<double>());
  EXPECT_LT(lod["triangles_scene"].get<std::uint64_t>(),
            report["triangles_scene"].get<std::uint64_t>());
  EXPECT_LE(lod["reference"]["id_mismatch"].get<double>(), 0.005);
  EXPECT_LE(lod["reference"]["p99_edge_px"].get<double>(), 2.0);
  // A moving eye (circling a point 10 m ahead, 3° a frame): the levels chosen for every frame's
  // eye, the scene rebuilt where they change; the last frame against the polygon city within the
  // moved eye's bounds of the static comparison.
  const nlohmann::json moving = render_report(
      "@lod=0.05 --frames 3 --eye 0,1.7,-6 --look-at "
      "0,1.7,-16");
  ASSERT_FALSE(moving.is_null());
  ASSERT_TRUE(moving.contains("depth_lod")) << moving.dump();
  const nlohmann::json& moving_lod = moving["depth_lod"];
  std::printf("moving eye, @lod=0.05, 3 frames: %s; id_mismatch %.5f, p99 %.2f px\n",
              moving_lod.dump().c_str(), moving["reference"]["id_mismatch"].get<double>(),
              moving["reference"]["p99_edge_px"].get<double>());
  EXPECT_GE(moving_lod["rebuilds"].get<int>(), 1);
  EXPECT_LT(moving_lod["triangles_max"].get<double>(), report["triangles_scene"].get<double>());
  EXPECT_LE(moving["reference"]["id_mismatch"].get<double>(), 0.005);
  EXPECT_LE(moving["reference"]["p99_edge_px"].get<double>(), 3.0);
  // A bad angle: exit 2 naming --scene and the angle.
  EXPECT_EQ(facet::test::run_facet("render --display builtin:dome180 --size 16x16 --scene depth:" +
                                       image.string() + "@lod=3",
                                   log),
            2);
  EXPECT_NE(facet::test::slurp(log).find("lod angle"), std::string::npos)
      << facet::test::slurp(log);
  EXPECT_NE(facet::test::slurp(log).find("--scene"), std::string::npos) << facet::test::slurp(log);
  EXPECT_EQ(facet::test::run_facet("render --display builtin:dome180 --size 16x16 --scene depth:" +
                                       image.string() + " --reference-scene builtin:city",
                                   log),
            2);
}

}  // namespace
}  // namespace facet::driver
