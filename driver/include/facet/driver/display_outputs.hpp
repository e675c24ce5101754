#pragma once
// The projector outputs of a display named on the command line.
#include <glm/glm.hpp>
#include <optional>
#include <string_view>
#include <vector>

#include "facet/driver/render_method.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::driver {

// `display` is one of
//   builtin:cylinder360  the seed paper's cylinder: cylindrical base, azimuth [-180°, 180°],
//                        tan(elevation) from 1 (top row) to -1 (bottom row); default 1600x1200.
//   builtin:dome180      a 180° fisheye dome master, default 2048x2048, looking straight up: the
//                        image centre is eye +y (up), the bottom edge of the image is eye -z
//                        (the viewer's front), its top edge +z (behind), its right edge +x.
//   builtin:wall2x2      a flat wall 2 m ahead (tan x in [-1.6, 1.6], tan y in [-1, 1]) tiled by
//                        2 × 2 overlapping perspective projectors wall_r<row>c<column>, default
//                        1280x800 each; sessions blend them (load_session_display).
//   FILE.warp.exr        one projector's offset map (FORMATS.md §2); the output is named after the
//                        file.
//   FILE.json            a display.json (FORMATS.md §4): one output per projector, named and
//                        sized as there.
// `size` overrides a built-in's default output size; for a file it must equal the file's size.
// Throws InputError("command line", OptionName "display" or "size", ...) for anything else, and the
// file's own InputError for a bad file.
std::vector<OutputSpec> load_display_outputs(std::string_view display,
                                             std::optional<glm::ivec2> size = std::nullopt);

// load_display_outputs, and for a display.json the file as read: the one read of it, for callers
// that need more of it than the warps (load_session_display, a cluster node's section).
struct LoadedDisplay {
  std::vector<OutputSpec> outputs;
  std::optional<projection_io::DisplayConfig> config;  // set for a display.json
};
// With `allow_glc`, `display` may also be a GLC camera, FILE.glc.json (driver/README.md, "GLC
// cameras"): one output named after the file, with OutputSpec::glc set; otherwise such a file is
// an InputError naming "display".
LoadedDisplay load_display(std::string_view display, std::optional<glm::ivec2> size = std::nullopt,
                           bool allow_glc = false);

}  // namespace facet::driver
