#include "material_programs.hpp"

#include <algorithm>
#include <glm/gtc/type_ptr.hpp>
#include <utility>

namespace facet::driver::detail {

void MaterialPrograms::prepare(const Scene& scene, const MaterialShader& render_shader,
                               const Link& link) {
  std::vector<MaterialShader> shaders{render_shader};
  std::vector<std::uint32_t> material_slot(scene.materials.size(), 0);
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    const auto& own = scene.materials[m].shader;
    if (!own) continue;
    const auto found = std::find(shaders.begin(), shaders.end(), *own);
    material_slot[m] = std::uint32_t(found - shaders.begin());
    if (found == shaders.end()) shaders.push_back(*own);
  }
  std::vector<Program> programs;
  programs.reserve(shaders.size());
  for (const MaterialShader& shader : shaders) {
    const auto linked = std::find(shaders_.begin(), shaders_.end(), shader);
    if (linked != shaders_.end() && programs_[std::size_t(linked - shaders_.begin())]) {
      programs.push_back(std::move(programs_[std::size_t(linked - shaders_.begin())]));
    } else {
      programs.push_back(link(shader));
    }
  }
  shaders_ = std::move(shaders);
  programs_ = std::move(programs);
  material_slot_ = std::move(material_slot);
}

void MaterialPrograms::clear() {
  shaders_.clear();
  programs_.clear();
  material_slot_.clear();
}

std::uint64_t draw_object_primitives(const Scene& scene, const GpuScene& gpu, std::size_t o,
                                     std::uint32_t first_id, const MaterialPrograms& programs,
                                     const Program*& in_use, GLenum mode,
                                     const std::function<void()>& send_object,
                                     std::uint32_t vertices_per_draw) {
  const Object& object = scene.objects[o];
  bool object_sent = false;
  std::uint32_t id = first_id;
  for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
    const Primitive& primitive = scene.primitives[object.first_primitive + k];
    const Program& program = programs.program_of(primitive.material);
    if (&program != in_use) {
      program.use();
      in_use = &program;
      object_sent = false;
    }
    if (!object_sent) send_object();
    object_sent = true;
    const Material& material = scene.materials.at(primitive.material);
    glUniform4fv(8, 1, glm::value_ptr(material.base_colour));
    glUniform1i(9, material.texture >= 0 ? 1 : 0);
    gpu.bind_material_texture(primitive.material, 0);
    glUniform1ui(2, primitive.first_index);
    glUniform1ui(3, id);
    const std::uint32_t per_draw = vertices_per_draw > 0
                                       ? vertices_per_draw
                                       : std::max<std::uint32_t>(primitive.index_count, 1);
    for (std::uint32_t first = 0; first < primitive.index_count; first += per_draw) {
      glDrawArrays(mode, GLint(first), GLsizei(std::min(per_draw, primitive.index_count - first)));
    }
    id += primitive.index_count / 3;
  }
  return id - first_id;
}

void begin_reversed_z_scene(bool cull_back_faces) {
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  if (cull_back_faces) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
  } else {
    glDisable(GL_CULL_FACE);
  }
}

void end_reversed_z_scene() {
  glDisable(GL_CULL_FACE);
  glDepthFunc(GL_LESS);
  glDisable(GL_DEPTH_TEST);
  glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
}

Program link_perspective_scene_program(const MaterialShader& shader, bool layered_cube) {
  ProgramBuilder builder;
  builder.define("WRITE_TRIANGLE_ID", "1")
      .define("CUBE_GS", layered_cube ? "1" : "0")
      .shader("baselines/cube_face.vert")
      .shader("baselines/pull_scene.vert");
  if (layered_cube) builder.shader("baselines/cube_face.geom");
  add_material_stages(builder, shader);
  return link_with_material(builder, shader);
}

}  // namespace facet::driver::detail
