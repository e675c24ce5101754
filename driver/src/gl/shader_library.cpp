#include "facet/driver/shader_library.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace facet::driver {

const EmbeddedShader& embedded_shader(std::string_view name) {
  const auto shaders = embedded_shaders();
  const auto it =
      std::lower_bound(shaders.begin(), shaders.end(), name,
                       [](const EmbeddedShader& s, std::string_view n) { return s.name < n; });
  if (it == shaders.end() || it->name != name)
    throw std::out_of_range("embedded_shader: no shader named '" + std::string(name) +
                            "' was embedded (is the file under shaders/?)");
  return *it;
}

}  // namespace facet::driver
