#pragma once
// GLSL sources embedded into the binary at build time (see driver/cmake/FacetShaders.cmake).
//
// Every file under shaders/ with a stage extension (.vert .frag .comp .geom .tesc .tese) is
// validated by glslangValidator during the build and compiled into facet_driver as text, so the
// runtime never reads shader files. A shader is named by its path relative to shaders/, for
// example "scene/mesh.vert".
#include <span>
#include <string_view>

namespace facet::driver {

struct EmbeddedShader {
  std::string_view name;  // path relative to shaders/, with '/' separators
  std::string_view text;  // the file's bytes, unchanged
};

// All embedded shaders, sorted by name.
std::span<const EmbeddedShader> embedded_shaders();

// The shader with this name. Throws std::out_of_range (a programmer error: the names are fixed at
// build time) naming the shader when there is none.
const EmbeddedShader& embedded_shader(std::string_view name);

}  // namespace facet::driver
