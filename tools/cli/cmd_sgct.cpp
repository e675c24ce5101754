// facet sgct: SGCT cluster configurations with SCISS .sgc or SimCAD meshes, or bare .sgc meshes,
// into a display folder; and a display out as an SGCT cluster.
#include <cctype>
#include <filesystem>
#include <iostream>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/interop/display_folder.hpp"
#include "facet/interop/sgct_cluster.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/display_config.hpp"
#include "option_flags.hpp"

namespace facet::cli {
namespace {

// ".sgc" for "D/Channel1.SGC".
std::string lowercase_extension(const std::string& file) {
  std::string extension = std::filesystem::path(file).extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"sgct", {{"out", "--out"}}};

const Registration registration{
    61, [](CLI::App& app) {
      auto* command = app.add_subcommand(
          "sgct", "Import or export SGCT cluster configurations with SCISS .sgc meshes and masks");
      command->require_subcommand(1);

      struct ExportOptions {
        std::string display, out;
        double spacing = 4, gamma = 2.2;
      };
      auto exporting = std::make_shared<ExportOptions>();
      auto* export_command = command->add_subcommand(
          "export",
          "Write a display.json as an SGCT cluster: cluster.xml, a SCISS .sgc mesh and a mask "
          "PNG per projector, into DIR");
      export_command
          ->add_option("display,--display", exporting->display, "display.json (or its folder)")
          ->required();
      export_command->add_option("--out", exporting->out, "The folder to create")->required();
      export_command->add_option("--node-spacing", exporting->spacing,
                                 "Spacing of the mesh vertices in output pixels (default 4)");
      export_command->add_option("--mask-gamma", exporting->gamma,
                                 "mask = blend^(1/gamma), 8 bits (default 2.2)");
      export_command->callback([exporting] {
        if (!(exporting->spacing >= 1 && exporting->spacing <= 1024)) {
          throw InputError("--node-spacing", "", "expected a spacing in [1, 1024] pixels");
        }
        if (!(exporting->gamma > 0 && exporting->gamma <= 10)) {
          throw InputError("--mask-gamma", "", "expected a gamma in (0, 10]");
        }
        interop::check_out_folder(exporting->out);  // before the export's work
        const auto display = projection_io::read_display_config(exporting->display);
        interop::SgctExportOptions options;
        options.node_spacing_px = exporting->spacing;
        options.mask_gamma = exporting->gamma;
        interop::write_files_folder(interop::export_sgct(display, options), exporting->out);
        std::cout << "wrote " << exporting->out << "/cluster.xml (" << display.projectors.size()
                  << " projectors)\n";
      });

      struct Options {
        std::vector<std::string> files;
        std::string out, size = "1920x1200", grid;
        double gamma = 2.2;
        DomeOrientationFlags orientation;
      };
      auto options = std::make_shared<Options>();
      auto* import_command = command->add_subcommand(
          "import",
          "Read CLUSTER.xml (every viewport with a .sgc or .simcad mesh and its mask) or bare .sgc "
          "meshes into DIR/display.json");
      import_command->add_option("files", options->files, "CLUSTER.xml, or one or more .sgc files")
          ->required();
      import_command->add_option("--out", options->out, "The folder to create")->required();
      import_command->add_option(
          "--size", options->size,
          "Projector resolution WxH of bare .sgc meshes (default 1920x1200; a cluster "
          "configuration gives its own)");
      import_command->add_option(
          "--grid", options->grid,
          "Node count GXxGY of every warp (default: the mesh's, doubled up to 1025 per side "
          "until it is followed within 0.25 px)");
      import_command->add_option("--mask-gamma", options->gamma,
                                 "Linear blend = mask^gamma (default 2.2)");
      options->orientation.add_to(*import_command);
      import_command->callback([options] {
        const DomeOrientation orientation = options->orientation.value();
        interop::check_out_folder(options->out);  // before the import's work
        if (!(options->gamma > 0 && options->gamma <= 10)) {
          throw InputError("--mask-gamma", "", "expected a gamma in (0, 10]");
        }
        glm::ivec2 grid{0, 0};
        if (!options->grid.empty()) {
          grid = parse_size(options->grid, "--grid");
          if (grid.x < 2 || grid.y < 2 || grid.x > 4096 || grid.y > 4096) {
            throw InputError("--grid", "", "expected GXxGY with each count in [2, 4096]");
          }
        }
        for (const std::string& file : options->files) {
          if (lowercase_extension(file) == ".simcad") {
            throw InputError(file, "",
                             "a .simcad mesh holds no frustum: import the SGCT cluster file next "
                             "to it (such as dome_bravo.xml), whose viewports' "
                             "<PlanarProjection> give the frusta");
          }
        }
        const bool meshes = lowercase_extension(options->files.front()) == ".sgc";
        if (!meshes && options->files.size() != 1) {
          throw InputError(options->files[1], "",
                           "expected either one cluster configuration or .sgc meshes only");
        }
        interop::ImportedDisplay display;
        if (meshes) {
          std::vector<std::filesystem::path> paths;
          for (const std::string& file : options->files) {
            if (lowercase_extension(file) != ".sgc") {
              throw InputError(file, "", "expected a .sgc mesh like the other files");
            }
            paths.emplace_back(file);
          }
          display = interop::import_sgc_files(paths, parse_size(options->size, "--size"), grid);
        } else {
          interop::SgctImportOptions import;
          import.mask_gamma = options->gamma;
          import.warp_grid = grid;
          display = interop::import_sgct_cluster(options->files.front(), import);
        }
        for (auto& projector : display.projectors) orient_warp(projector.warp, orientation);
        for (const std::string& note : display.notes) std::cerr << "facet: note: " << note << "\n";
        for (const auto& projector : display.projectors) {
          for (const std::string& note : projector.notes) {
            std::cerr << "facet: note: " << projector.name << ": " << note << "\n";
          }
        }
        interop::write_display_folder(display, options->out);
        std::cout << "wrote " << options->out << "/display.json (" << display.projectors.size()
                  << " projectors)\n";
      });
    }};

}  // namespace
}  // namespace facet::cli
