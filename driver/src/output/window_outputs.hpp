#pragma once
// What the windowed runs (a session's, run_windowed_session; content playback's,
// run_windowed_play) share: placing the display's outputs on the monitors, opening their
// windows, and showing the rendered outputs in them.
#include <cstddef>
#include <functional>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "facet/driver/gl_context.hpp"
#include "facet/driver/gl_objects.hpp"
#include "facet/driver/monitors.hpp"
#include "facet/driver/program.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/driver/session.hpp"

struct GLFWwindow;

namespace facet::driver::detail {

// Where each of the display's outputs goes among `monitors` (place_output); a missing monitor's
// InputError names projectors[i].output.monitor.
std::vector<OutputPlacement> place_display_outputs(const SessionDisplay& display,
                                                   std::span<const MonitorInfo> monitors);

// A window that shows outputs: the outputs (indices into the placements) and where each shows
// (x, y, width, height in framebuffer pixels, y up from the bottom as GL has it), and the
// window's own vertex array (vertex arrays are not shared), made by the caller.
struct OutputsWindow {
  std::unique_ptr<GlfwWindowContext> context;
  std::vector<std::size_t> outputs;
  std::vector<glm::ivec4> viewports;
  VertexArray vertex_array;
};

// Opens the windows of output_windows(placements, span), titled `title`, each sharing the first
// one's objects; `on_open` sets up each window's input (user pointer, callbacks) as it opens. A
// viewport of zero size becomes the window's whole framebuffer.
std::vector<OutputsWindow> open_outputs_windows(std::span<const OutputPlacement> placements,
                                                bool span, const std::string& title,
                                                const std::function<void(GLFWwindow*)>& on_open);

// Processes the windows' events (glfwPollEvents), then whether the run ends before its next
// frame: on SIGINT or SIGTERM (interrupt_signal, kept in `interrupted_by`), on `quit` (which the
// windows' key callbacks set), or when a window was asked to close.
bool poll_run_ends(std::span<const OutputsWindow> windows, const bool& quit, int& interrupted_by);

// Draws rendered outputs into windows' default framebuffers, byte for byte: each output's colour
// through an RGBA8 view (the encoded bytes, not decoded from sRGB) by output/present.frag.
// Made, used and destroyed with contexts that share the outputs' objects.
class WindowPresenter {
 public:
  explicit WindowPresenter(std::span<const OutputTarget> targets);
  // Clears the current context's default framebuffer (`framebuffer_size` pixels) to black and
  // draws output outputs[k] into viewports[k] (GL, from the bottom), scaled to fill it, with
  // `vertex_array`, the context's own.
  void present(glm::ivec2 framebuffer_size, const VertexArray& vertex_array,
               std::span<const std::size_t> outputs, std::span<const glm::ivec4> viewports) const;

 private:
  std::span<const OutputTarget> targets_;
  std::vector<Texture> raw_views_;  // per output: its colour as RGBA8
  Program present_;
};

}  // namespace facet::driver::detail
