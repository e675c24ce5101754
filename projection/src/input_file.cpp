#include "facet/projection/input_file.hpp"

#include <string>
#include <system_error>

#include "facet/projection/errors.hpp"

namespace facet {

void require_regular_file(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (fs::is_regular_file(status)) return;
  const char* what = !fs::exists(status)        ? "there is no such file"
                     : fs::is_directory(status) ? "it is a folder"
                     : fs::is_fifo(status)      ? "it is a FIFO"
                     : fs::is_socket(status)    ? "it is a socket"
                     : fs::is_block_file(status) || fs::is_character_file(status)
                         ? "it is a device"
                         : "it is not a regular file";
  throw InputError(path.string(), "", std::string("a regular file, but ") + what);
}

}  // namespace facet
