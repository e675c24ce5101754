#include "option_flags.hpp"

#include <map>

namespace facet::cli {
namespace {

// command -> library option -> flag.
std::map<std::string, std::map<std::string, std::string>>& tables() {
  static std::map<std::string, std::map<std::string, std::string>> by_command;
  return by_command;
}

// Whether `command` or a subcommand nested in it declares `flag`.
bool declares(const CLI::App& command, const std::string& flag) {
  if (command.get_option_no_throw(flag) != nullptr) return true;
  for (const CLI::App* sub : command.get_subcommands([](const CLI::App*) { return true; })) {
    if (declares(*sub, flag)) return true;
  }
  return false;
}

}  // namespace

void keep_declared_flags(const CLI::App& app) {
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    const auto table = tables().find(command->get_name());
    if (table == tables().end()) continue;
    std::erase_if(table->second, [&](const auto& row) { return !declares(*command, row.second); });
  }
}

OptionFlags::OptionFlags(const std::string& command,
                         std::initializer_list<std::pair<std::string, std::string>> option_flags,
                         const OptionFlagList& shared) {
  std::map<std::string, std::string>& table = tables()[command];
  for (const auto& [option, flag] : option_flags) table[option] = flag;
  for (const auto& [option, flag] : shared) table[option] = flag;
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
