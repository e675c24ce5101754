#include "facet/driver/monitors.hpp"

#include <glm/common.hpp>
#include <limits>

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

std::vector<OutputWindow> output_windows(std::span<const OutputPlacement> placements, bool span) {
  std::vector<OutputWindow> windows;
  if (span && !placements.empty()) {
    glm::ivec2 low(std::numeric_limits<int>::max()), high(std::numeric_limits<int>::min());
    for (const OutputPlacement& p : placements) {
      low = glm::min(low, glm::ivec2(p.rect.x, p.rect.y));
      high = glm::max(high, glm::ivec2(p.rect.x + p.rect.z, p.rect.y + p.rect.w));
    }
    OutputWindow& window = windows.emplace_back();
    window.options.position = low;
    window.options.width = high.x - low.x;
    window.options.height = high.y - low.y;
    window.options.decorated = false;
    for (std::size_t i = 0; i < placements.size(); ++i) {
      const glm::ivec4& r = placements[i].rect;
      window.outputs.push_back(i);
      // Desktop y grows down, GL viewports up from the bottom.
      window.viewports.emplace_back(r.x - low.x, high.y - (r.y + r.w), r.z, r.w);
    }
    return windows;
  }
  for (std::size_t i = 0; i < placements.size(); ++i) {
    OutputWindow& window = windows.emplace_back();
    apply_placement(placements[i], window.options);
    window.outputs.push_back(i);
    window.viewports.emplace_back(0, 0, 0, 0);
  }
  return windows;
}

}  // namespace facet::driver
