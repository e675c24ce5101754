#include "facet/projection/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <string>
#include <system_error>

#include "facet/projection/errors.hpp"

namespace facet {

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::symlink_status(path, error);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw InputError(path.string(), "", "a regular file or a new path to write");
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

void refuse_output_over_inputs(const std::filesystem::path& out, std::string_view flag,
                               std::initializer_list<std::filesystem::path> inputs) {
  for (const std::filesystem::path& input : inputs) {
    std::error_code error;
    if (std::filesystem::equivalent(out, input, error) && !error)
      throw InputError(out.string(), std::string(flag),
                       "a path other than the input " + input.string());
  }
}

}  // namespace facet
