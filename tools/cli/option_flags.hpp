#pragma once
// Libraries name a refused option by its library name (facet::OptionName: the field of its
// options struct, "fov_deg"), never by a flag. Each command lists here which of its flags sets
// which library option, and the CLI shows a library's InputError under the flag the user typed:
// "command line: field '--fov': ...".
#include <CLI/CLI.hpp>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "facet/projection/errors.hpp"

namespace facet::cli {

// Library option -> flag, for a group of flags several commands declare alike (view_flags.hpp).
using OptionFlagList = std::vector<std::pair<std::string, std::string>>;

// Use at namespace scope in a command's file, beside its Registration:
// `const OptionFlags flags{"play", {{"fov_deg", "--fov"}, {"format", "--format"}}};`
// `shared` adds the rows of a group of flags the command declares with the group's own helper.
struct OptionFlags {
  OptionFlags(const std::string& command,
              std::initializer_list<std::pair<std::string, std::string>> option_flags,
              const OptionFlagList& shared = {});
};

// Drops the rows whose flag `app`'s subcommand of that command (or one nested in it) does not
// declare, so that an error is never shown under a flag the command lacks: a command that takes a
// shared list (view_flags.hpp) keeps the rows of the flags it has. The CLI calls it once, after
// every command has added its options.
void keep_declared_flags(const CLI::App& app);

// The flag of `command` that sets the library option `option`; "" when it has none.
std::string flag_of_option(const std::string& command, const std::string& option);

// `error` as the user of `command` sees it: the option it names, if any, shown as its flag; an
// option the command has no flag for keeps its library name.
InputError shown_with_flags(const InputError& error, const std::string& command);

}  // namespace facet::cli
