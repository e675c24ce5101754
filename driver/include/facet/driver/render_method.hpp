#pragma once
// The interface every renderer of a display implements: the facet replication pipelines (modern
// and the seed's geometry-shader form) and the baselines (cube map, naive multi-pass, per-vertex
// projection). One scene, one view, several outputs per frame; each output is one projector.
//
// Triangle IDs. Every renderer can write a triangle-ID image (R32UI) beside colour and depth, and
// the CPU ray-cast reference writes the same numbering, so images compare pixel by pixel:
//   id = 1 + (triangles of all objects before this one, in Scene::objects order)
//          + (ordinal of the triangle inside this object's primitive range, primitives in order)
//   id = 0 where no triangle was drawn.
// scene_triangle_base() gives the first term.
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "facet/driver/gl_objects.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/scene.hpp"
#include "facet/projection/facets.hpp"
#include "facet/projection/glc.hpp"
#include "facet/projection/warp.hpp"

namespace facet::driver {

// One projector output as a renderer sees it: its exact warp (the map from eye directions to
// its output pixels) and its name. An output of a GLC camera (a *.glc.json display) has no
// single centre of projection: `glc` is its camera, drawn by the GLC methods alone ("glc",
// "glc-2pass": is_glc_method), and `warp`
// only carries its output size.
struct OutputSpec {
  std::string name;
  Warp warp;
  std::shared_ptr<const PiecewiseGlc> glc{};
};

// How pass 1 of the facet methods finds the facets a triangle may cover: the bucket grid
// (CoverageGrid; the hierarchy walk for huge triangles), or the hierarchy walk for every triangle
// (CoverageIndex), kept as the reference the grid is measured and tested against.
enum class FacetCoverage { grid, walk };

// Where the facet pipelines (facets, facets-gs, tessellated) cull objects against each output's
// facets and build the frame's triangle list: on the CPU, uploaded when the view or an object
// moves, or on the GPU (replication/list_build.comp), where only the objects' eye-frame spheres
// are uploaded. automatic takes the GPU on a hardware renderer and the CPU on a software one,
// where the CPU is the faster (driver/README.md). The images are the same; `naive` always culls
// on the CPU.
enum class TriangleListBuild { automatic, cpu, gpu };

struct RenderSettings {
  // Facet methods: how the warp is cut into facets, and how pass 1 finds a triangle's facets.
  FacetBuildOptions facets;
  FacetCoverage coverage = FacetCoverage::grid;
  TriangleListBuild triangle_list = TriangleListBuild::automatic;
  // Facet methods: draw the two facets of a tensor cell that share one projection as one quad
  // (FacetPieces); false draws every facet on its own, as the hierarchy walk lists them.
  bool merge_coplanar_facets = true;
  // Cube-map baseline: edge length of a cube face in pixels; perspective baseline: the longer
  // side of its image.
  int cube_face_size = 1024;
  // Cube-map baseline: how the faces are made. six_pass draws the scene once per face the
  // outputs need; layered draws it once, a geometry stage sending every triangle to each face
  // (gl_Layer), for GPUs. Six passes are the faster on llvmpipe (driver/README.md, "cubemap").
  enum class CubeCreation { six_pass, layered };
  CubeCreation cube_creation = CubeCreation::six_pass;
  // Cube-map baseline: per-face culling. objects: an object is drawn only into the faces whose
  // frustum its bounding sphere meets (on the CPU); triangles: besides, a geometry stage leaves a
  // triangle out of a face when all its vertices lie beyond one plane of the face's frustum
  // (layered creation culls with it always, unless none). none draws everything into every face.
  // The pixels are the same for all three; objects is the fastest on llvmpipe.
  enum class CubeCulling { none, objects, triangles };
  CubeCulling cube_culling = CubeCulling::objects;
  // Cube-map baseline: mipmaps of the colour faces (glGenerateMipmap after drawing them), sampled
  // trilinearly by the lookup pass, as Trapp & Döllner do. Triangle IDs always come from the
  // nearest level-0 texel, so IDs and edge errors do not change: only the colour (less aliasing
  // where face texels are smaller than output pixels) and the time (11-26% more on llvmpipe),
  // hence off by default.
  bool cube_mipmaps = false;
  // Per-vertex baseline: tessellation level cap (1 = no tessellation).
  int max_tessellation = 1;
  // Tessellator form: cap on its tessellation levels, 0 for GL_MAX_TESS_GEN_LEVEL (64 or more).
  // One patch makes at most cap² replicas; a triangle that covers more takes further instances
  // of the draw. Lower caps exist to test that path cheaply.
  int tessellated_max_level = 0;
  // Colour samples per pixel (0 or 1: no multisampling). IDs and depth are then resolved from
  // sample 0.
  int msaa_samples = 0;
  // Skip triangles that face away from the eye (counter-clockwise seen from the eye is front).
  bool cull_back_faces = true;
  // Near distance in metres along the facet normal (reversed-Z: depth = z_near / (n·X)).
  double z_near = 0.05;
  // The fragment shading of every method (driver/material_shader.hpp); IDs do not depend on it.
  MaterialShader material;
};

// The GPU images of one output, all at the warp's output size. Colour is SRGB8_ALPHA8, IDs
// R32UI, depth DEPTH_COMPONENT32F cleared to 0 (reversed-Z: greater is nearer).
// Row 0 of every texture is the bottom row of the output image (GL convention); the read_*
// functions return images with row 0 at the top (DESIGN.md output pixels).
class OutputTarget {
 public:
  static OutputTarget create(glm::ivec2 size, int msaa_samples = 0);

