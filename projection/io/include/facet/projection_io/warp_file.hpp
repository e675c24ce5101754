#pragma once
// Reading and writing `.warp.exr` offset maps (FORMATS.md §2) through OpenImageIO.
#include <string>

#include "facet/projection/warp.hpp"

namespace facet {

// Throws InputError naming the file and field for anything that breaks FORMATS.md §2: missing
// channels or metadata, wrong format string, bad base parameters, NaN or Inf, folds.
Warp read_warp(const std::string& path);
// Writes atomically: a temporary file in the same folder, renamed when complete.
void write_warp(const std::string& path, const Warp& warp);

}  // namespace facet
