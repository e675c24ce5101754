#pragma once
// Writing an output folder so that a failure never leaves part of it behind: the folder-sized
// counterpart of atomic_file.hpp, shared by every command that writes a folder.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "facet/projection/errors.hpp"

namespace facet {

// What an output folder may replace, and how a refusal is worded.
struct OutputFolderRules {
  // What names the folder in errors: in a library the option of its call (OptionName{"out"}), in
  // the CLI the flag ("--out"); empty when nothing does.
  InputField field;
  // The error's "expected" text when an existing path may not be replaced.
  std::string expected = "a folder that does not exist yet or is empty";
  // True for an existing folder that holds this command's own earlier output, which may be
  // replaced. Null: only an empty folder may be.
  std::function<bool(const std::filesystem::path& folder)> is_own_output;
  // What the command reads: the folder may neither be one of them nor hold one.
  std::vector<std::filesystem::path> inputs;
};

// True when every entry of `folder` is a regular file, not a link, whose name `own_name` accepts
// (an empty folder is): the usual OutputFolderRules::is_own_output of a command that writes a
// flat folder of files.
bool holds_only_files_named(const std::filesystem::path& folder,
                            const std::function<bool(const std::string& name)>& own_name);

// `folder` as written ("out/" is "out") once it passes the checks write_folder_atomically makes
// before writing anything. InputError naming the folder and rules.field when it is empty, is the
// current folder or one of its parents, is or holds one of rules.inputs, or exists and is not an
// empty folder or one that rules.is_own_output accepts (a symbolic link is not a folder here); or
// when it does not exist and could not be created: a name longer than 255 bytes, or a nearest
// existing ancestor that is not a folder or takes no new folder (one is made and removed at once
// to find out: /proc and /sys take none).
std::filesystem::path check_output_folder(const std::filesystem::path& folder,
                                          const OutputFolderRules& rules = {});

// Checks `folder` as check_output_folder does, creates its parent folders and a hidden temporary
// sibling ".NAME.tmp<pid>" (one writer per folder in a process at a time; a stale one is
// removed), and calls fill(temporary). When fill returns, the temporary replaces `folder`: an
// existing folder is moved aside (".NAME.old<pid>") until the new one is in place, then removed.
// When fill throws (Interrupted after SIGINT or SIGTERM included) or a rename fails, the
// temporary is removed, `folder` is left as it was and the exception propagates. A folder that
// cannot be created is an InputError naming it.
void write_folder_atomically(
    const std::filesystem::path& folder,
    const std::function<void(const std::filesystem::path& temporary)>& fill,
    const OutputFolderRules& rules = {});

}  // namespace facet
