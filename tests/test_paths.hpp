#pragma once
// Where the tests find the source tree, ../shared/data and the facet CLI. Every test source is
// compiled with this header included first (tests/CMakeLists.txt); the values live in one file
// that CMake generates in the build tree, so that the test sources compile to the same objects in
// any checkout and ccache reuses them.
#include <filesystem>
#include <string>

namespace facet::test_paths {
extern const char kSourceDir[];      // the repository root
extern const char kSharedDataDir[];  // the repository root's ../shared/data
extern const char kCli[];            // the facet executable; empty where none is built

// `name` and this process's ID in the temporary folder: two test runs at once (two checkouts, or
// CI beside a developer's run) never share a scratch folder or an ipc:// socket path there.
std::filesystem::path scratch_path(const std::string& name);
}  // namespace facet::test_paths

#define FACET_SOURCE_DIR (::facet::test_paths::kSourceDir)
#define FACET_SHARED_DATA_DIR (::facet::test_paths::kSharedDataDir)
#define FACET_CLI (::facet::test_paths::kCli)