  glm::ivec2 size() const { return size_; }
  const Framebuffer& framebuffer() const { return framebuffer_; }
  const Texture& colour() const { return colour_; }
  const Texture& ids() const { return ids_; }
  const Texture& depth() const { return depth_; }

  // Clears colour to `background` (linear RGBA), IDs to 0 and depth to 0 (far).
  void clear(const glm::vec4& background = {0, 0, 0, 1});
  // Binds the framebuffer (the multisampled one when there is one) and sets the viewport to the
  // whole output; enables GL_FRAMEBUFFER_SRGB. Colour is draw buffer 0, IDs draw buffer 1.
  void bind() const;
  // Copies the multisampled images into colour(), ids() and depth() (IDs and depth from one
  // sample). Renderers call it at the end of a frame; a no-op without multisampling.
  void resolve() const;

  std::vector<std::uint8_t> read_colour_rgba8() const;  // sRGB, top row first
  std::vector<std::uint32_t> read_ids() const;          // top row first
  std::vector<float> read_depth() const;                // top row first, reversed-Z

 private:
  glm::ivec2 size_{0, 0};
  int msaa_samples_ = 0;
  Framebuffer framebuffer_;
  Texture colour_, ids_, depth_;
  Framebuffer msaa_framebuffer_;  // empty without multisampling
  Renderbuffer msaa_colour_, msaa_ids_, msaa_depth_;
};

struct RenderStats {
  std::uint64_t triangles_scene = 0;  // Scene::triangle_count, whatever the method culls
  // Triangles the method takes in after culling whole objects by their bounds (the facet
  // pipelines cull clusters too, by their bounds and where they face away), summed over outputs.
  std::uint64_t triangles_in = 0;
  std::uint64_t triangles_visible = 0;  // after per-triangle culling (back face, behind, coverage)
  // Facet pipelines: of triangles_in, those whose object or cluster lies inside one piece's
  // guarded pyramid and clear of every other piece's (sole_piece_of_sphere), which pass 1 gives
  // that piece without the coverage grid.
  std::uint64_t triangles_sole_piece = 0;
  // Facet pipelines: whether an output's triangle list was built on the GPU
  // (RenderSettings::triangle_list).
  bool triangle_list_on_gpu = false;
  std::uint64_t replicas = 0;  // triangle draws issued, summed over outputs
  std::uint64_t facets = 0;    // facets over all outputs (0 for non-facet methods)
  // Passes 1+2 skipped: neither the view nor any object's transform changed since the last frame.
  bool reused_replication = false;
  // Per-vertex baseline only: triangles (tessellated pieces) dropped because the warp's P has no
  // value at a corner or they surround or near a singular direction, and draws beyond a
  // triangle's first on a 360° base (seam copies, included in replicas).
  std::uint64_t dropped_triangles = 0;
  std::uint64_t seam_copies = 0;
  // GPU memory the method holds for this frame beyond the scene itself, bytes: the facet methods'
  // pair, staging, scan and triangle-list buffers and facet tables; the cube map's faces; the
  // seed paper's Vbuf column.
  std::uint64_t gpu_buffer_bytes = 0;
  // Facet pipeline: outputs replicated a second time this frame because their pairs outgrew the
  // buffers sized from the frames before.
  std::uint64_t overflow_reruns = 0;
  // replicas / triangles_scene: draws per scene triangle, over all outputs, the seed paper's
  // replication ratio (its geometry shader took every scene triangle in), whatever a method
  // culls before.
  double replication_ratio() const {
    return triangles_scene == 0 ? 0.0 : double(replicas) / double(triangles_scene);
  }
};

class RenderMethod {
 public:
  virtual ~RenderMethod() = default;
  // "facets", "facets-gs", "tessellated", "cubemap", "perspective", "naive", "vertex", "glc",
  // "glc-2pass".
  virtual std::string_view name() const = 0;

