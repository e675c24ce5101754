#include "facet/driver/blend_pass.hpp"

#include <algorithm>

#include "../gl/image_rows.hpp"
#include "facet/driver/program.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {

namespace {

// RGB float texture in GL row order from an image-order map with 1 or 3 channels.
Texture upload_map(glm::ivec2 size, int channels, const std::vector<float>& values) {
  std::vector<float> rgb(std::size_t(size.x) * size.y * 3);
  for (int y = 0; y < size.y; ++y) {
    const int gl_row = flipped_row(y, size.y);
    for (int x = 0; x < size.x; ++x) {
      const std::size_t from = (std::size_t(y) * size.x + x) * channels;
      const std::size_t to = (std::size_t(gl_row) * size.x + x) * 3;
      for (int c = 0; c < 3; ++c) rgb[to + c] = values[from + (channels == 3 ? c : 0)];
    }
  }
  Texture texture = Texture::create_2d(GL_RGB32F, size.x, size.y);
  glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(texture.id(), 0, 0, 0, size.x, size.y, GL_RGB, GL_FLOAT, rgb.data());
  return texture;
}

}  // namespace

std::vector<glm::uvec2> BlendPass::tiles_needing_work(glm::ivec2 output_size, const BlendMaps& maps,
                                                      OutputEncoding encoding) {
  const int tiles_x = (output_size.x + kTile - 1) / kTile;
  const int tiles_y = (output_size.y + kTile - 1) / kTile;
  std::vector<glm::uvec2> tiles;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      bool needs_work = encoding.gamma.has_value();
      // Tiles are in GL rows (from the bottom); the maps are in image rows (from the top).
      for (int gy = ty * kTile; !needs_work && gy < std::min(output_size.y, (ty + 1) * kTile);
           ++gy) {
        const std::size_t row = flipped_row_start(gy, output_size.y, output_size.x);
        for (int x = tx * kTile; !needs_work && x < std::min(output_size.x, (tx + 1) * kTile);
             ++x) {
          for (int c = 0; c < maps.channels; ++c) {
            const std::size_t i = (row + x) * maps.channels + c;
            if ((!maps.alpha.empty() && !(maps.alpha[i] >= 1.0f)) ||
                (!maps.black.empty() && !(maps.black[i] <= 0.0f)))
              needs_work = true;
          }
        }
      }
      if (needs_work) tiles.emplace_back(tx * kTile, ty * kTile);
    }
  }
  return tiles;
}

BlendPass::BlendPass(glm::ivec2 output_size, const BlendMaps& maps, OutputEncoding encoding)
    : size_(output_size), encoding_(encoding), has_black_(!maps.black.empty()) {
  const std::size_t values = std::size_t(output_size.x) * output_size.y * maps.channels;
  FACET_ASSERT(maps.channels == 1 || maps.channels == 3);
  FACET_ASSERT(maps.alpha.empty() || (maps.size == output_size && maps.alpha.size() == values));
  FACET_ASSERT(maps.black.empty() || (maps.size == output_size && maps.black.size() == values));
  FACET_ASSERT(!encoding.gamma || *encoding.gamma > 0);

  const std::vector<glm::uvec2> tiles = tiles_needing_work(output_size, maps, encoding);
  tile_count_ = tiles.size();
  if (tile_count_ == 0) return;
  tiles_ = Buffer::create_from(tiles, 0);
  const std::vector<float> ones(std::size_t(output_size.x) * output_size.y, 1.0f);
  alpha_ = maps.alpha.empty() ? upload_map(output_size, 1, ones)
                              : upload_map(output_size, maps.channels, maps.alpha);
  if (has_black_) black_ = upload_map(output_size, maps.channels, maps.black);
  program_ = ProgramBuilder()
                 .shader("output/blend.comp")
                 .define("TILE", kTile)
                 .define("POWER_ENCODING", encoding.gamma ? 1 : 0)
                 .define("HAS_BLACK", has_black_ ? 1 : 0)
                 .link();
}

std::size_t BlendPass::tiles_total() const {
  return std::size_t((size_.x + kTile - 1) / kTile) * ((size_.y + kTile - 1) / kTile);
}

void BlendPass::apply(const Texture& colour) const {
  if (tile_count_ == 0) return;
  if (viewed_ != colour.id()) {
    raw_view_ = Texture::create_view(colour, GL_RGBA8);
    viewed_ = colour.id();
  }
  program_.use();
  if (encoding_.gamma) glUniform1f(0, float(1.0 / *encoding_.gamma));
  glBindImageTexture(0, raw_view_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA8);
  alpha_.bind_unit(0);
  if (has_black_) black_.bind_unit(1);
  tiles_.bind_base(GL_SHADER_STORAGE_BUFFER, 0);
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
  glDispatchCompute(GLuint(tile_count_), 1, 1);
  // Later readers (blits, reads, presentation) see the stores.
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA8);
}

}  // namespace facet::driver
