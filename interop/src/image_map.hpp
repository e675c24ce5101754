#pragma once
// Blend and black-level maps stored as images by other tools (MPCDI members, SGCT masks).
#include <string>

#include "facet/projection_io/blend_file.hpp"

namespace facet::interop {

// Decodes a PNG (or any image OpenImageIO reads; `name` gives the format by its extension) to
// `size` by bilinear resampling at output pixel centres; each value becomes value^gamma, clamped
// to [0,1]. Grey images give one channel, colour images three. Throws InputError naming
// `source` for an unreadable image or one over 2^26 pixels.
projection_io::BlendMap decode_image_map(const std::string& bytes, const std::string& name,
                                         double gamma, glm::ivec2 size, const std::string& source);

// The map's values (in [0,1]) as a PNG of 8 or 16 bits per channel.
std::string encode_png(const projection_io::BlendMap& map, int bits);

// A three-channel map whose channels agree at every pixel becomes one channel.
void collapse_equal_channels(projection_io::BlendMap& map);

}  // namespace facet::interop