  // Builds everything that depends only on the outputs and the scene: facets, matrices, cube
  // faces, lookup textures, programs. Needs a current context. Throws InputError for settings
  // that cannot work (for example a cube face size <= 0).
  virtual void prepare(const Scene& scene, const GpuScene& gpu_scene,
                       std::span<const OutputSpec> outputs, const RenderSettings& settings) = 0;

  // Renders one frame of every output into `targets` (one per output, same order, already
  // sized). T_eye_world maps world points (metres) into the eye frame of DESIGN.md. Passes are
  // timed with `timer` when it is given. Every call reads the objects' T_world_object and
  // bounds_world from the scene given to prepare (which must outlive the method): objects move
  // by changing both between frames (Session does, from FrameState::object_poses).
  virtual RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                             class GpuTimer* timer = nullptr) = 0;

  // The scene's triangles changed between frames (a view-dependent mesh rebuilt: the same
  // objects, materials and images, other vertices and indices): `scene` and `gpu_scene` (its
  // buffers replaced by replace_geometry) take the place of those given to prepare, with the
  // outputs and settings given there. What depends on the scene is rebuilt and the next frame runs
  // every pass (the facet methods' culling, lists and coverage, as for a moving scene); the facet
  // methods keep their facets, which depend only on the outputs. The default prepares anew.
  // Needs a current context.
  virtual void replace_scene(const Scene& scene, const GpuScene& gpu_scene,
                             std::span<const OutputSpec> outputs, const RenderSettings& settings);
};

// Every method name make_render_method accepts, in the order `facet bench` lists them.
std::span<const std::string_view> render_method_names();
// Whether the method draws GLC cameras (*.glc.json outputs), and only those: "glc" (the ray
// cast) and "glc-2pass" (the paper's two-pass rasterization).
bool is_glc_method(std::string_view name);
// Throws InputError(OptionName "method", ...) for an unknown name. Methods may make GL objects from
// the start: call with a current context (check_render_method checks a name without one).
std::unique_ptr<RenderMethod> make_render_method(std::string_view name);
// Throws make_render_method's InputError for a name it would reject; needs no GL context.
void check_render_method(std::string_view name);

// First triangle ID minus one of every object (see the numbering above), plus the total at the
// end: size objects + 1.
std::vector<std::uint32_t> scene_triangle_base(const Scene& scene);

}  // namespace facet::driver
