#pragma once
// Depth images (Liu, Liu & Wu's forward warping): colour, distance and normals per pixel, seen
// from one eye point, as a planar (perspective) image or a double-projective cylindrical image
// (DPCI: a 360° cylindrical panorama about the image frame's y axis plus a perspective cap
// looking up that axis). They are drawn forward onto any output as a grid mesh
// (depth_image_mesh): every pixel becomes a vertex at its ray's distance, so every render method
// draws them like polygons, sharing the z-buffer with them.
//
// Frames and units: the image frame has x right, y up and looks down -z (as the eye frame);
// T_world_image places it in the world (metres, rigid), its origin is the eye point. A part's
// base frame is turned into the image frame by R_image_part. Pixel (i, j), row 0 at the top,
// looks along R_image_part · base.direction(((i + 0.5) / W, (j + 0.5) / H)).
//
// The file (FILE.exr, multi-part OpenEXR, one part per image part, sharing the largest part's
// display window; driver/README.md "Depth images"). Channels are float unless said:
//   R, G, B: linear albedo, what the material's base colour times its texture
//            gives, before lighting;
//   Z: distance in metres from the eye point along the pixel centre's ray; +inf where the
//            ray meets nothing;
//   N.x, N.y, N.z: unit normal in the image frame, turned towards the eye; 0 where Z is inf;
//   id (uint, optional): the source scene's triangle ID (render_method.hpp numbering), 0 for none;
//   attribute facet:depth_image: JSON {"format": "facet-depth-image/1", "kind": "planar"|"dpci",
//            "part": name, "base": "perspective"|"cylindrical", base parameters as in
//            .warp.exr ("tan_extent", "azimuth", "tan_elevation"), "rotation" (R_image_part,
//            rows), "T_world_image" (4 rows of 4)}.
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/driver/scene.hpp"
#include "facet/projection/base_projection.hpp"
#include "facet/projection/warp.hpp"

namespace facet::driver {

enum class DepthImageKind { planar, dpci };
std::string to_string(DepthImageKind kind);

// The pixels a depth image file may hold in all parts together, checked from the header before
// any pixel is read (each part is also within kMaxImageSide and kMaxImagePixels).
inline constexpr std::int64_t kMaxDepthImagePixels = std::int64_t(1) << 26;

struct DepthImagePart {
  std::string name;  // "planar", or "cylinder" and "cap" for a DPCI
  BaseProjection base;
  glm::dmat3 R_image_part{1.0};
  glm::ivec2 size{0, 0};
  // Row-major, row 0 at the top, size.x * size.y entries each.
  std::vector<glm::vec3> colour;         // linear albedo RGB
  std::vector<float> distance_m;         // +inf where nothing is seen
  std::vector<glm::vec3> normal;         // image frame, unit, towards the eye; 0 where nothing
  std::vector<std::uint32_t> source_id;  // empty, or the source scene's triangle ID per pixel

  std::size_t pixel_index(int i, int j) const { return std::size_t(j) * size.x + i; }
  // Unit direction of pixel (i, j)'s centre ray in the image frame.
  glm::dvec3 v_image(int i, int j) const;
  // The part as an output of the render methods: its base, size and rotation, no offsets.
  Warp warp() const;
};

struct DepthImage {
  DepthImageKind kind = DepthImageKind::planar;
  glm::dmat4 T_world_image{1.0};
  std::vector<DepthImagePart> parts;  // planar: one; dpci: "cylinder", then "cap"

