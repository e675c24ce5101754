// facet mpcdi: MPCDI containers in and out (interop/README.md documents the conventions).
#include <cmath>
#include <cstdio>
#include <iostream>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/interop/display_folder.hpp"
#include "facet/interop/mpcdi.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "option_flags.hpp"

namespace facet::cli {
namespace {

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"mpcdi", {{"out", "--out"}, {"values", "--warp-values"}}};

const Registration registration{
    60, [](CLI::App& app) {
      auto* command = app.add_subcommand("mpcdi", "Import or export MPCDI containers (.mpcdi)");
      command->require_subcommand(1);

      struct ExportOptions {
        std::string display, out, profile = "3d";
        double spacing = 4.0;
      };
      auto exporting = std::make_shared<ExportOptions>();
      auto* export_command = command->add_subcommand(
          "export",
          "Write a display.json's warps and blends as an MPCDI container (profile 3d or a3)");
      export_command
          ->add_option("display,--display", exporting->display, "display.json (or its folder)")
          ->required();
      export_command->add_option("--out", exporting->out, "The .mpcdi file to write")->required();
      export_command->add_option("--node-spacing", exporting->spacing,
                                 "Spacing of the PFM warp nodes in output pixels (default 4)");
      export_command->add_option("--profile", exporting->profile,
                                 "3d (default: a frustum and source positions per node) or a3 "
                                 "(3D screen points per node: on display.json's screen, else on "
                                 "the unit sphere around the eye)");
      export_command->callback([exporting] {
        if (!(exporting->spacing >= 0.5 && exporting->spacing <= 1024)) {
          throw InputError("--node-spacing", "", "expected a spacing in [0.5, 1024] pixels");
        }
        check_output_file(exporting->out, "--out");  // before the export's work
        const auto display = projection_io::read_display_config(exporting->display);
        interop::MpcdiExportOptions options;
        options.node_spacing_px = exporting->spacing;
        if (exporting->profile == "a3") {
          options.profile = interop::MpcdiProfile::advanced_3d;
        } else if (exporting->profile != "3d") {
          throw InputError("--profile", "", "expected 3d or a3");
        }
        interop::write_zip_file(exporting->out, interop::export_mpcdi(display, options));
        std::cout << "wrote " << exporting->out << " (" << display.projectors.size()
                  << " regions)\n";
      });

      struct ImportOptions {
        std::string file, out, values = "auto", grid, eye;
        DomeOrientationFlags orientation;
      };
      auto importing = std::make_shared<ImportOptions>();
      auto* import_command = command->add_subcommand(
          "import", "Read an MPCDI container into DIR/display.json with warps and blends");
      import_command->add_option("file", importing->file, "The .mpcdi file")->required();
      import_command->add_option("--out", importing->out, "The folder to create")->required();
      import_command->add_option(
          "--warp-values", importing->values,
          "How the PFM is written: absolute (the standard: source positions on a grid over the "
          "output), offset (SGCT: offsets on a grid over the source) or auto (default: whichever "
          "gives an unfolded map)");
      import_command->add_option("--grid", importing->grid,
                                 "Node count GXxGY of the imported warps (default: as recorded "
                                 "by facet's export, else the PFM's)");
      import_command->add_option("--eye", importing->eye,
                                 "Profile a3: the eye point x,y,z in the file's frame and "
                                 "geometricUnit (default: the frame's origin)");
      importing->orientation.add_to(*import_command);
      import_command->callback([importing] {
        const DomeOrientation orientation = importing->orientation.value();
        interop::check_out_folder(importing->out);  // before the import's work
        interop::MpcdiImportOptions options;
        if (importing->values == "absolute") {
          options.values = interop::MpcdiWarpValues::absolute;
        } else if (importing->values == "offset") {
          options.values = interop::MpcdiWarpValues::offset;
        } else if (importing->values != "auto") {
          throw InputError("--warp-values", "", "expected auto, absolute or offset");
        }
        if (!importing->grid.empty()) {
          const glm::ivec2 grid = parse_size(importing->grid, "--grid");
          if (grid.x < 2 || grid.y < 2 || grid.x > 4096 || grid.y > 4096) {
            throw InputError("--grid", "", "expected GXxGY with each count in [2, 4096]");
          }
          options.warp_grid = grid;
        }
        if (!importing->eye.empty()) {
          glm::dvec3 eye;
          char end = 0;
          if (std::sscanf(importing->eye.c_str(), "%lf,%lf,%lf%c", &eye.x, &eye.y, &eye.z, &end) !=
                  3 ||
              !(std::abs(eye.x) <= 1e7 && std::abs(eye.y) <= 1e7 && std::abs(eye.z) <= 1e7)) {
            throw InputError("--eye", "", "expected x,y,z: three numbers within ±1e7");
          }
          options.eye = eye;
        }
        const auto files = interop::read_zip_file(importing->file);
        auto display = interop::import_mpcdi(files, importing->file, options);
        for (auto& projector : display.projectors) orient_warp(projector.warp, orientation);
        for (const std::string& note : display.notes) std::cerr << "facet: note: " << note << "\n";
        interop::write_display_folder(display, importing->out);
        std::cout << "wrote " << importing->out << "/display.json (" << display.projectors.size()
                  << " projectors)\n";
      });
    }};

}  // namespace
}  // namespace facet::cli
