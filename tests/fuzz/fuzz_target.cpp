#include "fuzz_target.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>

namespace facet::fuzz {
namespace {

std::vector<Target>& registry() {
  static std::vector<Target> all;
  return all;
}

}  // namespace

Registration::Registration(const char* name, Entry entry) {
  auto& all = registry();
  all.push_back({name, entry});
  std::sort(all.begin(), all.end(),
            [](const Target& a, const Target& b) { return a.name < b.name; });
}

const std::vector<Target>& targets() { return registry(); }

const Target* find_target(std::string_view name) {
  for (const Target& target : registry()) {
    if (target.name == name) return &target;
  }
  return nullptr;
}

const std::filesystem::path& scratch_folder() {
  // Never destroyed, so that the exit handler can still name it.
  static const std::filesystem::path* folder = [] {
    // The process id at a fixed width: paths (and the messages naming them) keep one length in
    // every run, so that a libFuzzer run with a fixed -seed follows the same sequence each time.
    char name[32];
    std::snprintf(name, sizeof name, "facet_fuzz_%010ld", long(::getpid()));
    auto* path = new std::filesystem::path(std::filesystem::temp_directory_path() / name);
    std::filesystem::create_directories(*path);
    return path;
  }();
  static const bool removed_at_exit = [] {
    return std::atexit([] {
             std::error_code ec;
             std::filesystem::remove_all(*folder, ec);
           }) == 0;
  }();
  (void)removed_at_exit;
  return *folder;
}

std::filesystem::path write_scratch(const std::string& name, Bytes bytes) {
  const std::filesystem::path path = scratch_folder() / name;
  std::ofstream stream(path, std::ios::binary | std::ios::trunc);
  stream.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  return path;
}

}  // namespace facet::fuzz
