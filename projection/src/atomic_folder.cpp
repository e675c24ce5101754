#include "facet/projection/atomic_folder.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <system_error>

#include "facet/projection/errors.hpp"

namespace facet {

namespace fs = std::filesystem;

namespace {

// True when `outer` is `inner` or one of its parents, after links and relative paths.
bool is_or_holds(const fs::path& outer, const fs::path& inner) {
  std::error_code error;
  const fs::path o = fs::weakly_canonical(outer, error);
  if (error) return false;
  const fs::path i = fs::weakly_canonical(inner, error);
  if (error) return false;
  auto a = o.begin(), b = i.begin();
  for (; a != o.end() && b != i.end(); ++a, ++b) {
    if (a->empty()) break;  // a trailing separator
    if (*a != *b) return false;
  }
  return a == o.end() || a->empty();
}

// A hidden sibling of `folder` (which has a file name): ".NAME<tag><pid>".
fs::path sibling(const fs::path& folder, const char* tag) {
  std::string name = ".";
  name += folder.filename().string();
  name += tag + std::to_string(::getpid());
  return folder.parent_path() / name;
}

void create_folders(const fs::path& path, const InputField& field) {
  std::error_code error;
  fs::create_directories(path, error);
  if (error)
    throw InputError(path.string(), field, "a folder that can be created: " + error.message());
}

}  // namespace

bool holds_only_files_named(const fs::path& folder,
                            const std::function<bool(const std::string& name)>& own_name) {
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, error)) {
    if (!own_name(entry.path().filename().string()) || entry.is_symlink(error) ||
        !entry.is_regular_file(error))
      return false;
  }
  return !error;
}

fs::path check_output_folder(const fs::path& folder, const OutputFolderRules& rules) {
  fs::path out = folder.lexically_normal();
  if (!out.has_filename()) out = out.parent_path();
  if (out.empty()) throw InputError("command line", rules.field, "expected an output folder");
  std::error_code error;
  const fs::path current = fs::current_path(error);
  if (!error && is_or_holds(out, current))
    throw InputError(out.string(), rules.field,
                     "a folder other than the current folder and its parents");
  for (const fs::path& input : rules.inputs) {
    if (is_or_holds(out, input))
      throw InputError(out.string(), rules.field,
                       "a folder that neither is nor holds the input " + input.string());
  }
  if (out.filename().string().size() > 255)
    throw InputError(out.string(), rules.field, "a folder name of at most 255 bytes");
  const fs::file_status status = fs::symlink_status(out, error);
  if (!fs::exists(status)) {
    // Created later, in its nearest existing ancestor: which must be a folder (not a file, nor a
    // link that leads nowhere or in a loop) that takes a new folder (/proc and /sys do not).
    fs::path above = out.parent_path();
    while (!above.empty() && !fs::exists(fs::symlink_status(above, error)) &&
           above != above.parent_path())
      above = above.parent_path();
    if (above.empty()) above = ".";
    if (!fs::is_directory(fs::status(above, error)))
      throw InputError(out.string(), rules.field,
                       "a folder that can be created: " + above.string() + " is no folder");
    const fs::path probe = above / (".facet-probe" + std::to_string(::getpid()));
    if (::mkdir(probe.c_str(), 0700) == 0) {
      ::rmdir(probe.c_str());
    } else if (errno != EEXIST) {
      throw InputError(out.string(), rules.field,
                       "a folder that can be created: " + std::generic_category().message(errno));
    }
    return out;
  }
  bool replaceable = fs::is_directory(status);
  if (replaceable && !fs::is_empty(out, error))
    replaceable = !error && rules.is_own_output && rules.is_own_output(out);
  if (!replaceable) throw InputError(out.string(), rules.field, rules.expected);
  return out;
}

void write_folder_atomically(const fs::path& folder,
                             const std::function<void(const fs::path& temporary)>& fill,
                             const OutputFolderRules& rules) {
  fs::path out = check_output_folder(folder, rules);
  // A bare name lives in the current folder: give it one so that its siblings do too.
  if (!out.has_parent_path()) out = fs::path(".") / out;
  create_folders(out.parent_path(), rules.field);
  const fs::path temporary = sibling(out, ".tmp");
  std::error_code error;
  fs::remove_all(temporary, error);
  create_folders(temporary, rules.field);
  try {
    fill(temporary);
    const bool replacing = fs::exists(fs::symlink_status(out, error));
    const fs::path earlier = sibling(out, ".old");
    if (replacing) {
      fs::remove_all(earlier, error);
      fs::rename(out, earlier);
    }
    try {
      fs::rename(temporary, out);
    } catch (...) {
      if (replacing) fs::rename(earlier, out, error);
      throw;
    }
    if (replacing) fs::remove_all(earlier, error);
  } catch (...) {
    fs::remove_all(temporary, error);
    throw;
  }
}

}  // namespace facet
