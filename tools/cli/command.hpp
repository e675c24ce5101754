#pragma once
// Subcommands register themselves here, one file each, so that adding a command never touches
// main.cpp. The callback set up by `add` runs after parsing; an InputError it throws becomes exit
// status 2.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace facet::cli {

using CommandSetup = std::function<void(CLI::App& app)>;

struct CommandRegistry {
  static std::vector<std::pair<int, CommandSetup>>& commands();
};

// Use at namespace scope in a command's file: `static const Registration reg{order, setup};`
// `order` sorts the help listing.
struct Registration {
  Registration(int order, CommandSetup setup);
};

}  // namespace facet::cli
