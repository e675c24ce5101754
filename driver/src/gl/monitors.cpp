#include "facet/driver/monitors.hpp"

#include "facet/projection/errors.hpp"

namespace facet::driver {

OutputPlacement place_output(const projection_io::DisplayOutput& output,
                             std::span<const MonitorInfo> monitors,
                             projection_io::MissingMonitor missing, glm::ivec2 fallback_size,
                             const std::string& source, const std::string& field) {
  using projection_io::DisplayOutput;
  if (output.kind == DisplayOutput::Kind::window)
    return {OutputPlacement::Kind::window, -1, output.window, "window"};

  auto fullscreen_on = [&](const MonitorInfo& monitor, const char* how) {
    return OutputPlacement{OutputPlacement::Kind::fullscreen, monitor.index,
                           glm::ivec4(monitor.position, monitor.size), how};
  };
  for (const MonitorInfo& monitor : monitors)
    if (monitor.name == output.monitor) return fullscreen_on(monitor, "monitor name");
  if (output.position && output.size) {
    for (const MonitorInfo& monitor : monitors)
      if (monitor.position == *output.position && monitor.size == *output.size)
        return fullscreen_on(monitor, "monitor position and size");
  }
  if (missing == projection_io::MissingMonitor::window) {
    const glm::ivec2 position = output.position.value_or(glm::ivec2(0));
    const glm::ivec2 size = output.size.value_or(fallback_size);
    return {OutputPlacement::Kind::window, -1, glm::ivec4(position, size),
            "fallback window (monitor " + output.monitor + " is not connected)"};
  }
  std::string connected;
  for (const MonitorInfo& monitor : monitors)
    connected += (connected.empty() ? "" : ", ") + monitor.name;
  throw InputError(source, field,
                   "a connected monitor (\"" + output.monitor + "\" is not connected; connected: " +
                       (connected.empty() ? "none" : connected) +
                       "); or set \"missing_monitor\": \"window\"");
}

void apply_placement(const OutputPlacement& placement, WindowOptions& options) {
  if (placement.kind == OutputPlacement::Kind::fullscreen) {
    options.monitor = placement.monitor;
  } else {
    options.position = glm::ivec2(placement.rect.x, placement.rect.y);
    options.width = placement.rect.z;
    options.height = placement.rect.w;
  }
}

}  // namespace facet::driver
