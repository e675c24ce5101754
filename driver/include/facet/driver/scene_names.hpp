#pragma once
// The scene names of `facet render`, `facet run` and `facet bench` (--scene), and the view that
// render and bench move through them frame by frame.
//
//   builtin:city          the built-in city (build_city): 34,642 triangles
//   builtin:city:K        the city as K x K tiles side by side (build_city_tiles), K in [1, 64]:
//                         :2 has 136,864 triangles, :4 545,008, :8 2,175,976, :18 11,005,920
//   builtin:city-fine:N   the city with every triangle cut into N² (subdivide_triangles), N in
//                         [1, 64]: 34,642 N² triangles; :4 has 554,272, :8 2,217,088,
//                         :17 10,011,538
//   FILE.gltf, FILE.glb   a glTF 2.0 file (load_gltf)
//   depth:FILE.exr        a depth image (depth_image.hpp) drawn as its grid mesh; several as
//                         depth:A.exr+depth:B.exr; FILE.exr@N takes every N-th pixel (N in
//                         1..64, DepthMeshOptions::step); FILE.exr@lod chooses the step per
//                         block from the eye (DepthMeshOptions::lod_angle_rad,
//                         kDepthLodDefaultRad), FILE.exr@lod=RADIANS with its own angle in
//                         (0, 1]
//   SCENE+depth:FILE.exr  hybrid: any scene above and depth images, in one z-buffer (the depth
//                         images' triangles numbered after the scene's)
// Names that would give more than kMaxSceneTriangles triangles are refused before anything is
// built.
#include <cstdint>
#include <filesystem>
#include <glm/mat4x4.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "facet/driver/city.hpp"
#include "facet/driver/depth_image.hpp"
#include "facet/driver/scene.hpp"
#include "facet/driver/scene_view.hpp"

