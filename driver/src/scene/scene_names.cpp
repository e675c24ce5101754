#include "facet/driver/scene_names.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "facet/driver/depth_image.hpp"
#include "facet/driver/gltf_loader.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/statistics.hpp"

namespace facet::driver {
namespace {

constexpr const char* kExpected =
    "builtin:city, builtin:city:K (K x K tiles, K in 1..64), builtin:city-fine:N (every "
    "triangle cut into N², N in 1..64) or a .gltf/.glb file, optionally followed by "
    "+depth:FILE.exr depth images, or depth:FILE.exr alone";

[[noreturn]] void refuse(std::string_view text, const std::string& why) {
  throw InputError("command line", OptionName{"scene"},
                   "expected " + std::string(kExpected) + "; got '" + std::string(text) + "'" +
                       (why.empty() ? "" : " (" + why + ")"));
}

int parse_count(std::string_view text, std::string_view digits) {
  int value = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || error != std::errc() || end != digits.data() + digits.size())
    refuse(text, "the count must be a whole number");
  if (value < 1 || value > 64) refuse(text, "the count must be in 1..64");
  return value;
}

double parse_lod_angle(std::string_view text, std::string_view digits) {
  double value = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || error != std::errc() || end != digits.data() + digits.size() ||
      !std::isfinite(value) || value <= 0 || value > 1)
    refuse(text, "the lod angle must be a number of radians in (0, 1]");
  return value;
}

std::uint64_t city_triangles() {
  static const std::uint64_t count = build_city().triangle_count();
  return count;
}

}  // namespace

SceneName parse_scene_name(std::string_view text) {
  // Depth images: "depth:A.exr", "depth:A.exr+depth:B.exr", "SCENE+depth:A.exr".
  constexpr std::string_view kDepth = "depth:", kMoreDepth = "+depth:";
  const bool only_depth = text.starts_with(kDepth);
  const std::size_t first_depth = only_depth ? 0 : text.find(kMoreDepth);
  if (first_depth != std::string_view::npos) {
    std::vector<DepthImageName> files;
    std::string_view rest = text.substr(first_depth + (only_depth ? kDepth : kMoreDepth).size());
    while (true) {
      const std::size_t next = rest.find(kMoreDepth);
      std::string_view file = rest.substr(0, next);
      DepthImageName image;
      const std::size_t at = file.rfind(".exr@");
      if (at != std::string_view::npos) {
        const std::string_view suffix = file.substr(at + 5);
        if (suffix == "lod") {
          image.lod_angle_rad = kDepthLodDefaultRad;
        } else if (suffix.starts_with("lod=")) {
          image.lod_angle_rad = parse_lod_angle(text, suffix.substr(4));
        } else {
          image.step = parse_count(text, suffix);
        }
        file = file.substr(0, at + 4);
      }
      if (!file.ends_with(".exr") || file.size() <= 4)
        refuse(text,
               "a depth image is a .exr file: depth:FILE.exr, depth:FILE.exr@STEP or "
               "depth:FILE.exr@lod[=RADIANS]");
      image.file = std::filesystem::path(file);
      files.push_back(image);
      if (next == std::string_view::npos) break;
      rest = rest.substr(next + kMoreDepth.size());
    }
    SceneName name;
    if (!only_depth) name = parse_scene_name(text.substr(0, first_depth));
    if (only_depth) name.kind = SceneName::Kind::depth_images;
    name.text = std::string(text);
    name.depth_images = std::move(files);
    return name;
  }
  SceneName name;
  name.text = std::string(text);
  if (text.starts_with("builtin:")) {
    const std::string_view rest = text.substr(8);
    if (rest == "city") {
      name.kind = SceneName::Kind::city;
    } else if (rest.starts_with("city:")) {
      name.kind = SceneName::Kind::city_tiles;
      name.count = parse_count(text, rest.substr(5));
    } else if (rest.starts_with("city-fine:")) {
      name.kind = SceneName::Kind::city_fine;
      name.count = parse_count(text, rest.substr(10));
    } else {
      refuse(text, "unknown built-in scene");
    }
    // Refused up front: a scene this size needs gigabytes before the first frame.
    const std::uint64_t triangles = builtin_scene_triangles(name);
    if (triangles > kMaxSceneTriangles)
      refuse(text, std::to_string(triangles) + " triangles; at most " +
                       std::to_string(kMaxSceneTriangles) + " are allowed");
    return name;
  }
  const std::filesystem::path path(text);
  const std::string ext = path.extension().string();
  if (ext != ".gltf" && ext != ".glb") refuse(text, "");
  name.kind = SceneName::Kind::file;
  name.file = path;
  return name;
}

std::uint64_t builtin_scene_triangles(const SceneName& name) {
  switch (name.kind) {
    case SceneName::Kind::city:
      return city_triangles();
    case SceneName::Kind::city_tiles:
      return city_tiles_triangle_count(name.count);
    case SceneName::Kind::city_fine:
      return city_triangles() * std::uint64_t(name.count) * std::uint64_t(name.count);
    case SceneName::Kind::file:
    case SceneName::Kind::depth_images:
      break;
  }
  return 0;
}

namespace {

Scene load_polygons(const SceneName& name) {
  switch (name.kind) {
    case SceneName::Kind::city:
      return build_city();
    case SceneName::Kind::city_tiles:
      return build_city_tiles(name.count);
    case SceneName::Kind::city_fine:
      return name.count == 1 ? build_city() : subdivide_triangles(build_city(), name.count);
    case SceneName::Kind::file:
      break;
    case SceneName::Kind::depth_images:
      return Scene{};
  }
  return load_gltf(name.file);
}

}  // namespace

