// Libraries name a refused option by its library name, never by a command-line flag; the CLI
// shows it under the flag that sets it, so that what the user reads names what they typed.
#include "../../tools/cli/option_flags.hpp"

#include <gtest/gtest.h>

#include <string>

#include "facet/projection/errors.hpp"

namespace {

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
  EXPECT_EQ(facet::cli::flag_of_option("run", "no_such_option"), "");
}

}  // namespace
