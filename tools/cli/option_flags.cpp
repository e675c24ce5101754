#include "option_flags.hpp"

#include <map>

namespace facet::cli {
namespace {

// command -> library option -> flag.
std::map<std::string, std::map<std::string, std::string>>& tables() {
  static std::map<std::string, std::map<std::string, std::string>> by_command;
  return by_command;
}

}  // namespace

OptionFlags::OptionFlags(const std::string& command,
                         std::initializer_list<std::pair<std::string, std::string>> option_flags) {
  std::map<std::string, std::string>& table = tables()[command];
  for (const auto& [option, flag] : option_flags) table[option] = flag;
}

std::string flag_of_option(const std::string& command, const std::string& option) {
  const auto command_table = tables().find(command);
  if (command_table == tables().end()) return "";
  const auto row = command_table->second.find(option);
  return row == command_table->second.end() ? "" : row->second;
}

InputError shown_with_flags(const InputError& error, const std::string& command) {
  if (error.option().empty()) return error;
  const std::string flag = flag_of_option(command, error.option());
  return flag.empty() ? error : error.with_option_shown_as(flag);
}

}  // namespace facet::cli