bool uses_depth_lod(const SceneName& name) {
  for (const DepthImageName& image : name.depth_images)
    if (image.lod_angle_rad > 0) return true;
  return false;
}

Scene load_scene(const SceneName& name, std::vector<std::uint32_t>* source_ids,
                 const std::optional<glm::dvec3>& lod_eye_world) {
  Scene scene = load_polygons(name);
  if (source_ids) {
    source_ids->resize(scene.triangle_count() + 1);
    for (std::size_t id = 0; id < source_ids->size(); ++id) (*source_ids)[id] = std::uint32_t(id);
  }
  for (std::size_t k = 0; k < name.depth_images.size(); ++k) {
    const DepthImageName& image = name.depth_images[k];
    DepthMesh mesh = depth_image_mesh(
        read_depth_image(image.file),
        {.step = image.step, .lod_angle_rad = image.lod_angle_rad, .lod_eye_world = lod_eye_world});
    mesh.scene.name = image.file.filename().string();
    if (source_ids)
      source_ids->insert(source_ids->end(), mesh.source_id.begin(), mesh.source_id.end());
    scene = (k == 0 && name.kind == SceneName::Kind::depth_images)
                ? std::move(mesh.scene)
                : merge_scenes(std::move(scene), mesh.scene);
  }
  return scene;
}

namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

ViewDependentScene::ViewDependentScene(const SceneName& name, const glm::dvec3& eye_world)
    : name_(name), polygons_(load_polygons(name)) {
  for (const DepthImageName& file : name.depth_images) {
    Image& image = images_.emplace_back();
    image.image = read_depth_image(file.file);
    if (file.lod_angle_rad > 0) {
      image.chooser.emplace(image.image, DepthMeshOptions{.lod_angle_rad = file.lod_angle_rad});
      image.levels = image.chooser->levels(eye_world);
      image.builder.emplace(image.image, DepthMeshOptions{.lod_angle_rad = file.lod_angle_rad});
      image.mesh = image.builder->build(image.levels);
    } else {
      image.mesh = depth_image_mesh(image.image, {.step = file.step});
    }
    image.mesh.scene.name = file.file.filename().string();
  }
  build();
}

void ViewDependentScene::build() {
  source_ids_.resize(polygons_.triangle_count() + 1);
  for (std::size_t id = 0; id < source_ids_.size(); ++id) source_ids_[id] = std::uint32_t(id);
  scene_ = name_.kind == SceneName::Kind::depth_images ? Scene{} : polygons_;
  for (std::size_t k = 0; k < images_.size(); ++k) {
    DepthMesh& mesh = images_[k].mesh;
    source_ids_.insert(source_ids_.end(), mesh.source_id.begin(), mesh.source_id.end());
    if (k > 0 || name_.kind != SceneName::Kind::depth_images)
      scene_ = merge_scenes(std::move(scene_), mesh.scene);
    else if (images_.size() == 1)
      scene_ = std::move(mesh.scene);  // a lone image's mesh is built anew before every build()
    else
      scene_ = mesh.scene;
  }
}

bool ViewDependentScene::update(const glm::dvec3& eye_world) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::optional<DepthLodLevels>> changed(images_.size());
  bool any = false;
  for (std::size_t k = 0; k < images_.size(); ++k) {
    if (!images_[k].chooser) continue;
    DepthLodLevels levels = images_[k].chooser->levels(eye_world);
    if (levels == images_[k].levels) continue;
    changed[k] = std::move(levels);
    any = true;
  }
  stats_.choose_ms.push_back(ms_since(start));
  if (any) {
    const auto build_start = std::chrono::steady_clock::now();
    std::size_t blocks = 0, remade = 0;
    for (std::size_t k = 0; k < images_.size(); ++k) {
      if (!images_[k].builder) continue;
      blocks += images_[k].builder->block_count();
      if (!changed[k]) continue;
      Image& image = images_[k];
      image.levels = std::move(*changed[k]);
      image.mesh = image.builder->build(image.levels);
      remade += image.builder->blocks_made();
      image.mesh.scene.name = name_.depth_images[k].file.filename().string();
    }
    build();
    stats_.build_ms.push_back(ms_since(build_start));
    stats_.blocks_remade.push_back(blocks > 0 ? double(remade) / double(blocks) : 0.0);
  }
  stats_.triangles.push_back(double(scene_.triangle_count()));
  return any;
}

ViewDependentScene::Summary ViewDependentScene::summary() const {
  Summary summary{.rebuilds = stats_.build_ms.size(),
                  .choose_ms = median(stats_.choose_ms),
                  .build_ms = median(stats_.build_ms),
                  .blocks_remade = median(stats_.blocks_remade),
                  .triangles_median = median(stats_.triangles)};
  if (!stats_.triangles.empty()) {
    const auto [fewest, most] =
        std::minmax_element(stats_.triangles.begin(), stats_.triangles.end());
    summary.triangles_min = *fewest;
    summary.triangles_max = *most;
  }
  return summary;
}

FrameViews::FrameViews(const SceneView& view, double city_step_s, bool static_view)
    : city_(view.follows_city_path), static_(static_view), step_s_(city_step_s), view_(view) {}

glm::dmat4 FrameViews::T_world_eye(int frame) const {
  const int k = static_ ? 0 : frame;
  if (city_) return path_.T_world_eye(k * step_s_);
  return view_.T_world_eye_turned(double(k % kTurnFrames) / kTurnFrames);
}

glm::dmat4 FrameViews::T_eye_world(int frame) const { return glm::inverse(T_world_eye(frame)); }

}  // namespace facet::driver
