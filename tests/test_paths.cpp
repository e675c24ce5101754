#include "test_paths.hpp"

#include <unistd.h>

namespace facet::test_paths {

std::filesystem::path scratch_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
}

}  // namespace facet::test_paths
