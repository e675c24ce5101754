#include "facet/projection/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "support/files.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;
using test::names_in;

void write_text(const fs::path& path, const std::string& text) {
  write_atomically(path, [&](const fs::path& temporary) {
    std::ofstream stream(temporary);
    stream << text;
    if (!stream) throw std::runtime_error("write failed");
  });
}

TEST(AtomicFile, ReplacesRegularFilesAndLeavesNothingOnFailure) {
  const fs::path folder = test::fresh_folder("facet_atomic_regular");
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
  const fs::path folder = test::fresh_folder("facet_atomic_special");
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
  const fs::path folder = test::fresh_folder("facet_atomic_input");
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

// A path the write could never take is refused up front, naming the flag; a new file in an
// existing folder, or an existing regular file, is taken.
TEST(AtomicFile, CheckOutputFileRefusesUnwritablePathsNamingTheFlag) {
  const fs::path folder = test::fresh_folder("facet_atomic_check");
  std::ofstream(folder / "file") << "the user's";
  fs::create_directories(folder / "dir");
  fs::create_symlink(folder / "loop", folder / "loop");
  const std::vector<fs::path> refused = {"",
                                         ".",
                                         folder / "dir",
                                         folder / "dir/",
                                         folder / "loop",
                                         folder / "missing/x.png",
                                         folder / "file/x.png",
                                         folder / "loop/x.png",
                                         folder / (std::string(256, 'n') + ".png"),
                                         "/proc/facet_atomic_check.png"};
  for (const fs::path& out : refused) {
    try {
      check_output_file(out, "--out");
      ADD_FAILURE() << out << " taken";
    } catch (const InputError& error) {
      EXPECT_EQ(error.field(), "--out") << out;
    }
  }
  EXPECT_NO_THROW(check_output_file(folder / "new.png", "--out"));
  EXPECT_NO_THROW(check_output_file(folder / "file", "--out"));
  EXPECT_EQ(test::slurp(folder / "file"), "the user's");
  fs::remove_all(folder);
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  return text;
}

// A command whose output is a folder holding run.txt, and nothing else.
OutputFolderRules own_run_rules() {
  OutputFolderRules rules;
  rules.field = "--out";
  rules.is_own_output = [](const fs::path& folder) {
    return names_in(folder) == std::vector<std::string>{"run.txt"};
  };
  return rules;
}

void write_run(const fs::path& out, const std::string& text) {
  write_folder_atomically(
      out, [&](const fs::path& temporary) { std::ofstream(temporary / "run.txt") << text; },
      own_run_rules());
}

TEST(AtomicFolder, ReplacesItsOwnEarlierOutputAndAcceptsATrailingSlash) {
  const fs::path folder = test::fresh_folder("facet_atomic_folder_own");
  const fs::path out = folder / "deeper" / "out";
  write_run(out, "one");
  EXPECT_EQ(slurp(out / "run.txt"), "one");
  write_run(out.string() + "/", "two");
  EXPECT_EQ(slurp(out / "run.txt"), "two");
  EXPECT_EQ(names_in(folder / "deeper"), std::vector<std::string>{"out"});
  // An empty folder is replaced without asking the command.
  fs::create_directories(folder / "empty");
  write_folder_atomically(folder / "empty/", [](const fs::path& temporary) {
    std::ofstream(temporary / "a.txt") << "a";
  });
  EXPECT_EQ(names_in(folder / "empty"), std::vector<std::string>{"a.txt"});
  fs::remove_all(folder);
}

TEST(AtomicFolder, RefusesAForeignFolderByNameBeforeWriting) {
  const fs::path folder = test::fresh_folder("facet_atomic_folder_foreign");
  const fs::path out = folder / "out";
  fs::create_directories(out);
  std::ofstream(out / "keep.txt") << "mine";
  std::ofstream(folder / "file") << "a file";
  // The error names the folder (without its trailing slash) and the option.
  for (const fs::path& target : {out, fs::path(out.string() + "/"), folder / "file"}) {
    bool filled = false;
    try {
      write_folder_atomically(
          target, [&](const fs::path&) { filled = true; }, own_run_rules());
      ADD_FAILURE() << "no InputError for " << target;
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), (target == folder / "file" ? target : out).string());
      EXPECT_EQ(e.field(), "--out");
    }
    EXPECT_FALSE(filled) << target;
  }
  EXPECT_EQ(slurp(out / "keep.txt"), "mine");
  EXPECT_EQ(names_in(folder), (std::vector<std::string>{"file", "out"}));
  // The current folder and its parents, an input and a folder holding one are refused too.
  const fs::path before = fs::current_path();
  fs::current_path(out);
  for (const char* here : {".", "..", "../", "../out"})
    EXPECT_THROW(check_output_folder(here, own_run_rules()), InputError) << here;
  fs::current_path(before);
  OutputFolderRules reading = own_run_rules();
  reading.inputs = {out / "keep.txt"};
  EXPECT_THROW(check_output_folder(folder / "out", reading), InputError);
  EXPECT_THROW(check_output_folder(folder / "out" / "keep.txt", reading), InputError);
  EXPECT_THROW(check_output_folder("", reading), InputError);
  EXPECT_EQ(check_output_folder(folder / "new/", reading), folder / "new");
  // A folder that could never be created, found before any work: under a file, under a link in
  // a loop, with a name longer than 255 bytes, or where no folder can be made (/proc).
  fs::create_symlink(folder / "loop", folder / "loop");
  for (const fs::path& never :
       {folder / "file" / "x", folder / "file" / "x" / "y", folder / "loop" / "x",
        folder / std::string(256, 'n'), fs::path("/proc/facet_atomic_check")}) {
    try {
      check_output_folder(never, own_run_rules());
      ADD_FAILURE() << never << " taken";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "--out") << never;
    }
  }
  fs::remove_all(folder);
}

TEST(AtomicFolder, AFailureLeavesNoTemporaryAndTheEarlierOutputIntact) {
  const fs::path folder = test::fresh_folder("facet_atomic_folder_failure");
  const fs::path out = folder / "out";
  write_run(out, "one");
  for (const fs::path& target : {out, folder / "new"}) {
    EXPECT_THROW(write_folder_atomically(
                     target,
                     [](const fs::path& temporary) {
                       std::ofstream(temporary / "run.txt") << "partial";
                       throw std::runtime_error("stopped");
                     },
                     own_run_rules()),
                 std::runtime_error);
  }
  EXPECT_EQ(slurp(out / "run.txt"), "one");
  EXPECT_EQ(names_in(folder), std::vector<std::string>{"out"});
  fs::remove_all(folder);
}

}  // namespace
}  // namespace facet
