#pragma once
// Monitors as the window system reports them, and the choice of where each projector's output
// goes (display.json `output`, `missing_monitor`).
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>
#include <span>
#include <string>
#include <vector>

#include "facet/driver/gl_context.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::driver {

struct MonitorInfo {
  int index = 0;              // GLFW's monitor index at the time of listing
  std::string name;           // e.g. the connector ("DP-1", "DUMMY0") or the EDID name
  glm::ivec2 position{0, 0};  // desktop position of its top-left corner, pixels (y down)
  glm::ivec2 size{0, 0};      // current video mode, pixels
  int refresh_hz = 0;
};

// The connected monitors. Needs a display server (X11 or Wayland): throws GlContextError
// without one.
std::vector<MonitorInfo> list_monitors();

struct OutputPlacement {
  enum class Kind { fullscreen, window };
  Kind kind = Kind::window;
  int monitor = -1;             // fullscreen: index into the monitor list
  glm::ivec4 rect{0, 0, 0, 0};  // the desktop rectangle x, y, width, height it covers
  std::string how;              // "monitor name", "monitor position and size", "window", ...
};

// Where `output` goes among `monitors`. A monitor output matches by name first, then by the
// position and size the config recorded. When nothing matches, `missing` decides: a fallback
// window at the recorded position and size (or `fallback_size` at the origin), or an InputError
// naming `source` and `field` and listing the connected monitors.
OutputPlacement place_output(const projection_io::DisplayOutput& output,
                             std::span<const MonitorInfo> monitors,
                             projection_io::MissingMonitor missing, glm::ivec2 fallback_size,
                             const std::string& source, const std::string& field);

// Sets where a window goes: full screen on the placement's monitor, or at its desktop rectangle.
void apply_placement(const OutputPlacement& placement, WindowOptions& options);

// One window of a windowed session and the outputs it shows, each in a viewport of its own
// (x, y, width, height in framebuffer pixels, y up from the bottom as GL has it); a viewport of
// zero size is the window's whole framebuffer, whose size is known once the window is open.
struct OutputWindow {
  WindowOptions options;
  std::vector<std::size_t> outputs;  // indices into `placements`
  std::vector<glm::ivec4> viewports;
};
// The windows that show outputs placed at `placements`: with `span`, one borderless window over
// the bounding rectangle of them all, each output in its own rectangle of it; otherwise one window
// per output, where apply_placement puts it.
std::vector<OutputWindow> output_windows(std::span<const OutputPlacement> placements, bool span);

}  // namespace facet::driver
