#include "pixel_lookup.hpp"

#include <cmath>
#include <vector>

#include "../gl/image_rows.hpp"
#include "facet/projection/warp_inverse.hpp"

namespace facet::driver::detail {

Texture pixel_lookup_texture(
    const Warp& warp,
    const std::function<std::optional<glm::vec4>(const glm::dvec3& v_eye)>& value) {
  const WarpInverse inverse(warp);
  const glm::ivec2 size = warp.output_size;
  const auto st = inverse.st_at_pixel_centres();
  std::vector<glm::vec4> lookup(st.size(), glm::vec4(0));
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const glm::dvec2 s = st[std::size_t(y) * size.x + x];
      if (std::isnan(s.x)) continue;
      if (const auto texel = value(warp.v_eye_from_st(s)))
        lookup[flipped_row_start(y, size.y, size.x) + x] = *texel;
    }
  }
  Texture texture = Texture::create_2d(GL_RGBA32F, size.x, size.y);
  glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureSubImage2D(texture.id(), 0, 0, 0, size.x, size.y, GL_RGBA, GL_FLOAT, lookup.data());
  return texture;
}

}  // namespace facet::driver::detail
