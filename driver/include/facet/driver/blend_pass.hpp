#pragma once
// The blend and black-level pass of one projector output (DESIGN.md "Blending", FORMATS.md §3).
// It runs after the scene is drawn, pixel for pixel in place on the output's colour texture, so
// it never resamples the scene: out = c·α·(1−β) + β in linear light, then the projector's
// encoding. Only 16×16 tiles that hold a weight below 1 or a black level above 0 are touched;
// an output encoded with a power-law gamma needs every pixel re-encoded (the colour target holds
// sRGB), so there every tile is listed.
#include <cstddef>
#include <cstdint>
#include <glm/vec2.hpp>
#include <optional>
#include <vector>

#include "facet/driver/gl_objects.hpp"

namespace facet::driver {

// How an output turns linear light into the values sent to the projector.
struct OutputEncoding {
  // nullopt: the sRGB transfer function, which the colour target already applies; otherwise
  // value = linear^(1/gamma).
  std::optional<double> gamma;

  bool operator==(const OutputEncoding&) const = default;
};

// Per-pixel maps in linear light, row 0 at the top (image order), `channels` floats per pixel
// (1: one weight for all colours; 3: RGB).
struct BlendMaps {
  glm::ivec2 size{0, 0};
  int channels = 1;
  std::vector<float> alpha;  // weight α in [0,1]; empty: 1 everywhere
  std::vector<float> black;  // black level β in [0,1]; empty: 0 everywhere
};

class BlendPass {
 public:
  static constexpr int kTile = 16;

  BlendPass() = default;
  // Validates the maps against `output_size` (FACET_ASSERT: sizes and channel counts are the
  // caller's to check when reading files), lists the tiles that need work and uploads the maps.
  // Needs a current context.
  BlendPass(glm::ivec2 output_size, const BlendMaps& maps, OutputEncoding encoding);

  // Applies the pass in place to `colour` (SRGB8_ALPHA8 with immutable storage, output_size).
  // Does nothing when no tile needs work.
  void apply(const Texture& colour) const;

  std::size_t tiles_listed() const { return tile_count_; }
  std::size_t tiles_total() const;
  bool touches_nothing() const { return tile_count_ == 0; }

  // The tile origins (GL row order: pixel of each tile's lower-left corner) that need work:
  // exposed for tests and statistics.
  static std::vector<glm::uvec2> tiles_needing_work(glm::ivec2 output_size, const BlendMaps& maps,
                                                    OutputEncoding encoding);

 private:
  glm::ivec2 size_{0, 0};
  OutputEncoding encoding_;
  bool has_black_ = false;
  std::size_t tile_count_ = 0;
  Buffer tiles_;
  Texture alpha_, black_;
  Program program_;
  // The RGBA8 view of the last colour texture applied to (made once, not every frame).
  mutable Texture raw_view_;
  mutable GLuint viewed_ = 0;
};

}  // namespace facet::driver
