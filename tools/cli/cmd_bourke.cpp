// facet bourke: Paul Bourke warp meshes (.data) into a display folder.
#include <fstream>
#include <iostream>
#include <sstream>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/interop/bourke.hpp"
#include "facet/interop/display_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "option_flags.hpp"

namespace facet::cli {
namespace {

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"bourke", {{"out", "--out"}}};

const Registration registration{
    61, [](CLI::App& app) {
      auto* command = app.add_subcommand("bourke", "Import Paul Bourke warp meshes (.data)");
      command->require_subcommand(1);
      struct Options {
        std::string file, out, size = "1920x1080", grid, zenith = "centre";
        double fov = 180, gamma = 2.2;
        DomeOrientationFlags orientation;
      };
      auto options = std::make_shared<Options>();
      auto* import_command = command->add_subcommand(
          "import",
          "Read a mesh into DIR/display.json: an offset map over a fisheye master and a blend "
          "map from the intensity column");
      import_command->add_option("file", options->file, "The .data mesh")->required();
      import_command->add_option("--out", options->out, "The folder to create")->required();
      import_command->add_option("--size", options->size,
                                 "Projector resolution WxH; its aspect must match the mesh's "
                                 "(default 1920x1080)");
      import_command->add_option(
          "--fov", options->fov,
          "Field of view of the fisheye source image, degrees (default 180)");
      import_command->add_option(
          "--grid", options->grid,
          "Node count GXxGY of the warp (default: the mesh's, doubled up to 1025 "
          "per side until its nodes are followed within 1 px)");
      import_command->add_option("--intensity-gamma", options->gamma,
                                 "Linear blend = intensity^gamma (default 2.2)");
      import_command->add_option(
          "--zenith", options->zenith,
          "Where the fisheye master's centre points: centre (default: overhead, the image's bottom "
          "edge to the front, as a dome master) or front (straight ahead, the image's top up)");
      options->orientation.add_to(*import_command);
      import_command->callback([options] {
        const FisheyeZenith zenith =
            fisheye_zenith_from_string(options->zenith, "command line", "--zenith");
        const glm::dmat3 R_eye_dome = options->orientation.value().R_eye_dome();
        interop::check_out_folder(options->out);  // before the import's work
        require_regular_file(options->file);
        std::ifstream stream(options->file, std::ios::binary);
        if (!stream) throw InputError(options->file, "", "cannot open the file");
        std::ostringstream text;
        text << stream.rdbuf();
        const interop::BourkeMesh mesh = interop::parse_bourke(text.str(), options->file);
        interop::BourkeImportOptions import;
        import.output_size = parse_size(options->size, "--size");
        if (!(options->fov > 0 && options->fov <= 360)) {
          throw InputError("--fov", "", "expected degrees in (0, 360]");
        }
        if (!(options->gamma > 0 && options->gamma <= 10)) {
          throw InputError("--intensity-gamma", "", "expected a gamma in (0, 10]");
        }
        import.base = BaseProjection::fisheye(options->fov);
        import.R_eye_base = R_eye_dome * R_dome_fisheye(zenith);
        import.intensity_gamma = options->gamma;
        if (!options->grid.empty()) {
          import.warp_grid = parse_size(options->grid, "--grid");
          if (import.warp_grid.x < 2 || import.warp_grid.y < 2 || import.warp_grid.x > 4096 ||
              import.warp_grid.y > 4096) {
            throw InputError("--grid", "", "expected GXxGY with each count in [2, 4096]");
          }
        }
        interop::ImportedDisplay display;
        display.name = std::filesystem::path(options->file).stem().string();
        display.projectors.push_back(interop::import_bourke(mesh, import, options->file,
                                                            interop::sanitize_name(display.name)));
        for (const std::string& note : display.projectors[0].notes) {
          std::cerr << "facet: note: " << options->file << ": " << note << "\n";
        }
        interop::write_display_folder(display, options->out);
        std::cout << "wrote " << options->out << "/display.json\n";
      });
    }};

}  // namespace
}  // namespace facet::cli
