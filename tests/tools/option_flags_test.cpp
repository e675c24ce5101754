// Libraries name a refused option by its library name, never by a command-line flag; the CLI
// shows it under the flag that sets it, so that what the user reads names what they typed.
#include "../../tools/cli/option_flags.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

#include "../../tools/cli/command.hpp"
#include "facet/projection/content_projection.hpp"
#include "facet/projection/errors.hpp"
#include "support/facet_cli.hpp"

namespace {

namespace fs = std::filesystem;

// The arguments of each `InputError(...)` call in `text`, with the line it starts on: from the
// opening parenthesis to its match, string and character literals skipped whole.
std::vector<std::pair<int, std::string>> input_error_calls(const std::string& text) {
  std::vector<std::pair<int, std::string>> calls;
  const std::string opening = "InputError(";
  for (std::size_t at = text.find(opening); at != std::string::npos;
       at = text.find(opening, at + 1)) {
    std::size_t i = at + opening.size();
    int depth = 1;
    while (i < text.size() && depth > 0) {
      const char c = text[i];
      if (c == '"' || c == '\'') {
        for (++i; i < text.size() && text[i] != c; ++i) {
          if (text[i] == '\\') ++i;
        }
      } else if (c == '(') {
        ++depth;
      } else if (c == ')') {
        --depth;
      }
      ++i;
    }
    const int line = 1 + int(std::count(text.begin(), text.begin() + long(at), '\n'));
    calls.emplace_back(line, text.substr(at, i - at));
  }
  return calls;
}

// The string literals of `call` that are a flag and nothing else ("--fov"): a source or a field
// named by a flag.
std::vector<std::string> flags_named(const std::string& call) {
  static const std::regex flag(R"re("(--[a-z][a-z0-9-]*)")re");
  std::vector<std::string> flags;
  for (std::sregex_iterator it(call.begin(), call.end(), flag), end; it != end; ++it) {
    flags.push_back((*it)[1]);
  }
  return flags;
}

// The string literals of C++ source `text` with the line each starts on; comments, character
// literals and the code between literals are skipped. A raw string is taken whole.
std::vector<std::pair<int, std::string>> string_literals(const std::string& text) {
  std::vector<std::pair<int, std::string>> literals;
  int line = 1;
  std::size_t i = 0;
  const auto skip_to = [&](std::size_t end) {
    line += int(std::count(text.begin() + long(i), text.begin() + long(end), '\n'));
    i = end;
  };
  while (i < text.size()) {
    if (text.compare(i, 2, "//") == 0) {
      skip_to(std::min(text.find('\n', i), text.size()));
    } else if (text.compare(i, 2, "/*") == 0) {
      const std::size_t end = text.find("*/", i + 2);
      skip_to(end == std::string::npos ? text.size() : end + 2);
    } else if (text.compare(i, 2, "R\"") == 0 &&
               (i == 0 ||
                !(std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '_'))) {
      const std::size_t open = text.find('(', i + 2);
      if (open == std::string::npos) break;
      const std::string close = ")" + text.substr(i + 2, open - i - 2) + "\"";
      const std::size_t end = std::min(text.find(close, open), text.size());
      literals.emplace_back(line, text.substr(open + 1, end - open - 1));
      skip_to(std::min(end + close.size(), text.size()));
    } else if (text[i] == '"' || text[i] == '\'') {
      const char quote = text[i];
      std::size_t end = i + 1;
      while (end < text.size() && text[end] != quote && text[end] != '\n')
        end += text[end] == '\\' ? 2 : 1;
      if (quote == '"') literals.emplace_back(line, text.substr(i + 1, end - i - 1));
      skip_to(std::min(end + 1, text.size()));
    } else {
      skip_to(i + 1);
    }
  }
  return literals;
}

// The command-line flags ("--fov") a text mentions anywhere in its wording: "--" at the start of
// a word, then a lower-case letter.
std::vector<std::string> flags_mentioned(const std::string& text) {
  static const std::regex flag(R"re((?:^|[^-\w])(--[a-z][a-z0-9-]*))re");
  std::vector<std::string> flags;
  for (std::sregex_iterator it(text.begin(), text.end(), flag), end; it != end; ++it) {
    flags.push_back((*it)[1]);
  }
  return flags;
}

// What a scan of the libraries' sources found: the pieces `pieces_of` cut from them, and
// "file:line flag" for every flag `flags_of` finds in a piece.
struct LibraryScan {
  std::size_t pieces = 0;
  std::vector<std::string> found;
  std::string list() const {
    std::string text;
    for (const std::string& site : found) text += "\n  " + site;
    return text;
  }
};
LibraryScan scan_libraries(
    const std::function<std::vector<std::pair<int, std::string>>(const std::string&)>& pieces_of,
    const std::function<std::vector<std::string>(const std::string&)>& flags_of) {
  LibraryScan scan;
  for (const char* library : {"projection", "calibration", "interop", "driver", "api"}) {
    const fs::path folder = fs::path(FACET_SOURCE_DIR) / library;
    EXPECT_TRUE(fs::is_directory(folder)) << folder;
    if (!fs::is_directory(folder)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(folder)) {
      const std::string extension = entry.path().extension().string();
      if (!entry.is_regular_file() || (extension != ".cpp" && extension != ".hpp")) continue;
      std::ifstream stream(entry.path(), std::ios::binary);
      const std::string text{std::istreambuf_iterator<char>(stream),
                             std::istreambuf_iterator<char>()};
      for (const auto& [line, piece] : pieces_of(text)) {
        ++scan.pieces;
        for (const std::string& flag : flags_of(piece)) {
          scan.found.push_back(fs::relative(entry.path(), FACET_SOURCE_DIR).string() + ":" +
                               std::to_string(line) + " " + flag);
        }
      }
    }
  }
  return scan;
}

TEST(LibrarySources, TheScanFindsAFlagInTheWordingOfAnyLibraryText) {
  const auto literals = string_literals(
      "throw InputError(\"command line\", OptionName{\"eye_world\"},\n"
      "                 \"expected --eye as well\");  // a comment on --eye is no text\n"
      "notes.push_back(\"give the real eye point \"\n  \"with --eye x,y,z\");\n"
      "/* --camera in a block comment */ char c = '\"'; int top = stack[--top];\n"
      "const char* s = R\"(raw \"--look-at\" text)\"; const char* t = \"a -- b, x--y\";\n");
  std::vector<std::string> flags;
  std::vector<int> lines;
  for (const auto& [line, literal] : literals) {
    for (const std::string& flag : flags_mentioned(literal)) {
      flags.push_back(flag);
      lines.push_back(line);
    }
  }
  EXPECT_EQ(flags, (std::vector<std::string>{"--eye", "--eye", "--look-at"}));
  EXPECT_EQ(lines, (std::vector<int>{2, 4, 6}));
}

// No library text names a command-line flag in its wording: not an error's expectation, a note
// or a warning. A library names an option by its OptionName and words the rest without flags.
TEST(LibrarySources, NoLibraryTextMentionsACommandLineFlag) {
  const LibraryScan scan = scan_libraries(string_literals, flags_mentioned);
  std::cout << scan.pieces << " string literals in the libraries, " << scan.found.size()
            << " mentioning a flag\n";
  EXPECT_GT(scan.pieces, 3000u) << "the scan found too few string literals to mean anything";
  EXPECT_TRUE(scan.found.empty()) << scan.found.size()
                                  << " library texts mention a flag:" << scan.list();
}

TEST(LibrarySources, TheScanFindsAFlagNamedInAnInputError) {
  const auto calls = input_error_calls(
      "throw InputError(\"command line\", \"--fov\", \"a (field) of view\");\n"
      "throw InputError(\n    source, \"--preview-size\",\n    \"8 to 8192\");\n"
      "throw InputError(source, OptionName{\"fov_deg\"}, \"expected --fov's range\");\n");
  ASSERT_EQ(calls.size(), 3u);
  EXPECT_EQ(calls[1].first, 2);
  EXPECT_EQ(flags_named(calls[0].second), std::vector<std::string>{"--fov"});
  EXPECT_EQ(flags_named(calls[1].second), std::vector<std::string>{"--preview-size"});
  EXPECT_TRUE(flags_named(calls[2].second).empty());
}

// No library error names a command-line flag as its source or field: libraries name options by
// their library names (OptionName), and the CLI maps them onto flags.
TEST(LibrarySources, NoInputErrorNamesACommandLineFlag) {
  const LibraryScan scan = scan_libraries(input_error_calls, flags_named);
  std::cout << scan.pieces << " InputError calls in the libraries, " << scan.found.size()
            << " naming a flag\n";
  EXPECT_GT(scan.pieces, 300u) << "the scan found too few InputError calls to mean anything";
  EXPECT_TRUE(scan.found.empty()) << scan.found.size()
                                  << " library errors name a flag:" << scan.list();
}

TEST(OptionFlags, ALibraryErrorNamesItsOptionByItsLibraryName) {
  try {
    facet::fisheye_content(400).validate("command line");
    FAIL() << "a 400° dome master was accepted";
  } catch (const facet::InputError& e) {
    EXPECT_EQ(e.option(), "fov_deg");
    EXPECT_EQ(e.field(), "fov_deg");
    EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
  }
}

#if !defined(FACET_TEST_WITHOUT_CALIBRATION) && !defined(FACET_TEST_WITHOUT_DRIVER) && \
    !defined(FACET_TEST_WITHOUT_INTEROP)
TEST(OptionFlags, TheCliShowsALibraryOptionUnderItsCommandsFlag) {
  using facet::InputError;
  using facet::OptionName;
  const InputError field("command line", OptionName{"fov_deg"}, "degrees in (0, 360]");
  EXPECT_EQ(std::string(facet::cli::shown_with_flags(field, "play").what()),
            "command line: field '--fov': degrees in (0, 360]");
  // The same library name is another flag in another command.
  const InputError size("command line", OptionName{"size"}, "a size");
  EXPECT_EQ(std::string(facet::cli::shown_with_flags(size, "run").what()),
            "command line: field '--size': a size");
  const InputError camera_size(OptionName{"size"}, "a size the camera offers");
  EXPECT_EQ(std::string(facet::cli::shown_with_flags(camera_size, "capture").what()),
            "--camera-size: a size the camera offers");
  // A command without such a flag, and an error naming no option, keep what the library said.
  EXPECT_EQ(std::string(facet::cli::shown_with_flags(field, "patterns").what()),
            "command line: field 'fov_deg': degrees in (0, 360]");
  const InputError file("display.json", "render.tolerance_px", "a positive number");
  EXPECT_EQ(std::string(facet::cli::shown_with_flags(file, "run").what()), file.what());
  EXPECT_EQ(facet::cli::flag_of_option("run", "factor"), "--scale");
  // The session's default tolerance, and the content format play checks the image against.
  EXPECT_EQ(facet::cli::flag_of_option("run", "tolerance_px"), "--tolerance");
  EXPECT_EQ(facet::cli::flag_of_option("play", "format"), "--format");
  EXPECT_EQ(facet::cli::flag_of_option("mpcdi", "values"), "--warp-values");
  EXPECT_EQ(facet::cli::flag_of_option("run", "no_such_option"), "");
}
#endif

#ifndef FACET_TEST_WITHOUT_DRIVER
// The scene-view rows (view_flags.hpp) are one list shared by render, run, bench and depth-image;
// once the commands have declared their options, each keeps only the rows of flags it has.
TEST(OptionFlags, ACommandKeepsOnlyTheSharedRowsOfTheFlagsItDeclares) {
  using facet::cli::flag_of_option;
  CLI::App app;
  for (auto& [order, setup] : facet::cli::CommandRegistry::commands()) setup(app);
  facet::cli::keep_declared_flags(app);
  for (const char* command : {"render", "run"}) {
    EXPECT_EQ(flag_of_option(command, "material"), "--material") << command;
    EXPECT_EQ(flag_of_option(command, "step"), "--scene") << command;
  }
  for (const char* command : {"render", "run", "bench"}) {
    EXPECT_EQ(flag_of_option(command, "camera"), "--camera") << command;
    EXPECT_EQ(flag_of_option(command, "eye_world"), "--eye") << command;
    EXPECT_EQ(flag_of_option(command, "look_at_world"), "--look-at") << command;
  }
  EXPECT_EQ(flag_of_option("depth-image", "eye_world"), "--eye");
  EXPECT_EQ(flag_of_option("depth-image", "scene"), "--scene");
  EXPECT_EQ(flag_of_option("depth-image", "camera"), "");
  EXPECT_EQ(flag_of_option("bench", "scene"), "--scene");
  EXPECT_EQ(flag_of_option("bench", "frames"), "--frames");
  for (const char* option : {"material", "size"})
    EXPECT_EQ(flag_of_option("bench", option), "") << option;
}
#endif

#ifndef FACET_TEST_WITHOUT_DRIVER
// Every command that shows or writes for one display takes it the same way: as its positional
// (after the content file for play), or by --display.
TEST(DisplayArgument, EveryCommandTakesItsDisplayAsAPositionalOrByFlag) {
  CLI::App app;
  for (auto& [order, setup] : facet::cli::CommandRegistry::commands()) setup(app);
  std::vector<std::string> commands = {"render", "run", "preview", "play", "capture", "display"};
#ifndef FACET_TEST_WITHOUT_INTEROP
  for (const char* name : {"lookup", "mpcdi export", "sgct export"}) commands.push_back(name);
#endif
  for (const std::string& name : commands) {
    const CLI::App* command = app.get_subcommand(name.substr(0, name.find(' ')));
    if (name.find(' ') != std::string::npos)
      command = command->get_subcommand(name.substr(name.find(' ') + 1));
    const CLI::Option* display = command->get_option_no_throw("--display");
    ASSERT_NE(display, nullptr) << name;
    EXPECT_TRUE(display->get_positional()) << name;
    EXPECT_TRUE(display->check_name("display")) << name;
  }
}

TEST(DisplayArgument, ThePositionalAndTheFlagRenderTheSameAndNotBoth) {
  const std::string size = " --size 48x32 --frames 1 --json";
  std::string positional, flag, both;
  ASSERT_EQ(facet::test::run_facet("render builtin:cylinder360" + size, &positional), 0)
      << positional;
  ASSERT_EQ(facet::test::run_facet("render --display builtin:cylinder360" + size, &flag), 0)
      << flag;
  // The line of the JSON report that holds `key`.
  const auto line_of = [](const std::string& report, const std::string& key) {
    const std::size_t at = report.find("\"" + key + "\": ");
    return at == std::string::npos ? std::string() : report.substr(at, report.find('\n', at) - at);
  };
  EXPECT_EQ(line_of(positional, "display"), "\"display\": \"builtin:cylinder360\",");
  EXPECT_EQ(line_of(flag, "display"), line_of(positional, "display"));
  EXPECT_NE(line_of(positional, "facets"), "");
  EXPECT_EQ(line_of(flag, "facets"), line_of(positional, "facets"));
  EXPECT_EQ(
      facet::test::run_facet("render builtin:cylinder360 --display builtin:dome180" + size, &both),
      2)
      << both;
}
#endif

#ifndef FACET_TEST_WITHOUT_DRIVER
// What the user of the facet executable reads when a library refuses an option: its flag.
TEST(OptionFlags, TheFacetExecutableNamesTheFlagOfALibrarysOption) {
  const fs::path out = facet::test_paths::scratch_path("option_flags") / "depth.exr";
  std::string output;
  EXPECT_EQ(facet::test::run_facet("depth-image --kind sphere --out " + out.string(), &output), 2);
  EXPECT_EQ(output,
            "facet: error: command line: field '--kind': expected planar or dpci; got 'sphere'\n");
  EXPECT_FALSE(fs::exists(out));
}
#endif

#if !defined(FACET_TEST_WITHOUT_DRIVER) && !defined(FACET_TEST_WITHOUT_CALIBRATION)
// The same for an option a library names as the error's source.
TEST(OptionFlags, TheFacetExecutableNamesTheFlagOfALibrarysOptionAsTheSource) {
  const fs::path display =
      fs::path(FACET_SOURCE_DIR) / "configs/displays/sample_two_projectors.display.json";
  const fs::path out = facet::test_paths::scratch_path("option_flags") / "capture";
  std::string output;
  EXPECT_EQ(facet::test::run_facet("capture --display " + display.string() +
                                       " --camera fake:builtin:wall2x2 --quiet --max-clipped 2"
                                       " --out " +
                                       out.string(),
                                   &output),
            2);
  EXPECT_EQ(output, "facet: error: --max-clipped: a fraction of camera pixels from 0 to 1\n");
  EXPECT_FALSE(fs::exists(out));
}
#endif

}  // namespace
