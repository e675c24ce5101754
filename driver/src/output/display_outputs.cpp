#include "facet/driver/display_outputs.hpp"

#include <filesystem>
#include <memory>
#include <string>

#include "facet/projection/errors.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/glc_file.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet::driver {

namespace {

// One output per projector of `config`, its warp read and checked against the projector's size.
std::vector<OutputSpec> display_config_outputs(const projection_io::DisplayConfig& config,
                                               const std::string& source) {
  std::vector<OutputSpec> outputs;
  for (const auto& projector : config.projectors) {
    const std::string path = config.resolve(projector.warp).string();
    Warp warp = read_warp(path);
    if (warp.output_size != projector.size) {
      throw InputError(source, "projectors." + projector.name + ".size",
                       "expected the size of " + path);
    }
    outputs.push_back({projector.name, std::move(warp)});
  }
  return outputs;
}

}  // namespace

LoadedDisplay load_display(std::string_view display, std::optional<glm::ivec2> size,
                           bool allow_glc) {
  if (size && (size->x < 1 || size->y < 1)) {
    throw InputError("command line", OptionName{"size"}, "expected a positive output size");
  }
  LoadedDisplay loaded;
  std::vector<OutputSpec>& outputs = loaded.outputs;
  if (display == "builtin:cylinder360") {
    outputs.push_back({"cylinder360", Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1),
                                                     size.value_or(glm::ivec2(1600, 1200)))});
  } else if (display == "builtin:dome180") {
    // Rotates the base's view axis (-z) onto eye +y and the base's up (+y) onto eye +z, so the
    // bottom of the dome master is the viewer's front, as in the usual dome master layout.
    const glm::dmat3 R_eye_base(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0));
    outputs.push_back({"dome180", Warp::analytic(BaseProjection::fisheye(180),
                                                 size.value_or(glm::ivec2(2048, 2048)),
                                                 glm::ivec2(2, 2), R_eye_base)});
  } else if (display == "builtin:wall2x2") {
    // A flat wall 2 m in front of the eye, 6.4 m × 4 m (tan x in [-1.6, 1.6], tan y in [-1, 1]),
    // tiled by 2 × 2 projectors that overlap across tan x in [-0.16, 0.16] and tan y in
    // [-0.1, 0.1] (see wall2x2_blend in session.cpp for their weights).
    const glm::ivec2 tile_size = size.value_or(glm::ivec2(1280, 800));
    const double x_edges[2][2] = {{-1.6, 0.16}, {-0.16, 1.6}};
    const double y_edges[2][2] = {{1.0, -0.1}, {0.1, -1.0}};  // top, bottom of each row
    for (int row = 0; row < 2; ++row)
      for (int column = 0; column < 2; ++column)
        outputs.push_back(
            {"wall_r" + std::to_string(row) + "c" + std::to_string(column),
             Warp::analytic(BaseProjection::perspective(x_edges[column][0], x_edges[column][1],
                                                        y_edges[row][0], y_edges[row][1]),
                            tile_size)});
  } else if (display.ends_with(".warp.exr")) {
    const std::string path(display);
    Warp warp = read_warp(path);
    if (size && *size != warp.output_size) {
      throw InputError("command line", OptionName{"size"},
                       "expected the size of " + path + " (" + std::to_string(warp.output_size.x) +
                           "x" + std::to_string(warp.output_size.y) + ") or none");
    }
    std::string name = std::filesystem::path(path).filename().string();
    name = name.substr(0, name.size() - std::string_view(".warp.exr").size());
    outputs.push_back({name.empty() ? "output" : name, std::move(warp)});
  } else if (display.ends_with(".glc.json")) {
    if (!allow_glc) {
      throw InputError(
          "command line", OptionName{"display"},
          "expected a display; " + std::string(display) +
              " is a GLC camera, which only the glc and glc-2pass render methods draw");
    }
    auto camera = std::make_shared<const PiecewiseGlc>(read_glc_camera(std::string(display)));
    if (size && *size != camera->size) {
      throw InputError("command line", OptionName{"size"},
                       "expected the size of " + std::string(display) + " (" +
                           std::to_string(camera->size.x) + "x" + std::to_string(camera->size.y) +
                           ") or none");
    }
    std::string name = std::filesystem::path(display).filename().string();
    name = name.substr(0, name.size() - std::string_view(".glc.json").size());
    // The warp only carries the output size: no warp describes a GLC camera.
    outputs.push_back({name.empty() ? "output" : name,
                       Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), camera->size),
                       std::move(camera)});
  } else if (display.ends_with(".json")) {
    projection_io::DisplayConfig config =
        projection_io::read_display_config(std::filesystem::path(display));
    if (size) {
      throw InputError("command line", OptionName{"size"},
                       "expected none with a display.json (each projector has its own size)");
    }
    outputs = display_config_outputs(config, std::string(display));
    loaded.config = std::move(config);
  } else {
    throw InputError(
        "command line", OptionName{"display"},
        "expected builtin:cylinder360, builtin:dome180, builtin:wall2x2, a .warp.exr file or a "
        "display.json; got '" +
            std::string(display) + "'");
  }
  return loaded;
}

std::vector<OutputSpec> load_display_outputs(std::string_view display,
                                             std::optional<glm::ivec2> size) {
  return load_display(display, size).outputs;
}

}  // namespace facet::driver
