#pragma once
// facet's application API: show an application's scene, or its own images, on a projector
// display (dome, cylinder, wall) through each projector's exact warp, blended.
//
//   facet::Display display = facet::Display::open("builtin:dome180");  // or a display.json
//   facet::Context context = facet::Context::headless();  // or Context::borrow_current()
//   facet::SceneBuilder builder;                           // or Scene::load("model.glb")
//   const int red = builder.add_material({.base_colour = {1, 0, 0, 1}});
//   const int mesh = builder.add_mesh({positions, normals, uvs, indices}, red);
//   const facet::ObjectId ball = builder.add_object(mesh, T_world_ball);
//   facet::Renderer renderer(display, std::move(builder).build());
//   for (each frame) {
//     renderer.set_frame({.frame = n, .time_s = t, .T_world_eye = eye_pose});
//     renderer.set_object_transform(ball, T_world_ball_now);
//     renderer.render();                          // every output, blended
//     renderer.output_texture(0);                 // hand the texture on, or:
//     renderer.present(0, {0, 0, width, height});  // draw it into the current framebuffer
//   }
//
// Frames and units. The world frame is the scene's, in metres, y up (as glTF). The eye frame
// has x right, y up and looks down -z; T_world_eye places it in the world. T_a_b maps points of
// frame b into frame a; matrices are glm's (column-major), affine. Output images are the
// projector's pixels: size as the display says, row 0 at the top when read into memory (GL
// textures keep GL's convention, row 0 at the bottom).
//
// Threads and GL. Every call that touches GL (Renderer's, Context's) needs the context it was
// made with current on the calling thread. facet makes no context current behind the caller's
// back, except that Context::headless() and Context::window() make their new context current.
// Renderer calls leave the framebuffer bindings and the viewport as they found them; other GL
// state (program, vertex array, textures, depth, blending, culling) is left as facet's passes
// set it, so an application that draws in the same context sets what it relies on.
//
// Errors. Bad input (a file, a field, an index, a size) throws facet::InputError, whose message
// names the file or argument, the field and what was expected; no GL context throws
// facet::ContextError. Both derive from std::runtime_error.
#include <array>
#include <cstdint>
#include <filesystem>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "facet/projection/errors.hpp"  // facet::InputError

namespace facet {

struct ContentProjection;
namespace driver {
struct Scene;
struct SessionDisplay;
class Session;
class GlContext;
}  // namespace driver

// No OpenGL 4.5 core context could be made or found.
class ContextError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// ---- Display ------------------------------------------------------------------------------

// The projectors of a display: each one's exact warp, blend and black-level maps and encoding.
class Display {
 public:
  // Opens `name`:
  // - "builtin:dome180", "builtin:cylinder360", "builtin:wall2x2": analytic displays; `size`
  //   sets every output's size (default: each built-in's own);
  // - a display.json (its warps, blends, black levels, gammas, render method and tolerance);
  // - a single ".warp.exr" (one projector, no blend);
  // - an imported calibration: an MPCDI container (".mpcdi", profiles 2d, 3d, a3) or an SGCT
  //   cluster configuration (".xml") with its SCISS or SimCAD meshes and masks.
  // InputError for anything else, naming the file or field.
  static Display open(const std::string& name, std::optional<glm::ivec2> size = std::nullopt);

  std::size_t output_count() const;
  std::string output_name(std::size_t output) const;
  glm::ivec2 output_size(std::size_t output) const;  // pixels

  // How scenes are rendered into every output: "facets" (default; piecewise perspective
  // replication, the best quality), "facets-gs", "tessellated", "cubemap", "perspective" (one
  // perspective image per output: projectors and views narrower than 160°), "naive", "vertex".
  // InputError for another name.
  void set_method(const std::string& method);
  const std::string& method() const;
  // facets methods: the largest error of the piecewise perspective pieces, in output pixels
  // (> 0; 0.25 by default).
  void set_tolerance_px(double tolerance_px);
  // The fragment shading of every output (the CLI's --material): "lit" (the default),
  // "solid-wireframe", "pen-and-ink", "procedural", or a GLSL file (".frag") defining
  // `vec4 shade(MaterialInput m)` against facet's material interface (world position, normal,
  // uv, barycentrics and edge distances in output pixels, eye distance, base colour and
  // texture; shaders/scene/material_interface.frag, installed as
  // share/facet/material_interface.frag). Triangle IDs and depth never depend on it, and the
  // replication never sees it. InputError for an unknown name or a file that is missing, over
  // 1 MiB, or uses discard or gl_FragDepth; a file that does not compile is an InputError from
  // the Renderer's constructor, naming its line.
  void set_material_shader(const std::string& name_or_file);
  // Every output's size and warp scaled by `factor` in (0, 1], for previews.
  void scale(double factor);

