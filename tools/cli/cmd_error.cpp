// facet error: how far facets are from the exact warp, against how many there are.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <variant>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/projection/facet_error.hpp"
#include "facet/projection/facets.hpp"

namespace facet::cli {
namespace {

struct ErrorRow {
  std::string display, layout;
  std::size_t facets = 0;
  FacetError error;
  double build_ms = 0;
};

std::string describe(const FacetLayout& layout) {
  if (auto* s = std::get_if<FacetStrips>(&layout)) return "pieces " + std::to_string(s->count);
  if (auto* g = std::get_if<FacetGrid>(&layout)) {
    return "grid " + std::to_string(g->columns) + "x" + std::to_string(g->rows);
  }
  char text[64];
  std::snprintf(text, sizeof text, "tolerance %g px", std::get<FacetTolerance>(layout).px);
  return text;
}

ErrorRow measure(const std::string& display, const Warp& warp, const FacetLayout& layout) {
  ErrorRow row;
  row.display = display;
  row.layout = describe(layout);
  const auto start = std::chrono::steady_clock::now();
  const FacetMesh mesh = build_facets(warp, {layout});
  row.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  row.facets = mesh.facets.size();
  // Which builder a tolerance layout ended with: only the tensor grid records its breaks.
  if (std::holds_alternative<FacetTolerance>(layout)) {
    row.layout += mesh.s_breaks.empty() ? ", bisection" : ", tensor";
  }
  row.error = evaluate_facet_error(warp, mesh);
  return row;
}

nlohmann::json to_json(const ErrorRow& row) {
  return {{"display", row.display},
          {"layout", row.layout},
          {"facets", row.facets},
          {"max_px", row.error.max_px},
          {"rms_px", row.error.rms_px},
          {"float32_max_px", row.error.float32_max_px},
          {"float32_rms_px", row.error.float32_rms_px},
          {"samples", row.error.samples},
          {"missed_samples", row.error.missed_samples},
          {"worst_q", {row.error.worst_q.x, row.error.worst_q.y}},
          {"build_ms", row.build_ms}};
}

void print_header() {
  std::printf("%-34s %-28s %8s %10s %10s %12s %10s\n", "display", "facets from", "facets", "max px",
              "rms px", "float32 px", "build ms");
}

void print_row(const ErrorRow& row) {
  std::printf("%-34s %-28s %8zu %10.4f %10.4f %12.2e %10.1f\n", row.display.c_str(),
              row.layout.c_str(), row.facets, row.error.max_px, row.error.rms_px,
              row.error.float32_max_px, row.build_ms);
  if (row.error.missed_samples) {
    std::printf("  warning: %zu covered samples fell in no facet\n", row.error.missed_samples);
  }
  std::fflush(stdout);
}

void sweep(bool json) {
  const Warp cylinder = Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {1600, 1200});
  const Warp dome = Warp::analytic(BaseProjection::fisheye(180), {2048, 2048});
  std::vector<std::tuple<std::string, const Warp*, FacetLayout>> cases;
  for (int n : {20, 40, 80, 160, 320, 640}) {
    cases.emplace_back("cylinder 360x90 1600x1200", &cylinder, FacetStrips{n});
  }
  for (int n : {4, 8, 16, 32, 64, 128}) {
    cases.emplace_back("dome fisheye 180 2048x2048", &dome, FacetGrid{n, n});
  }
  for (const auto* warp : {&cylinder, &dome}) {
    for (double tolerance : {1.0, 0.5, 0.25, 0.1, 0.05}) {
      cases.emplace_back(
          warp == &cylinder ? "cylinder 360x90 1600x1200" : "dome fisheye 180 2048x2048", warp,
          FacetTolerance{tolerance});
    }
  }
  nlohmann::json rows = nlohmann::json::array();
  if (!json) print_header();
  for (const auto& [name, warp, layout] : cases) {
    const ErrorRow row = measure(name, *warp, layout);
    if (json) {
      rows.push_back(to_json(row));
    } else {
      print_row(row);
    }
  }
  if (json) std::cout << rows.dump(2) << "\n";
}

const Registration registration{
    10, [](CLI::App& app) {
      auto* command = app.add_subcommand(
          "error", "Facet count, max and RMS error (output px), float32 error and build time");
      struct Options {
        DisplayFlags display;
        LayoutFlags layout;
        bool json = false;
        bool sweep = false;
      };
      auto options = std::make_shared<Options>();
      options->display.add_to(*command);
      options->layout.add_to(*command);
      command->add_flag("--json", options->json, "Print one JSON object");
      command->add_flag(
          "--sweep", options->sweep,
          "Error against facet count for the seed's 360°×90° cylinder at 1600×1200 and a "
          "180° dome master at 2048×2048");
      command->callback([options] {
        if (options->sweep) return sweep(options->json);
        const Warp warp = options->display.make_warp();
        const std::string name = options->display.warp_path.empty()
                                     ? options->display.base + " " + options->display.size
                                     : options->display.warp_path;
        const ErrorRow row = measure(name, warp, options->layout.layout());
        if (options->json) {
          std::cout << to_json(row).dump() << "\n";
        } else {
          print_header();
          print_row(row);
        }
      });
    }};

}  // namespace
}  // namespace facet::cli
