// facet display: writes a display (a built-in, a warp file or a display.json) as a display.json
// folder with its warps and blends, ready to edit (monitor names) and to run.
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/driver/session.hpp"
#include "option_flags.hpp"

namespace facet::cli {
namespace {

struct DisplayOptions {
  std::string display;
  std::string size;
  std::string name;
  bool name_given = false;
  std::string out;
  DomeOrientationFlags orientation;
};

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"display",
                               {{"display", "--display"}, {"size", "--size"}, {"out", "--out"}}};

const Registration registration{
    45, [](CLI::App& app) {
      auto options = std::make_shared<DisplayOptions>();
      auto* command = app.add_subcommand(
          "display",
          "Write a display (builtin:cylinder360, builtin:dome180, builtin:wall2x2, a .warp.exr or "
          "a display.json) as a folder holding display.json, the warps and the blends");
      command->add_option("display,--display", options->display, "The display to write")
          ->required();
      command->add_option("--size", options->size, "Output size WxH of a built-in display");
      command->add_option("--name", options->name, "Name in display.json (default: the folder's)")
          ->each([options](const std::string&) { options->name_given = true; });
      command->add_option("--out", options->out, "Folder to create")->required();
      options->orientation.add_to(*command);
      command->callback([options] {
        if (options->name_given) check_name(options->name, "--name");
        std::optional<glm::ivec2> size;
        if (!options->size.empty()) size = parse_size(options->size, "--size");
        const auto orientation = builtin_dome_orientation(options->orientation, options->display);
        driver::SessionDisplay display = driver::load_session_display(options->display, size);
        for (auto& output : display.outputs) {
          if (orientation) orient_warp(output.spec.warp, *orientation);
        }
        const std::filesystem::path out(options->out);
        const std::string name = options->name.empty() ? out.filename().string() : options->name;
        driver::write_session_display(display, name, out);
        std::cout << "facet display: " << display.outputs.size() << " output(s) written to "
                  << (out / "display.json").string() << "\n";
      });
    }};

}  // namespace
}  // namespace facet::cli