  // The narrowest perspective view that holds every direction output `output` shows: an
  // application renders exactly this for Renderer::warp_perspective. R_eye_view rotates the
  // view's frame (x right, y up, looking down -z) into the eye frame; tan_extent is the tangents
  // of the image's left, right, top and bottom edges in that frame.
  struct Frustum {
    glm::dmat3 R_eye_view{1.0};
    std::array<double, 4> tan_extent{-1.0, 1.0, 1.0, -1.0};
    // The OpenGL projection matrix (clip z in [-w, w]) for near and far distances in metres,
    // 0 < z_near < z_far. Render with projection · view, where the view matrix is
    // inverse(T_world_eye · R_eye_view) for the current eye pose.
    glm::dmat4 projection(double z_near, double z_far) const;
  };
  Frustum frustum(std::size_t output) const;

 private:
  friend class Renderer;
  std::shared_ptr<driver::SessionDisplay> display_;
};

// ---- Scene ----------------------------------------------------------------------------------

// An object of a scene: its index in the order objects were added (glTF: the order nodes with a
// mesh are met, depth first). Triangle IDs (Renderer::read_output_ids) count triangles in this
// order.
using ObjectId = std::uint32_t;

// A scene as facet draws it: triangle meshes placed by objects, with materials and textures.
// Cheap to copy (shared, immutable).
class Scene {
 public:
  // A glTF 2.0 file (.gltf or .glb), its animations included (they play by frame time), or a
  // built-in ("builtin:city", "builtin:city:K", "builtin:city-fine:N").
  static Scene load(const std::string& name);

  std::size_t object_count() const;
  std::size_t triangle_count() const;  // counting every object's instance
  // The object named `name` (the first of that name), or nullopt.
  std::optional<ObjectId> find_object(std::string_view name) const;
  // The box around every object at its starting pose, world frame, metres.
  std::pair<glm::vec3, glm::vec3> bounds_world() const;

 private:
  friend class SceneBuilder;
  friend class Renderer;
  std::shared_ptr<const driver::Scene> scene_;
};

// The application's own arrays, copied in. Counter-clockwise triangles face their viewer.
struct MeshData {
  std::span<const glm::vec3> positions;    // object frame, metres
  std::span<const glm::vec3> normals;      // unit, one per position; empty: computed per vertex
  std::span<const glm::vec2> uvs;          // one per position, (0,0) the texture's first texel of
                                           // its top row; empty: all (0,0)
  std::span<const std::uint32_t> indices;  // triangle list; a multiple of 3, each < positions
};

// An RGBA8 image, rows from the top, sRGB-encoded colour with linear alpha.
struct TextureData {
  int width = 0, height = 0;           // 1 to 16,384 each
  std::span<const std::uint8_t> rgba;  // width · height · 4 bytes
};

struct MaterialData {
  glm::vec4 base_colour{1.0f};  // linear RGBA, multiplied with the texture
  int texture = -1;             // SceneBuilder::add_texture's index, or -1
  bool repeat = true;           // texture coordinates wrap (else clamp to edge)
  bool unlit = false;           // shown as authored (no lighting)
  // Its own shading: empty for the Display's (set_material_shader), else a built-in material's
  // name or a GLSL file (".frag") defining `vec4 shade(MaterialInput m)`, as there. A file that
  // does not compile is an InputError from the Renderer's constructor, naming its line.
  std::string shader{};
};

// Builds a Scene from the application's arrays: no file needed. Indices returned are 0, 1, 2, ...
// in the order of the calls of each kind.
class SceneBuilder {
 public:
  SceneBuilder();
  ~SceneBuilder();
  SceneBuilder(SceneBuilder&&) noexcept;
  SceneBuilder& operator=(SceneBuilder&&) noexcept;

  int add_texture(const TextureData& texture);
  int add_material(const MaterialData& material);
  // One mesh drawn with one material; InputError for mismatched arrays, indices out of range,
  // non-finite positions or an unknown material.
  int add_mesh(const MeshData& mesh, int material);
  // Places mesh `mesh` in the world (several objects may share a mesh).
  ObjectId add_object(int mesh, const glm::dmat4& T_world_object, const std::string& name = {});

  // The scene, with every object's bounds; the builder is left empty.
  Scene build() &&;

 private:
  std::unique_ptr<driver::Scene> scene_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> meshes_;  // primitive of each mesh
};

// ---- GL context --------------------------------------------------------------------------------

// The OpenGL 4.5 core context facet renders with.
class Context {
 public:
  // A new headless context (EGL: a GPU device, else Mesa's surfaceless llvmpipe), made current
  // on this thread. Outputs are rendered into textures; nothing is shown.
  static Context headless();
  // A window of `size` pixels (GLFW, needs a display server: ContextError without one), its
  // context current on this thread. Renderer::present draws into it; swap() shows it.
  static Context window(glm::ivec2 size, const std::string& title = "facet");
  // The application's context, current on this thread now: facet uses it and never makes
  // another current. ContextError when none is current or it is older than GL 4.5 core.
  static Context borrow_current();

  Context(Context&&) noexcept;
  Context& operator=(Context&&) noexcept;
  ~Context();

  void make_current();  // headless and window contexts only; a borrowed one stays the app's
  bool is_borrowed() const;
  // Window contexts: shows the frame, handles window events; true once the user closed it.
  void swap();
  bool should_close() const;
  std::string renderer() const;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