namespace facet::driver {

inline constexpr std::uint64_t kMaxSceneTriangles = 64'000'000;
// The --scene values, for command-line help.
inline constexpr const char* kSceneNameSyntax =
    "builtin:city | builtin:city:K (KxK tiles) | builtin:city-fine:N (each triangle in N^2) | "
    "FILE.gltf | depth:FILE.exr[@STEP|@lod[=RADIANS]] (a depth image) | SCENE+depth:FILE.exr "
    "(hybrid)";

// A depth image of a scene name, and the grid step its mesh takes.
struct DepthImageName {
  std::filesystem::path file;
  int step = 1;
  double lod_angle_rad = 0;  // DepthMeshOptions::lod_angle_rad; 0: one step for the image
};

struct SceneName {
  // depth_images: no polygon scene, only the depth images.
  enum class Kind { city, city_tiles, city_fine, file, depth_images };
  Kind kind = Kind::city;
  int count = 1;               // K of builtin:city:K, N of builtin:city-fine:N, else 1
  std::filesystem::path file;  // Kind::file only
  std::string text;            // as given
  // The depth images drawn with (or, for Kind::depth_images, instead of) the scene.
  std::vector<DepthImageName> depth_images;
  // The built-in city in any form: its camera path applies (a depth image's eye comes first:
  // choose_scene_view).
  bool builtin_city() const { return kind != Kind::file && kind != Kind::depth_images; }
};

// Parses a scene name (the CLI's --scene value). InputError("command line", OptionName "scene",
// what was expected) for an unknown builtin: name, a count that is not a whole number in range, a
// file that is not .gltf/.glb, a depth image that is not .exr, or a built-in scene of more than
// kMaxSceneTriangles triangles.
SceneName parse_scene_name(std::string_view text);

// Triangles of a built-in scene, counted without building it (0 for files).
std::uint64_t builtin_scene_triangles(const SceneName& name);

// Builds or loads the scene (load_gltf's and read_depth_image's InputError for a bad file), the
// depth images' grid meshes (depth_image_mesh, default options) appended. Images named with @lod
// choose their steps as seen from lod_eye_world, or from their own eye when it is not given.
// With `source_ids`, also the table that maps every triangle ID of the result to the triangle ID
// of the scene the pictures came from: the identity for the polygon scene's own triangles, and for
// a depth image's triangles the source ID its id channel stored (DepthMesh::source_id; 0 when it
// has none). Entry 0 is 0; the table has triangle_count() + 1 entries.
Scene load_scene(const SceneName& name, std::vector<std::uint32_t>* source_ids = nullptr,
                 const std::optional<glm::dvec3>& lod_eye_world = std::nullopt);
// Whether any depth image of the name takes level of detail (@lod).
bool uses_depth_lod(const SceneName& name);
inline Scene load_scene(std::string_view text) { return load_scene(parse_scene_name(text)); }

// A scene name whose depth images take level of detail (@lod), rebuilt as the eye moves. The
// files are read, the polygon scene and the meshes of images without @lod built once; each @lod
// image keeps a DepthLodChooser, and the scene is rebuilt only when some image's levels change:
// then it is load_scene's result for the eye, with the same objects, materials and images and
// other vertices and indices (for replace_geometry and RenderMethod::replace_scene).
class ViewDependentScene {
 public:
  // The scene as seen from eye_world (world frame, metres). load_scene's errors.
  ViewDependentScene(const SceneName& name, const glm::dvec3& eye_world);
  // Chooses every @lod image's levels as seen from eye_world; rebuilds the scene and returns true
  // when any differ from the scene's.
  bool update(const glm::dvec3& eye_world);
  const Scene& scene() const { return scene_; }
  // load_scene's source_ids table of the current scene.
  const std::vector<std::uint32_t>& source_ids() const { return source_ids_; }
  // What the updates so far did (wall-clock milliseconds on the CPU).
  struct Stats {
    std::vector<double> choose_ms;  // per update: choosing every @lod image's levels
    std::vector<double> build_ms;   // per rebuild: the meshes and the merged scene
    // Per rebuild: the share of the @lod images' blocks whose triangles were made anew
    // (DepthMeshBuilder::blocks_made over block_count); the others kept theirs.
    std::vector<double> blocks_remade;
    std::vector<double> triangles;  // per update: the scene's triangles after it
  };
  const Stats& stats() const { return stats_; }
  // The rebuilds, medians of stats() (0 where there is none) and the fewest and most triangles.
  struct Summary {
    std::size_t rebuilds = 0;
    double choose_ms = 0, build_ms = 0, blocks_remade = 0;
    double triangles_median = 0, triangles_min = 0, triangles_max = 0;
  };
  Summary summary() const;

 private:
  void build();
  SceneName name_;
  Scene polygons_;
  struct Image {
    DepthImage image;
    std::optional<DepthLodChooser> chooser;   // @lod only
    std::optional<DepthMeshBuilder> builder;  // @lod only
    DepthLodLevels levels;                    // @lod only: the scene's
    DepthMesh mesh;                           // the mesh of the scene
  };
  std::vector<Image> images_;
  Scene scene_;
  std::vector<std::uint32_t> source_ids_;
  Stats stats_;
};

// The eye pose of frame k of `facet render` and `facet bench`, turning about world up (y) by 360°
// every kTurnFrames frames where no camera path drives it. A static view keeps frame 0's pose on
// every frame (so the facet pipelines reuse passes 1 and 2).
class FrameViews {
 public:
  static constexpr int kTurnFrames = 120;
  // From a chosen view (choose_scene_view; facet render and bench): the city camera path at
  // k · city_step_s seconds when it follows it, else view.T_world_eye_turned(k / kTurnFrames)
  // (a turn on the spot or about the point looked at).
  FrameViews(const SceneView& view, double city_step_s, bool static_view = false);
  glm::dmat4 T_world_eye(int frame) const;
  glm::dmat4 T_eye_world(int frame) const;

 private:
  bool city_ = false, static_ = false;
  double step_s_ = 0;
  SceneView view_;
  CityCameraPath path_;
};

}  // namespace facet::driver
