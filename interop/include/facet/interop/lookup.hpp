#pragma once
// Per-pixel lookup export, for tools that only resample: an OpenEXR image at the output size
// holding, for every output pixel centre (x + 0.5, y + 0.5), the base-image position st and the
// unit eye-frame direction it shows, from the exact inverse of the warp (WarpInverse).
//
// Channels: R = s, G = t (normalised base-image coordinates, t downwards, as in FORMATS.md §2),
// B = 0, A = 1 where covered; X, Y, Z = the eye direction (x right, y up, looking down −z).
// Uncovered pixels hold NaN in R, G, X, Y, Z and 0 in A. Header attribute `facet:lookup` holds
// {"format": "facet-lookup/1", "warp": <the warp's facet:warp metadata>}.
#include <filesystem>

#include "facet/projection/warp.hpp"

namespace facet::interop {

// Writes atomically. Takes about one WarpInverse build plus one inversion per output pixel.
void write_lookup(const Warp& warp, const std::filesystem::path& path);

}  // namespace facet::interop