 private:
  Context() = default;
  std::unique_ptr<driver::GlContext> owned_;
  bool borrowed_ = false;
};

// ---- Rendering ---------------------------------------------------------------------------------

// An object's pose for one frame (see FrameInfo).
struct ObjectTransform {
  ObjectId object = 0;
  glm::dmat4 T_world_object{1.0};  // affine
};

// Everything one frame depends on.
struct FrameInfo {
  std::uint64_t frame = 0;
  double time_s = 0;            // scene time: drives the scene's own (glTF) animations
  glm::dmat4 T_world_eye{1.0};  // the viewer's eye, rigid
};

struct OutputReport {
  std::string name;
  bool rendered = false;           // false: this output sees nothing, it was only cleared
  std::uint64_t triangles_in = 0;  // triangles of the objects that may be seen
  std::uint64_t replicas = 0;      // triangle draws (facets methods: one per facet covered)
  bool reused_coverage = false;    // nothing moved: the facet coverage of the last frame served
};

struct FrameReport {
  std::uint64_t frame = 0;
  double cpu_ms = 0;  // wall time of render()
  std::vector<OutputReport> outputs;
};

// Renders a scene into every output of a display, then each output's blend and black level.
// Made and used with one context current (the one current at construction).
class Renderer {
 public:
  // Uploads `scene` and prepares `display`'s method for every output. InputError for a display
  // or method that cannot work; ContextError when no context is current.
  Renderer(const Display& display, const Scene& scene);
  // Mode 2 only (warp_perspective and friends): no scene.
  explicit Renderer(const Display& display);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // The eye pose and time of the next render.
  void set_frame(const FrameInfo& frame);
  // Moves object `object` for this and later frames (it stays until moved again or reset);
  // InputError for an object the scene lacks. reset_object_transform returns it to the scene's
  // own pose (its animation, else where it was built).
  void set_object_transform(ObjectId object, const glm::dmat4& T_world_object);
  void reset_object_transform(ObjectId object);

  // Renders every output that can see part of the scene with the display's method, then blends
  // every output. With `finish`, waits for the GPU so cpu_ms is the whole frame.
  FrameReport render(bool finish = false);

  // Mode 2, image through warp: the application rendered `frustum(output)` of the display into
  // `texture` (a 2D GL texture, RGBA8 or SRGB8_ALPHA8, sRGB-encoded, of any size, in the
  // context's share group); facet resamples it through the exact warp into the output (mip-
  // mapped, in linear light) and blends. The texture is copied, not kept.
  void warp_perspective(std::size_t output, unsigned int texture);
  // Mode 2 for content of the whole view, into every output: a dome master (fisheye of
  // `fisheye_fov_deg` in (0, 360], its centre the zenith and its bottom edge the front) or an
  // equirectangular 360° x 180° panorama (its middle column straight ahead, -z), as a 2D texture
  // like warp_perspective's. Not for a Renderer with a scene.
  enum class ImageKind { fisheye, equirect };
  void warp_image(unsigned int texture, ImageKind kind, double fisheye_fov_deg = 180);
  // Mode 2 for a cube map of the whole view, into every output: `texture` is a GL cube-map
  // texture (RGBA8 or SRGB8_ALPHA8, sRGB-encoded, square faces) in the eye frame (x right, y up,
  // -z ahead), its faces as GL samples them (OpenGL 4.5 §8.13, table 8.19): what the
  // application's own texture(samplerCube, v_eye) returns for an eye direction v_eye is what that
  // direction shows. Copied, not kept. Not for a Renderer with a scene.
  void warp_cubemap(unsigned int texture);

  std::size_t output_count() const;
  glm::ivec2 output_size(std::size_t output) const;
  // The output's finished image as a GL texture name: SRGB8_ALPHA8, blended and encoded for the
  // projector (sample it with GL_FRAMEBUFFER_SRGB off, or through an RGBA8 view, to get the
  // projector's bytes). Owned by the renderer; valid until it is destroyed.
  unsigned int output_texture(std::size_t output) const;
  // Draws the output's bytes, unscaled if the sizes agree, into `viewport` (x, y, width,
  // height; GL's origin at the bottom left) of the currently bound draw framebuffer.
  void present(std::size_t output, const glm::ivec4& viewport) const;
  // Reads the output back: RGBA8 bytes as sent to the projector, row 0 at the top.
  std::vector<std::uint8_t> read_output_rgba8(std::size_t output) const;
  // Triangle IDs of the last render(): 0 where nothing was drawn, else 1 + the triangle's index
  // counting every object's triangles in ObjectId order; row 0 at the top.
  std::vector<std::uint32_t> read_output_ids(std::size_t output) const;
  // Writes read_output_rgba8 as a PNG (under a temporary name, renamed when complete).
  void write_output_png(std::size_t output, const std::filesystem::path& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  void warp_content(const std::vector<std::size_t>& outputs, unsigned int texture,
                    const ContentProjection& projection, std::size_t key,
                    const std::string& source);
  // Content of the whole view (a dome master, a panorama, a cube map) into every output.
  void warp_whole_view(unsigned int texture, const ContentProjection& projection,
                       const std::string& source);
};

}  // namespace facet
