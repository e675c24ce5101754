// An application that draws its own pictures: for every projector of a display it asks facet for
// the projector's frustum (the narrowest perspective view that holds what it shows), renders
// that view itself with its own GL program, and hands the texture to facet, which resamples it
// through the projector's exact warp and applies the blend (mode 2, image through warp). The
// picture here is a latitude-longitude grid of the eye's sky with a turning colour wheel, so
// neighbouring projectors visibly line up.
//
//   own_perspective [--display NAME] [--frames N] [--out DIR]
//
// The display must be one whose projectors each see less than 160° (builtin:wall2x2 by
// default, a display.json, an MPCDI file); writes DIR/<output>_<frame>.png.
#include <epoxy/gl.h>

#include <cstdio>
#include <cstdlib>
#include <facet/facet.hpp>
#include <filesystem>
#include <glm/gtc/type_ptr.hpp>
#include <string>

namespace {

// A full-screen triangle whose fragments find their view direction from the frustum's tangents
// and colour it by the eye frame's latitude and longitude.
constexpr const char* kVertex = R"(#version 450 core
out vec2 tangents;
uniform vec4 tan_extent;  // left, right, top, bottom
void main() {
  vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);  // (0,0), (2,0), (0,2)
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
  tangents = vec2(mix(tan_extent.x, tan_extent.y, corner.x), mix(tan_extent.w, tan_extent.z, corner.y));
}
)";

constexpr const char* kFragment = R"(#version 450 core
in vec2 tangents;
out vec4 colour;
uniform mat3 R_eye_view;
uniform float turn;  // radians
const float PI = 3.14159265358979;
void main() {
  vec3 v = normalize(R_eye_view * vec3(tangents, -1.0));
  float latitude = asin(clamp(v.y, -1.0, 1.0));
  float longitude = atan(v.x, -v.z) + turn;
  vec3 hue = 0.5 + 0.5 * cos(longitude + vec3(0.0, 2.094, 4.189));
  vec2 grid = abs(fract(vec2(longitude, latitude) / radians(10.0) + 0.5) - 0.5) / fwidth(vec2(longitude, latitude) / radians(10.0));
  float line = 1.0 - clamp(min(grid.x, grid.y) - 0.5, 0.0, 1.0);
  colour = vec4(mix(0.35 * hue, vec3(1.0), line), 1.0);
}
)";

GLuint compile(GLenum stage, const char* text) {
  const GLuint shader = glCreateShader(stage);
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    std::fprintf(stderr, "shader: %s\n", log);
    std::exit(1);
  }
  return shader;
}

}  // namespace

int main(int argc, char** argv) try {
  std::string display_name = "builtin:wall2x2", out = "own_perspective_frames";
  int frames = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--display")
      display_name = argv[i + 1];
    else if (arg == "--frames")
      frames = std::stoi(argv[i + 1]);
    else if (arg == "--out")
      out = argv[i + 1];
    else {
      std::fprintf(stderr, "usage: %s [--display NAME] [--frames N] [--out DIR]\n", argv[0]);
      return 2;
    }
  }
  const facet::Display display = facet::Display::open(display_name);
  facet::Context context = facet::Context::headless();
  facet::Renderer renderer(display);  // no scene: only the warp and the blend

  // The application's own GL: a program, an empty vertex array, a texture and framebuffer per
  // projector at a size near the projector's.
  const GLuint program = glCreateProgram();
  glAttachShader(program, compile(GL_VERTEX_SHADER, kVertex));
  glAttachShader(program, compile(GL_FRAGMENT_SHADER, kFragment));
  glLinkProgram(program);
  GLuint vertex_array = 0;
  glCreateVertexArrays(1, &vertex_array);
  std::vector<GLuint> textures(display.output_count()), framebuffers(display.output_count());
  glCreateTextures(GL_TEXTURE_2D, GLsizei(textures.size()), textures.data());
  glCreateFramebuffers(GLsizei(framebuffers.size()), framebuffers.data());
  std::vector<facet::Display::Frustum> frusta;
  for (std::size_t o = 0; o < display.output_count(); ++o) {
    frusta.push_back(display.frustum(o));
    const glm::ivec2 size = display.output_size(o);
    glTextureStorage2D(textures[o], 1, GL_SRGB8_ALPHA8, size.x, size.y);
    glNamedFramebufferTexture(framebuffers[o], GL_COLOR_ATTACHMENT0, textures[o], 0);
    std::printf("%s: %dx%d, frustum tangents left %.3f right %.3f top %.3f bottom %.3f\n",
                display.output_name(o).c_str(), size.x, size.y, frusta[o].tan_extent[0],
                frusta[o].tan_extent[1], frusta[o].tan_extent[2], frusta[o].tan_extent[3]);
  }
  std::filesystem::create_directories(out);
  for (int frame = 0; frame < frames; ++frame) {
    for (std::size_t o = 0; o < display.output_count(); ++o) {
      // 1. The application renders the projector's frustum into its own texture.
      const glm::ivec2 size = display.output_size(o);
      glBindFramebuffer(GL_FRAMEBUFFER, framebuffers[o]);
      glViewport(0, 0, size.x, size.y);
      glEnable(GL_FRAMEBUFFER_SRGB);
      glUseProgram(program);
      const auto& t = frusta[o].tan_extent;
      glUniform4f(glGetUniformLocation(program, "tan_extent"), float(t[0]), float(t[1]),
                  float(t[2]), float(t[3]));
      const glm::mat3 R(frusta[o].R_eye_view);
      glUniformMatrix3fv(glGetUniformLocation(program, "R_eye_view"), 1, GL_FALSE,
                         glm::value_ptr(R));
      glUniform1f(glGetUniformLocation(program, "turn"), 0.3f * float(frame));
      glBindVertexArray(vertex_array);
      glDrawArrays(GL_TRIANGLES, 0, 3);
      glDisable(GL_FRAMEBUFFER_SRGB);
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      // 2. facet warps it into the projector's pixels and blends.
      renderer.warp_perspective(o, textures[o]);
      char name[64];
      std::snprintf(name, sizeof name, "%s_%03d.png", display.output_name(o).c_str(), frame);
      renderer.write_output_png(o, std::filesystem::path(out) / name);
    }
  }
  std::printf("frames written to %s\n", out.c_str());
  glDeleteFramebuffers(GLsizei(framebuffers.size()), framebuffers.data());
  glDeleteTextures(GLsizei(textures.size()), textures.data());
  glDeleteVertexArrays(1, &vertex_array);
  glDeleteProgram(program);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "own_perspective: %s\n", e.what());
  return 2;
}
