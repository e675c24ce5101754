#pragma once
// Libraries name a refused option by its library name (facet::OptionName: the field of its
// options struct, "fov_deg"), never by a flag. Each command lists here which of its flags sets
// which library option, and the CLI shows a library's InputError under the flag the user typed:
// "command line: field '--fov': ...".
#include <initializer_list>
#include <string>
#include <utility>

#include "facet/projection/errors.hpp"

namespace facet::cli {

// Use at namespace scope in a command's file, beside its Registration:
// `const OptionFlags flags{"play", {{"fov_deg", "--fov"}, {"format", "--format"}}};`
struct OptionFlags {
  OptionFlags(const std::string& command,
              std::initializer_list<std::pair<std::string, std::string>> option_flags);
};

// The flag of `command` that sets the library option `option`; "" when it has none.
std::string flag_of_option(const std::string& command, const std::string& option);

// `error` as the user of `command` sees it: the option it names, if any, shown as its flag; an
// option the command has no flag for keeps its library name.
InputError shown_with_flags(const InputError& error, const std::string& command);

}  // namespace facet::cli
