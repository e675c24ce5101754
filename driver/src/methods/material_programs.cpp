#include "material_programs.hpp"

#include <algorithm>
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

}  // namespace facet::driver::detail
