#pragma once
// Inputs are regular files. A FIFO, a device or a socket given where a file is expected would
// block or never end when read, and a folder cannot be read as one.
#include <filesystem>

namespace facet {

// InputError naming `path` unless it names a regular file (after symbolic links): "no such file",
// or what it is instead.
void require_regular_file(const std::filesystem::path& path);

}  // namespace facet
