// Uploading scenes and drawing them with the shared material shader: the city seen from its
// camera path fills the view, and its triangles face outwards (back-face culling removes none of
// the visible surface).
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <vector>

#include "facet/driver/city.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "gl_test_context.hpp"

namespace facet::driver {
namespace {

constexpr int width = 96, height = 64;

// Draws `scene` from `T_world_eye` with a 90 degree horizontal field of view; returns the RGBA
// float image (rows from the bottom).
std::vector<float> draw(const Scene& scene, const GpuScene& gpu, const Program& program,
                        const glm::mat4& T_world_eye, bool cull_back_faces) {
  Texture colour = Texture::create_2d(GL_RGBA16F, width, height);
  Renderbuffer depth = Renderbuffer::create(GL_DEPTH_COMPONENT32F, width, height);
  Framebuffer fbo = Framebuffer::create();
  fbo.attach(GL_COLOR_ATTACHMENT0, colour);
  fbo.attach(GL_DEPTH_ATTACHMENT, depth);
  fbo.check_complete();
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
  glViewport(0, 0, width, height);
  const float clear[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, clear);
  glClearNamedFramebufferfi(fbo.id(), GL_DEPTH_STENCIL, 0, 1.0f, 0);
  glEnable(GL_DEPTH_TEST);
  if (cull_back_faces) glEnable(GL_CULL_FACE);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  // 90 degrees horizontally: tan(45°) = 1 across half the width.
  const float vertical_fov = 2.0f * std::atan(1.0f / aspect);
  const glm::mat4 projection = glm::perspective(vertical_fov, aspect, 0.5f, 2000.0f);
  const glm::mat4 T_eye_world = glm::inverse(T_world_eye);
  program.use();
  glBindVertexArray(gpu.vertex_array.id());
  for (const Object& object : scene.objects) {
    const glm::mat4 T_clip_object = projection * T_eye_world * object.T_world_object;
    glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(T_clip_object));
    glUniformMatrix4fv(1, 1, GL_FALSE, glm::value_ptr(object.T_world_object));
    for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
      const Primitive& p = scene.primitives[object.first_primitive + k];
      const Material& m = scene.materials[p.material];
      glUniform4fv(8, 1, glm::value_ptr(m.base_colour));
      glUniform1i(9, m.texture >= 0 ? 1 : 0);
      gpu.bind_material_texture(p.material, 0);
      glDrawElements(
          GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
          reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u));
    }
  }
  glBindVertexArray(0);
  glDisable(GL_CULL_FACE);
  glDisable(GL_DEPTH_TEST);
  std::vector<float> pixels(static_cast<std::size_t>(width * height * 4));
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, pixels.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl_error("draw");
  return pixels;
}

TEST(SceneRender, CityFromTheCameraPath) {
  test::shared_context();
  CityOptions options;
  options.texture_size = 32;  // small textures keep llvmpipe quick; geometry is unchanged
  const Scene scene = build_city(options);
  const GpuScene gpu = upload_scene(scene);
  EXPECT_EQ(gpu.positions.size(), scene.positions.size() * sizeof(glm::vec3));
  EXPECT_EQ(gpu.indices.size(), scene.indices.size() * sizeof(std::uint32_t));
  EXPECT_EQ(gpu.textures.size(), scene.images.size());
  EXPECT_EQ(gpu.objects.size(), scene.objects.size() * sizeof(GpuObject));
  ProgramBuilder builder;
  builder.shader("scene/mesh.vert");
  add_material_stages(builder, MaterialShader{});
  const Program program = builder.link();
  const CityCameraPath path(options);
  const glm::mat4 T_world_eye(path.T_world_eye(0.3 * path.period_s()));

  const std::vector<float> plain = draw(scene, gpu, program, T_world_eye, false);
  const std::vector<float> culled = draw(scene, gpu, program, T_world_eye, true);
  int covered = 0, covered_culled = 0, lower_half_covered = 0;
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      const std::size_t at = static_cast<std::size_t>((j * width + i) * 4);
      const bool hit = plain[at + 3] > 0.5f;
      covered += hit;
      covered_culled += culled[at + 3] > 0.5f;
      if (j < height / 2) lower_half_covered += hit;
      if (hit) {
        // Shaded colours are finite and in the range the material shader can produce.
        ASSERT_TRUE(plain[at] >= 0.0f && plain[at] <= 1.5f) << i << "," << j;
      }
    }
  // At street level the ground fills the lower half (the horizon is the middle row), and
  // buildings rise above it; the sky stays empty.
  EXPECT_EQ(lower_half_covered, width * (height / 2));
  EXPECT_GT(covered, width * height * 6 / 10);
  EXPECT_LT(covered, width * height);
  // Every visible surface faces the eye: culling back faces changes at most 0.5% of pixels.
  EXPECT_NEAR(covered_culled, covered, width * height / 200);
}

}  // namespace
}  // namespace facet::driver