  // InputError naming `source` and the field: part count and names for the kind, sizes, channel
  // lengths, base parameters, a pose that is not rigid, and the first bad pixel (a distance that
  // is NaN, -inf, zero or negative; a seen pixel whose normal or colour is not finite, or whose
  // normal is not unit length within 1%).
  void validate(const std::string& source = {}) const;
};

// The parts of a DPCI: a cylinder of azimuth [-180°, 180°] and tan elevation [tan_top,
// tan_bottom] at size (W, H), and a cap looking straight up (image +y; the cap's top row
// towards image +z) of H × H pixels with tan extents ±kDpciCapTan, so that it overlaps the
// cylinder's top rows (the cap reaches down to elevation atan(1 / kDpciCapTan) ≈ 38.7° with
// tan_top = 1 at 45°). Pixels empty.
inline constexpr double kDpciCapTan = 1.25;
DepthImage make_dpci(glm::ivec2 cylinder_size, double tan_top = 1.0, double tan_bottom = -1.0);
// A planar image of size (W, H) with horizontal field of view fov_x_deg (square pixels).
DepthImage make_planar(glm::ivec2 size, double fov_x_deg = 90.0);

// Reads FILE.exr. InputError naming the file and the field: not a regular file, not an image,
// a missing channel or attribute, part sizes beyond kMaxImageSide / kMaxImagePixels or all parts
// beyond kMaxDepthImagePixels (from the header, before reading pixels), then validate().
DepthImage read_depth_image(const std::filesystem::path& path);
// Validates, then writes every part atomically (write_atomically); InputError naming the file.
void write_depth_image(const std::filesystem::path& path, const DepthImage& image);

// How a depth image becomes a grid mesh.
struct DepthMeshOptions {
  // Every step-th pixel of a part becomes a vertex (with the last row and column kept), 1: all.
  int step = 1;
  // A grid edge between two seen pixels joins one surface when the plane through either end
  // (its point and stored normal) meets the other end's ray within `edge_footprints` of that
  // ray's pixel footprints (distance · the angle between the two rays) of the other end's
  // distance, or when the edge runs within `edge_tangent_deg` of either end's tangent plane.
  // Across a depth discontinuity between surfaces facing the eye the gap is many footprints and
  // the edge runs along the ray, steep to both surfaces. A plane predicts its own neighbours
  // exactly, however grazing; a fold (a box's edge) is off by about a footprint when both faces
  // face the eye, and the edge follows the grazing face when one does not. Surfaces seen more
  // than 90° - edge_tangent_deg from their normal get a sheet to what lies behind them, nearly
  // along the rays. Triangles with an edge that fails, or a corner not seen, are dropped.
  double edge_footprints = 4.0;
  double edge_tangent_deg = 15.0;
  // View-dependent level of detail, off at 0 (one `step` for the whole image, which must then
  // be 1 to turn it on). Each kDepthLodBlock × kDepthLodBlock block of a part takes the coarsest
  // step of 1, 2, 4, ..., kDepthLodBlock at which neighbouring grid vertices, seen from
  // lod_eye_world (the image's own eye when not given), stay within lod_angle_rad of each other:
  // the block's largest angle between neighbouring pixels that join one surface, times the step.
  // Neighbouring blocks (the cylinder's seam included) differ by one level at most, the finer
  // one winning; a coarse cell next to a finer block takes the finer block's vertices on their
  // shared edge (a fan about its centre pixel, or a strip where it is one pixel wide), so the
  // mesh has no T-junctions. Discontinuity edges are judged as above on every triangle.
  // From the image's own eye every surface is seen at the image's own resolution, so the step
  // there follows only the pixels' angular pitch (finer near a cylinder's horizon than its top
  // rows, finer at a cap's centre than its corners); moving towards a surface enlarges it (step
  // 1 at the least: the image holds no more), moving away shrinks it.
  double lod_angle_rad = 0;
  std::optional<glm::dvec3> lod_eye_world = std::nullopt;
  // With level of detail: the levels (DepthLodChooser::levels) to build, instead of choosing them
  // from lod_eye_world; InputError naming "lod" when their counts do not fit the image's blocks.
  std::optional<std::vector<std::vector<std::uint8_t>>> lod_levels = std::nullopt;
};
// The block side of DepthMeshOptions::lod_angle_rad, in pixels, and the coarsest step.
inline constexpr int kDepthLodBlock = 16;
// The angle `depth:FILE.exr@lod` takes (scene_names.hpp): 0.01 rad, about 1.6 pixels of the
// 512² 180° dome.
inline constexpr double kDepthLodDefaultRad = 0.01;

// The level of every level-of-detail block (its step is 2^level) of every part: levels[p][by ·
// blocks_x + bx], blocks_x = ceil(last_x / kDepthLodBlock) and blocks_y = ceil((H - 1) /
// kDepthLodBlock) with last_x = W at a cylinder (its seam) and W - 1 otherwise.
using DepthLodLevels = std::vector<std::vector<std::uint8_t>>;

// The level choice of DepthMeshOptions::lod_angle_rad for any eye, keeping what does not depend
// on the eye: every seen pixel's point in the image frame and which neighbouring pixels join one
// surface. levels() for an eye equals what depth_image_mesh chooses with lod_eye_world = that eye,
// so a view that moves can rebuild the mesh (DepthMeshOptions::lod_levels) only when they change.
class DepthLodChooser {
 public:
  // InputError as depth_image_mesh's, and naming "lod" for an angle that is not in (0, 1] rad.
  DepthLodChooser(const DepthImage& image, const DepthMeshOptions& options);
  // The levels seen from eye_world (world frame, metres).
  DepthLodLevels levels(const glm::dvec3& eye_world) const;

