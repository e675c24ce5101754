#pragma once
// OpenEXR allocates every header attribute at the size the file gives before reading it: a
// 600-byte file can ask for 2 GB. check_exr_header walks the header first.
#include <string>

namespace facet::projection_io {

// InputError naming `path` unless every attribute of its OpenEXR header (of each part of a
// multi-part file) fits in the file: names and types of 1 to 255 bytes, sizes from 0 to the bytes
// left. Files that do not start with the OpenEXR magic are left to the image reader.
void check_exr_header(const std::string& path);

}  // namespace facet::projection_io
