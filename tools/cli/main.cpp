#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <new>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#if __has_include(<opencv2/core.hpp>)
#include <opencv2/core.hpp>
#define FACET_CLI_HAS_OPENCV 1
#endif

#include "command.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "option_flags.hpp"

namespace facet::cli {

std::vector<std::pair<int, CommandSetup>>& CommandRegistry::commands() {
  static std::vector<std::pair<int, CommandSetup>> registered;
  return registered;
}

Registration::Registration(int order, CommandSetup setup) {
  CommandRegistry::commands().emplace_back(order, std::move(setup));
}

namespace {

// The arguments that name existing files or folders, outputs aside: the inputs a failure
// without a source of its own is reported against.
std::string inputs_of(int argc, char** argv) {
  std::string inputs;
  for (int i = 2; i < argc; ++i) {
    std::error_code ec;
    const std::string arg = argv[i];
    const std::string before = argv[i - 1];
    if (before == "--out" || before == "--stats") continue;
    if (arg.empty() || arg.starts_with("-") || !std::filesystem::exists(arg, ec)) continue;
    inputs += (inputs.empty() ? "" : ", ") + arg;
  }
  return inputs.empty() ? "the command line" : inputs;
}

// What the process may allocate: its address-space limit, else the machine's memory.
std::string memory_limit() {
  rlimit limit{};
  double bytes = 0;
  const char* kind = "physical memory";
  if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    bytes = static_cast<double>(limit.rlim_cur);
    kind = "address-space limit";
  } else {
    bytes = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) *
            static_cast<double>(::sysconf(_SC_PAGESIZE));
  }
  char text[64];
  std::snprintf(text, sizeof text, "%.1f GiB %s", bytes / double(1 << 30), kind);
  return text;
}

}  // namespace

// Maps an exception that left a command to its message on stderr and the exit status: 2 for the
// input's fault (InputError, exhausted memory or GL resources, a library's complaint about a file
// being read), 3 for a lost peer, 1 for a bug (named by its function where it says so).
int report_failure(std::exception_ptr failure, const std::string& command, int argc, char** argv) {
  const std::string prefix = "facet" + (command.empty() ? "" : " " + command);
  const std::string activity = facet::Activity::failed();
  const std::string doing = activity.empty() ? "running " + prefix : activity;
  auto input_error = [&](const std::string& what) {
    std::cerr << prefix << ": error: " << what << "\n";
    return 2;
  };
  auto out_of_memory = [&](const std::string& detail) {
    return input_error("out of memory while " + doing + ", input " + inputs_of(argc, argv) +
                       ": it asks for more than this process may use (" + memory_limit() + "); " +
                       detail);
  };
  try {
    std::rethrow_exception(failure);
  } catch (const facet::Interrupted& e) {
    // A long command stopped on SIGINT or SIGTERM after removing its temporary outputs; what()
    // says what was done.
    std::cerr << prefix << ": interrupted by " << facet::signal_name(e.signal()) << ": " << e.what()
              << "\n";
    return e.exit_status();
  } catch (const facet::InputError& e) {
    // A library names the option it refuses by its library name: shown here by its flag.
    std::cerr << "facet: error: " << shown_with_flags(e, command).what() << "\n";
    return 2;
  } catch (const facet::PeerLost& e) {
    std::cerr << "facet: stopped: " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    return out_of_memory("ask for smaller sizes, grids or counts");
  } catch (const std::length_error& e) {
    return out_of_memory(std::string("a size too large to hold (") + e.what() + ")");
  } catch (const facet::ResourceExhausted& e) {
    return input_error(std::string(e.what()) + " while " + doing + ", input " +
                       inputs_of(argc, argv) + " (" + memory_limit() + "); ask for smaller sizes");
  } catch (const std::filesystem::filesystem_error& e) {
    const std::string path = e.path1().empty() ? inputs_of(argc, argv) : e.path1().string();
    return input_error(path + ": " + e.code().message() + " (while " + doing + ")");
  } catch (const nlohmann::json::exception& e) {
    return input_error("while " + doing + ", input " + inputs_of(argc, argv) +
                       ": JSON that cannot be read (" + e.what() + ")");
#ifdef FACET_CLI_HAS_OPENCV
  } catch (const cv::Exception& e) {
    if (e.code == cv::Error::StsNoMem) return out_of_memory("ask for smaller images");
    // OpenCV's complaint while a step on an input was under way is about that input.
    if (!activity.empty()) {
      return input_error("while " + doing + ", input " + inputs_of(argc, argv) + ": " + e.err);
    }
    std::cerr << prefix << ": internal error: " << e.what() << "\n";
    return 1;
#endif
  } catch (const std::exception& e) {
    std::cerr << prefix << ": internal error: " << e.what() << "\n";
    return 1;
  } catch (...) {
    std::cerr << prefix << ": internal error: an exception of unknown type\n";
    return 1;
  }
}