 private:
  struct Part {
    int blocks_x = 0, blocks_y = 0;
    bool wraps = false;
    std::vector<glm::dvec3> p_image;  // per pixel, row-major; unused where nothing is seen
    // Neighbouring pixels (right, below; across the seam) that join one surface, and the block
    // their first pixel lies in.
    struct Pair {
      std::uint32_t a, b, block;
    };
    std::vector<Pair> pairs;
  };
  glm::dmat4 T_image_world_{1.0};
  double angle_rad_ = 0;
  std::vector<Part> parts_;
};

// The source of every triangle of a depth image's mesh.
struct DepthMesh {
  Scene scene;  // one object per part, its colour as a texture, lit by the material's shading
  // For triangle ID k (render_method.hpp numbering) source_id[k - 1] is the part's id channel at
  // the triangle's corners (the value two or three corners share, else the first corner's); 0
  // when the image has no id channel. source_id[0 - 1] does not exist: ID 0 maps to 0.
  std::vector<std::uint32_t> source_id;
  std::size_t dropped_triangles = 0;  // cells' triangles dropped at discontinuities
  // With level of detail: blocks (all parts) per step, index log2(step); else empty.
  std::vector<std::size_t> lod_blocks_by_level;
};

// The grid mesh: the vertex of pixel (i, j) at eye + distance · v (McMillan's pre-warp), in the
// world frame; per vertex the stored normal (world frame) and the colour image's texel centre as
// uv. The cylinder's last column joins its first. Triangles face the eye (counter-clockwise seen
// from it). The scene also holds a SceneCamera named kDepthImageEyeCamera at T_world_image.
// InputError naming the option "step" for a step outside [1, 64], "lod" for an angle that is
// not finite or outside [0, 1] rad, or an angle with a step other than 1.
DepthMesh depth_image_mesh(const DepthImage& image, const DepthMeshOptions& options = {});

// depth_image_mesh for one image and options at any levels of detail, keeping what does not
// depend on the levels: every seen pixel's point, the colour textures, and each block's triangles
// with the level they were made at and the levels of its finer neighbours (the nodes a block's
// cells stitch to). A build re-assembles only the blocks whose own or finer neighbours' levels
// differ from the last build's; the rest keep their triangles, so a view that moves pays for the
// blocks whose level changed and for copying the others. build(levels) equals
// depth_image_mesh(image, options with lod_levels = levels), vertex for vertex.
class DepthMeshBuilder {
 public:
  // depth_image_mesh's InputError for the image and options (lod_levels and lod_eye_world are not
  // used here: build() takes the levels).
  DepthMeshBuilder(const DepthImage& image, const DepthMeshOptions& options);
  ~DepthMeshBuilder();
  DepthMeshBuilder(DepthMeshBuilder&&) noexcept;
  DepthMeshBuilder& operator=(DepthMeshBuilder&&) noexcept;

  // The mesh at `levels` (DepthLodChooser::levels; ignored without level of detail). InputError
  // naming "lod" when they do not fit the image's blocks.
  DepthMesh build(const DepthLodLevels& levels);
  // Blocks (all parts) whose triangles the last build made anew, and blocks in all.
  std::size_t blocks_made() const { return blocks_made_; }
  std::size_t block_count() const;

 private:
  struct Part;
  std::vector<Part> parts_;
  glm::dmat4 T_world_image_{1.0};
  DepthMeshOptions options_;
  bool lod_ = false;
  std::size_t blocks_made_ = 0;
};

// Several scenes in one: objects, primitives, materials, images and cameras appended in order
// (triangle IDs of `b` follow those of `a`). `a`'s animation is kept, `b`'s is not taken.
Scene merge_scenes(Scene a, const Scene& b);

// What `facet depth-image` renders.
struct DepthImageRequest {
  DepthImageKind kind = DepthImageKind::dpci;
  glm::ivec2 size{512, 512};  // planar: the image; dpci: the cylinder (the cap is H × H)
  double fov_x_deg = 90.0;    // planar only
  glm::dmat4 T_world_image{1.0};
};

// Renders `scene` into a depth image with the facet pipeline (IDs of every part, back faces
// culled), then intersects each pixel's ray with the triangle seen there for the exact distance,
// the interpolated normal and the material's colour (base colour times the texture, bilinear).
// Needs a current GL context. InputError naming --size for a size beyond the limits.
DepthImage render_depth_image(const Scene& scene, const DepthImageRequest& request);

// `facet depth-image`: --scene (scene_names.hpp), --out FILE.exr, --kind, --size, --eye.
struct DepthImageCommand {
  std::string scene = "builtin:city";
  std::filesystem::path out;
  std::string kind = "dpci";       // planar | dpci
  std::optional<glm::ivec2> size;  // default 512x512
  std::optional<glm::dvec3> eye_world;
};
// The pose of the image: at eye_world when given (the image frame's axes the world's), else at
// the scene's default view (choose_scene_view; the city camera path at t = 0): a planar image
// takes that view's orientation, a DPCI only its position (its axis stays world y).
glm::dmat4 depth_image_pose(const Scene& scene, bool builtin_city, DepthImageKind kind,
                            const std::optional<glm::dvec3>& eye_world);
// Loads the scene, renders it in a headless GL context and writes --out atomically. InputError
// naming the flag for a bad --kind, an --out that is not .exr or is the scene file, sizes beyond
// the limits; the scene's own errors. Returns the image written.
DepthImage run_depth_image_command(const DepthImageCommand& command);

}  // namespace facet::driver
