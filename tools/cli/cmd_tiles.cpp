// facet tiles: a projection tile screen (Trapp & Döllner) into a display folder.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/interop/display_folder.hpp"
#include "facet/interop/tiles.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/facet_error.hpp"
#include "facet/projection/facets.hpp"

namespace facet::cli {
namespace {

const Registration registration{
    63, [](CLI::App& app) {
      auto* command = app.add_subcommand(
          "tiles",
          "Author a display from a projection tile screen (TILES.json: RPTS grid or TPTS "
          "triangles of features x, y, φ, θ, s, f): one warp per continuous piece, with the "
          "facet error of a tolerance build");
      struct Options {
        std::string file, out, size;
        double tolerance = 0.25;
        bool json = false;
      };
      auto options = std::make_shared<Options>();
      command->add_option("file", options->file, "The tile screen, JSON")->required();
      command->add_option("--out", options->out, "The folder to create")->required();
      command->add_option("--size", options->size,
                          "Output size WxH, with the screen's aspect (default: the screen's size)");
      command->add_option("--tolerance", options->tolerance,
                          "Facet tolerance, output px, of the build whose error is reported "
                          "(default 0.25)");
      command->add_flag("--json", options->json, "Print one JSON object per projector");
      command->callback([options] {
        if (!(options->tolerance > 0 && options->tolerance <= kMaxImageSide)) {
          throw InputError("--tolerance", "", "expected a number of pixels in (0, 16384]");
        }
        std::optional<glm::ivec2> size;
        if (!options->size.empty()) size = parse_size(options->size, "--size");
        interop::check_out_folder(options->out);  // before the work
        const interop::TileScreen screen = interop::read_tile_screen(options->file);
        if (size &&
            std::abs(double(size->x) / size->y * screen.size.y / screen.size.x - 1) > 0.01) {
          throw InputError("--size", "",
                           "expected the tile screen's aspect (" + std::to_string(screen.size.x) +
                               "x" + std::to_string(screen.size.y) + ") within 1%");
        }
        interop::TileDisplay tiles =
            interop::build_tile_display(screen, size.value_or(screen.size), options->file);
        for (const std::string& note : tiles.display.notes) {
          std::cerr << "facet: note: " << options->file << ": " << note << "\n";
        }
        nlohmann::json rows = nlohmann::json::array();
        for (std::size_t p = 0; p < tiles.display.projectors.size(); ++p) {
          const interop::ImportedProjector& projector = tiles.display.projectors[p];
          FacetBuildOptions build;
          build.layout = FacetTolerance{options->tolerance};
          build.origin = {"command line", "--tolerance", projector.name};
          const auto start = std::chrono::steady_clock::now();
          const FacetMesh mesh = build_facets(projector.warp, build);
          const double build_ms =
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                  .count();
          const FacetError error = evaluate_facet_error(projector.warp, mesh);
          const glm::ivec2 g = projector.warp.grid_size;
          if (options->json) {
            rows.push_back({{"projector", projector.name},
                            {"base", to_string(projector.warp.base.kind)},
                            {"warp_grid", {g.x, g.y}},
                            {"check_samples", tiles.checked_samples[p]},
                            {"check_max_px", tiles.worst_check_px[p]},
                            {"tolerance_px", options->tolerance},
                            {"facets", mesh.facets.size()},
                            {"max_px", error.max_px},
                            {"rms_px", error.rms_px},
                            {"float32_max_px", error.float32_max_px},
                            {"missed_samples", error.missed_samples},
                            {"build_ms", build_ms}});
          } else {
            for (const std::string& note : projector.notes) {
              std::cout << note << "\n";
            }
            std::printf(
                "%s: %zu facets at tolerance %g px: max %.4f px, RMS %.4f px "
                "(float32 max %.4f px)\n",
                projector.name.c_str(), mesh.facets.size(), options->tolerance, error.max_px,
                error.rms_px, error.float32_max_px);
          }
        }
        interop::write_display_folder(tiles.display, options->out);
        if (options->json) {
          std::cout << rows.dump() << "\n";
        } else {
          std::cout << "wrote " << options->out << "/display.json\n";
        }
      });
    }};

}  // namespace
}  // namespace facet::cli
