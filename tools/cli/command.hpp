#pragma once
// Subcommands register themselves here, one file each, so that adding a command never touches
// main.cpp. The callback set up by `add` runs after parsing; an InputError it throws becomes exit
// status 2.
#include <CLI/CLI.hpp>
#include <charconv>
#include <cstdint>
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

// A check for a 64-bit unsigned option: CLI11 converts "-1" to an unsigned type by wrapping it to
// the largest value, and a number past 2^64 - 1 to that value (strtoull's overflow, unchecked);
// this refuses any sign, and digits past the type's range, instead.
inline CLI::Validator unsigned_only() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        const auto first = value.find_first_not_of(" \t");
        if (first != std::string::npos && (value[first] == '-' || value[first] == '+')) {
          return "expected an integer from 0 up without a sign, got '" + value + "'";
        }
        if (first == std::string::npos) return "";
        std::uint64_t number = 0;
        const std::from_chars_result parsed =
            std::from_chars(value.data() + first, value.data() + value.size(), number);
        if (parsed.ec == std::errc::result_out_of_range) {
          return "expected an integer from 0 to 18446744073709551615, got '" + value + "'";
        }
        return "";
      },
      "");
}

// A name given on the command line (a display's): 1 to 256 bytes of valid UTF-8, neither blank
// nor holding control characters; else an InputError naming `flag` and what is wrong.
void check_name(const std::string& name, const std::string& flag);

// The whole CLI: parses argv, runs the subcommand and returns the exit status (0, 1 for a bug, 2
// for the user's mistake, 3 for a lost peer). main() is this alone.
int run(int argc, char** argv);

}  // namespace facet::cli
