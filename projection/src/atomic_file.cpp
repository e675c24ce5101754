#include "facet/projection/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <string>
#include <system_error>

namespace facet {

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write) {
  static std::atomic<unsigned> counter{0};
  // Keep the extension last so that writers that choose a format by extension still do.
  std::filesystem::path temporary = path;
  // Appending (rather than `"." + ...`) also keeps GCC 12's -Wrestrict false positive at -O3 away.
  std::string name = ".";
  name += path.stem().string();
  name += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  name += path.extension().string();
  temporary.replace_filename(name);
  try {
    write(temporary);
    std::filesystem::rename(temporary, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

}  // namespace facet
