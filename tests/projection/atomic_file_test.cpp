#include "facet/projection/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

fs::path fresh_folder(const std::string& name) {
  const fs::path folder =
      fs::temp_directory_path() / ("facet_atomic_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

void write_text(const fs::path& path, const std::string& text) {
  write_atomically(path, [&](const fs::path& temporary) {
    std::ofstream stream(temporary);
    stream << text;
    if (!stream) throw std::runtime_error("write failed");
  });
}

TEST(AtomicFile, ReplacesRegularFilesAndLeavesNothingOnFailure) {
  const fs::path folder = fresh_folder("regular");
  const fs::path file = folder / "out.txt";
  write_text(file, "one");
  write_text(file, "two");
  std::ifstream in(file);
  std::string text;
  in >> text;
  EXPECT_EQ(text, "two");
  EXPECT_THROW(write_atomically(file, [](const fs::path&) { throw std::runtime_error("no"); }),
               std::runtime_error);
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(folder)) entries += entry.exists();
  EXPECT_EQ(entries, 1u);  // the file; no temporary left beside it
  fs::remove_all(folder);
}

TEST(AtomicFile, RefusesTargetsThatAreNotRegularFiles) {
  const fs::path folder = fresh_folder("special");
  const fs::path fifo = folder / "fifo.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path sub = folder / "folder.png";
  fs::create_directories(sub);
  const fs::path link = folder / "link.png";
  fs::create_symlink(folder / "elsewhere.png", link);
  for (const fs::path& target : {fifo, sub, link}) {
    bool wrote = false;
    EXPECT_THROW(write_atomically(target, [&](const fs::path&) { wrote = true; }), InputError)
        << target;
    EXPECT_FALSE(wrote) << target;
  }
  // Each is still what it was.
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  EXPECT_TRUE(fs::is_directory(fs::symlink_status(sub)));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  fs::remove_all(folder);
}

TEST(AtomicFile, RefusesAnOutputThatIsAnInput) {
  const fs::path folder = fresh_folder("input");
  const fs::path input = folder / "a.warp.exr";
  std::ofstream(input) << "warp";
  const fs::path link = folder / "b.warp.exr";
  fs::create_symlink(input, link);
  for (const fs::path& out : {input, folder / "." / "a.warp.exr", link}) {
    EXPECT_THROW(refuse_output_over_inputs(out, "--out", {folder / "other.exr", input}), InputError)
        << out;
  }
  EXPECT_NO_THROW(refuse_output_over_inputs(folder / "new.exr", "--out", {input}));
  fs::remove_all(folder);
}

}  // namespace
}  // namespace facet
