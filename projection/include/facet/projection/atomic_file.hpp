#pragma once
// Writing output files so that a failure never leaves a partial file behind.
#include <filesystem>
#include <functional>

namespace facet {

// Calls write(temporary_path) with a path in the same folder as `path`, then renames it onto
// `path`. If write throws, the temporary file is removed and the exception propagates.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write);

}  // namespace facet
