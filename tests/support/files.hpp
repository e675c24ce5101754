#pragma once
// Temporary folders and files of the tests.
#include <filesystem>
#include <string>
#include <vector>

namespace facet::test {

// A fresh, empty folder under the system's temporary folder, named `name`, this process's ID and a
// count (two tests, or two test runs at once, never share one), removed with everything in it when
// the object goes.
class TempFolder {
 public:
  explicit TempFolder(const std::string& name = "facet-test");
  ~TempFolder();
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& child) const {
    return path_ / child;
  }

 private:
  std::filesystem::path path_;
};

// An empty folder test_paths::scratch_path(name) (emptied if it exists), left in place afterwards
// so that a failed test's files can be looked at.
std::filesystem::path fresh_folder(const std::string& name);

// The names in `folder`, hidden ones included, sorted.
std::vector<std::string> names_in(const std::filesystem::path& folder);

// A file's bytes.
std::string slurp(const std::filesystem::path& path);

}  // namespace facet::test