namespace {

// Whether `text` is well-formed UTF-8: no stray continuation bytes, no overlong forms, no
// surrogates, nothing past U+10FFFF.
bool valid_utf8(const std::string& text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char lead = byte(i);
    std::size_t length = 0;
    std::uint32_t code = 0, least = 0;
    if (lead < 0x80) {
      ++i;
      continue;
    } else if ((lead & 0xe0) == 0xc0) {
      length = 2, code = lead & 0x1f, least = 0x80;
    } else if ((lead & 0xf0) == 0xe0) {
      length = 3, code = lead & 0x0f, least = 0x800;
    } else if ((lead & 0xf8) == 0xf0) {
      length = 4, code = lead & 0x07, least = 0x10000;
    } else {
      return false;
    }
    if (i + length > text.size()) return false;
    for (std::size_t k = 1; k < length; ++k) {
      if ((byte(i + k) & 0xc0) != 0x80) return false;
      code = (code << 6) | (byte(i + k) & 0x3f);
    }
    if (code < least || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return false;
    i += length;
  }
  return true;
}

}  // namespace

void check_name(const std::string& name, const std::string& flag) {
  auto refuse = [&](const std::string& why) {
    throw facet::InputError("command line", flag,
                            "a name of 1 to 256 bytes of UTF-8 without control characters, " + why);
  };
  if (name.size() > 256) refuse("got " + std::to_string(name.size()) + " bytes");
  if (name.find_first_not_of(" \t") == std::string::npos) refuse("got a blank one");
  if (!valid_utf8(name)) refuse("got bytes that are not UTF-8");
  for (const char c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) refuse("got a control character");
  }
}

namespace {

// An empty value (--out=, --scene "") is refused naming its flag, for every option of every
// command: none means anything by it, and taken for the flag left out it would run the default.
void refuse_empty_values(CLI::App& command) {
  for (CLI::Option* option : command.get_options()) {
    if (option->get_expected_max() == 0) continue;
    option->check(CLI::Validator(
        [](std::string& value) -> std::string {
          return value.empty() ? "expected a value, got an empty one" : "";
        },
        ""));
  }
  for (CLI::App* sub : command.get_subcommands([](CLI::App*) { return true; })) {
    refuse_empty_values(*sub);
  }
}

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{
      "facet: calibration and piecewise perspective rendering for dome, cylinder and "
      "wall projector displays"};
  app.require_subcommand(1);
  auto commands = facet::cli::CommandRegistry::commands();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [order, setup] : commands) setup(app);
  keep_declared_flags(app);
  refuse_empty_values(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (...) {
    const std::string command =
        app.get_subcommands().empty() ? "" : app.get_subcommands().front()->get_name();
    try {
      return facet::cli::report_failure(std::current_exception(), command, argc, argv);
    } catch (...) {  // no memory left even for the message
      std::fputs("facet: error: out of memory\n", stderr);
      return 2;
    }
  }
  return 0;
}

}  // namespace facet::cli
