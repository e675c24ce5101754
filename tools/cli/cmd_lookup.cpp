// facet lookup: per-pixel source coordinates for tools that only resample.
#include <iostream>
#include <vector>

#include "command.hpp"
#include "facet/interop/lookup.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet::cli {
namespace {

const Registration registration{
    62, [](CLI::App& app) {
      auto* command = app.add_subcommand(
          "lookup",
          "Write an EXR holding, for every output pixel, the base st (R, G) and eye direction "
          "(X, Y, Z) it shows");
      struct Options {
        std::string warp, display, out;
      };
      auto options = std::make_shared<Options>();
      auto* warp = command->add_option("--warp", options->warp, "A .warp.exr");
      auto* display = command->add_option("display,--display", options->display,
                                          "A display.json: one <projector>.lookup.exr each");
      warp->excludes(display);
      command
          ->add_option("--out", options->out,
                       "The .exr to write (with --display: the folder to write into)")
          ->required();
      command->callback([options] {
        if (!options->warp.empty()) {
          check_output_file(options->out, "--out");
          refuse_output_over_inputs(options->out, "--out", {options->warp});
          interop::write_lookup(read_warp(options->warp), options->out);
          std::cout << "wrote " << options->out << "\n";
          return;
        }
        if (options->display.empty()) {
          throw InputError("--warp, --display", "", "expected one of them");
        }
        const auto config = projection_io::read_display_config(options->display);
        // Every warp is read before anything is written: a bad second warp leaves no first file.
        std::vector<Warp> warps;
        for (const auto& projector : config.projectors)
          warps.push_back(read_warp(config.resolve(projector.warp).string()));
        // The folder is written whole or not at all, and replaces only an earlier lookup folder.
        OutputFolderRules rules;
        rules.field = "--out";
        rules.expected =
            "a new path, an empty folder, or a folder of earlier lookups (*.lookup.exr only)";
        rules.is_own_output = [](const std::filesystem::path& folder) {
          return holds_only_files_named(
              folder, [](const std::string& name) { return name.ends_with(".lookup.exr"); });
        };
        rules.inputs.push_back(options->display);
        for (const auto& projector : config.projectors)
          rules.inputs.push_back(config.resolve(projector.warp));
        write_folder_atomically(
            options->out,
            [&](const std::filesystem::path& temporary) {
              for (std::size_t i = 0; i < warps.size(); ++i)
                interop::write_lookup(warps[i],
                                      temporary / (config.projectors[i].name + ".lookup.exr"));
            },
            rules);
        for (const auto& projector : config.projectors)
          std::cout
              << "wrote "
              << (std::filesystem::path(options->out) / (projector.name + ".lookup.exr")).string()
              << "\n";
      });
    }};

}  // namespace
}  // namespace facet::cli
