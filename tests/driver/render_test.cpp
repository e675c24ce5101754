// Rendering into float framebuffers and computing into SSBOs, read back and checked exactly
// enough to catch wrong pipelines but not rasterizer rounding.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "facet/driver/gl_objects.hpp"
#include "facet/driver/program.hpp"
#include "gl_test_context.hpp"

namespace facet::driver {
namespace {

struct Vertex {
  float x, y;        // normalised device coordinates
  float r, g, b, a;  // colour
};

TEST(Render, Rgba32fTriangleReadsBackExpectedPixels) {
  test::shared_context();
  constexpr int width = 32, height = 24;
  // Red, green and blue corners at the lower-left, lower-right and upper-left of the target:
  // the triangle covers the pixels below the diagonal from (w,0) to (0,h) in GL's bottom-up
  // window coordinates.
  const std::array<Vertex, 3> vertices = {
      {{-1, -1, 1, 0, 0, 1}, {1, -1, 0, 1, 0, 1}, {-1, 1, 0, 0, 1, 1}}};
  Buffer vbo = Buffer::create_from(vertices);
  VertexArray vao = VertexArray::create();
  glVertexArrayVertexBuffer(vao.id(), 0, vbo.id(), 0, sizeof(Vertex));
  glEnableVertexArrayAttrib(vao.id(), 0);
  glEnableVertexArrayAttrib(vao.id(), 1);
  glVertexArrayAttribFormat(vao.id(), 0, 2, GL_FLOAT, GL_FALSE, offsetof(Vertex, x));
  glVertexArrayAttribFormat(vao.id(), 1, 4, GL_FLOAT, GL_FALSE, offsetof(Vertex, r));
  glVertexArrayAttribBinding(vao.id(), 0, 0);
  glVertexArrayAttribBinding(vao.id(), 1, 0);

  Texture colour = Texture::create_2d(GL_RGBA32F, width, height);
  Framebuffer fbo = Framebuffer::create();
  fbo.attach(GL_COLOR_ATTACHMENT0, colour);
  fbo.check_complete();

  // The scale define checks that caller defines reach the shader.
  constexpr float scale = 0.5f;
  Program program = ProgramBuilder()
                        .shader("test/triangle.vert")
                        .shader("test/triangle.frag")
                        .define("TEST_COLOUR_SCALE", "0.5")
                        .link();

  glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
  glViewport(0, 0, width, height);
  const float background[4] = {0.25f, -1.0f, 7.0f, 0.0f};  // float target: no clamping
  glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, background);
  program.use();
  glBindVertexArray(vao.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);

  std::vector<float> pixels(static_cast<std::size_t>(width * height * 4));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, pixels.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl_error("Rgba32fTriangle");

  // Interpolated colours agree with barycentric weights to float precision; 1e-4 allows for the
  // rasterizer's fixed-point sample positions and attribute interpolation.
  constexpr float tolerance = 1e-4f;
  int inside = 0, outside = 0;
  for (int j = 0; j < height; ++j) {
    for (int i = 0; i < width; ++i) {
      // Pixel centre in NDC, rows from the bottom as glReadPixels returns them.
      const float x = (static_cast<float>(i) + 0.5f) / width * 2.0f - 1.0f;
      const float y = (static_cast<float>(j) + 0.5f) / height * 2.0f - 1.0f;
      const float* px = &pixels[static_cast<std::size_t>((j * width + i) * 4)];
      // Signed distance of the centre from the hypotenuse x + y = 0, in pixels (roughly).
      const float margin = -(x + y) * 0.5f * static_cast<float>(std::min(width, height));
      if (std::abs(margin) < 1.0f) continue;  // edge pixels depend on the fill rule only
      if (margin > 0) {
        ++inside;
        // Barycentric weights of the red (-1,-1), green (1,-1) and blue (-1,1) corners.
        const float w_green = (x + 1) / 2, w_blue = (y + 1) / 2, w_red = 1 - w_green - w_blue;
        EXPECT_NEAR(px[0], scale * w_red, tolerance) << "pixel " << i << "," << j;
        EXPECT_NEAR(px[1], scale * w_green, tolerance) << "pixel " << i << "," << j;
        EXPECT_NEAR(px[2], scale * w_blue, tolerance) << "pixel " << i << "," << j;
        EXPECT_NEAR(px[3], scale, tolerance) << "pixel " << i << "," << j;
      } else {
        ++outside;
        for (int c = 0; c < 4; ++c) EXPECT_EQ(px[c], background[c]) << "pixel " << i << "," << j;
      }
    }
  }
  EXPECT_GT(inside, width * height / 3);
  EXPECT_GT(outside, width * height / 3);
}

TEST(Compute, ShaderWritesSsbo) {
  test::shared_context();
  constexpr GLuint count = 1000;  // not a multiple of the work group size: tests the bound check
  constexpr GLuint offset = 7;
  constexpr GLuint sentinel = 0xdeadbeefu;
  std::vector<GLuint> initial(count + 1, sentinel);
  Buffer values = Buffer::create_from(initial);
  Program program = ProgramBuilder().shader("test/fill_ssbo.comp").link();
  program.use();
  glUniform1ui(0, count);
  glUniform1ui(1, offset);
  values.bind_base(GL_SHADER_STORAGE_BUFFER, 0);
  glDispatchCompute((count + 63) / 64, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<GLuint> result(count + 1);
  values.get_sub_data(0, result.size() * sizeof(GLuint), result.data());
  check_gl_error("ShaderWritesSsbo");
  for (GLuint i = 0; i < count; ++i) ASSERT_EQ(result[i], i * i + offset) << "index " << i;
  EXPECT_EQ(result[count], sentinel) << "the shader wrote past its count";
}

}  // namespace
}  // namespace facet::driver
