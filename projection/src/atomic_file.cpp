#include "facet/projection/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
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

void check_output_file(const std::filesystem::path& path, const InputField& field) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError("command line", field, "expected a file to write");
  const std::string name = path.filename().string();
  if (name.empty() || name == "." || name == "..")
    throw InputError(path.string(), field, "a file to write, not a folder");
  if (name.size() > 255) throw InputError(path.string(), field, "a file name of at most 255 bytes");
  std::error_code error;
  const fs::file_status status = fs::symlink_status(path, error);
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw InputError(path.string(), field, "a regular file or a new path to write");
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(fs::status(folder, error)))
    throw InputError(path.string(), field, "a file in an existing folder");
  // A file made and removed at once: /proc, /sys and read-only folders take none.
  const fs::path probe = folder / (".facet-probe" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd >= 0) {
    ::close(fd);
    ::unlink(probe.c_str());
  } else if (errno != EEXIST) {
    throw InputError(
        path.string(), field,
        "a file in a folder that takes new files: " + std::generic_category().message(errno));
  }
}

void refuse_output_over_inputs(const std::filesystem::path& out, const InputField& field,
                               std::initializer_list<std::filesystem::path> inputs) {
  for (const std::filesystem::path& input : inputs) {
    std::error_code error;
    if (std::filesystem::equivalent(out, input, error) && !error)
      throw InputError(out.string(), field, "a path other than the input " + input.string());
  }
}

}  // namespace facet
