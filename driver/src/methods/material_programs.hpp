#pragma once
// The draw programs of a render method, one per distinct material shader of a scene: the render's
// own (RenderSettings::material) and each scene material's Material::shader.
#include <cstdint>
#include <functional>
#include <vector>

#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/scene.hpp"

namespace facet::driver::detail {

class MaterialPrograms {
 public:
  // Links the program of `shader` with the method's other stages.
  using Link = std::function<Program(const MaterialShader& shader)>;

  // Slot 0 is `render_shader`; each distinct Material::shader of `scene` gets the next slot.
  // Programs of shaders linked before are kept; the others are linked with `link` (whose
  // InputError names a user's file that does not compile).
  void prepare(const Scene& scene, const MaterialShader& render_shader, const Link& link);
  // Forgets every program, so that the next prepare links all of them (the other stages changed).
  void clear();

  std::size_t size() const { return programs_.size(); }
  const Program& program(std::size_t slot) const { return programs_.at(slot); }
  // The slot that shades scene material m; slot 0 for an index beyond the scene's materials.
  std::uint32_t slot_of(std::uint32_t material) const {
    return material < material_slot_.size() ? material_slot_[material] : 0u;
  }
  const Program& program_of(std::uint32_t material) const {
    return programs_.at(slot_of(material));
  }

 private:
  std::vector<MaterialShader> shaders_;  // per slot
  std::vector<Program> programs_;        // per slot
  std::vector<std::uint32_t> material_slot_;
};

// Patches per draw on a software rasterizer (the tessellated form with the CPU's triangle list,
// the vertex method). llvmpipe's tessellation-evaluation stage (Mesa 22.3, draw_tess.c) grows its
// output vertex, index and length arrays by realloc once per patch of a batch of up to 1024
// vertices. Under ASan every realloc copies into fresh pages, so a batch costs time quadratic in
// its patches: in the ASan build, the bench of BenchCli.DepthImageLevelOfDetail... took 1,992 ms
// a frame for the tessellated form and 2,551 ms for the vertex method at tess=16, against 116
// and 102 ms in draws of 64. In the normal build draws of 64 cost the same or less (`facet bench
// --quick --scenario cylinder`, three runs each: tessellated 302-347 against 349-357 ms, vertex
// at tess=16 102-124 against 133-140 ms).
inline constexpr std::uint32_t kSoftwarePatchesPerDraw = 64;

// Draws scene object o's primitives, each with its material's program of `programs`, for the
// programs that pull the scene's vertices one primitive at a time (baselines/pull_scene.vert):
// uniform 2 is the primitive's first index, 3 its first triangle ID (IDs run from `first_id`), 8
// and 9 the material's base colour and whether it has a texture (bound to unit 0).
// `send_object` sets the object's own uniforms on the program in use, and is called again
// whenever the program changes; `in_use` carries the program in use from call to call (nullptr
// at first). `mode`: GL_TRIANGLES, or GL_PATCHES of three vertices for tessellation.
// `vertices_per_draw` > 0 splits each primitive into draws of at most that many vertices (a
// multiple of 3; kSoftwarePatchesPerDraw patches on a software rasterizer); 0 draws it whole.
// Returns the triangles drawn.
std::uint64_t draw_object_primitives(const Scene& scene, const GpuScene& gpu, std::size_t o,
                                     std::uint32_t first_id, const MaterialPrograms& programs,
                                     const Program*& in_use, GLenum mode,
                                     const std::function<void()>& send_object,
                                     std::uint32_t vertices_per_draw = 0);

// The depth convention of every scene pass: clip z in [0, 1] with the origin at the lower left,
// reversed Z (GL_GREATER against depth cleared to 0), and GL's back-face culling on exactly when
// `cull_back_faces` (the caller sets glFrontFace).
void begin_reversed_z_scene(bool cull_back_faces);
// GL's defaults again after a scene pass: clip z in [-1, 1], depth test off with GL_LESS, no face
// culling.
void end_reversed_z_scene();

// A perspective image of the scene shaded by `shader` (baselines/cube_face.vert pulling the
// scene's vertices, WRITE_TRIANGLE_ID 1): the cube map's faces, in one layered pass through
// baselines/cube_face.geom when `layered_cube`, and the perspective baseline's image.
Program link_perspective_scene_program(const MaterialShader& shader, bool layered_cube);

}  // namespace facet::driver::detail
