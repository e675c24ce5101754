#pragma once
// Showing structured-light patterns on projector outputs for live capture (`facet capture`): a
// grey image per output, pixel for pixel, each output otherwise black. Two presenters share one
// interface: windowed (a GLFW window per projector, fullscreen on its monitor as `facet run`
// places it, vsync) and headless (EGL, one framebuffer object per output; for tests and the fake
// camera). Both draw the image through the same GL path (a texture drawn 1:1 by
// output/present.frag) and read back what the presented framebuffer holds.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <glm/vec2.hpp>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "facet/projection_io/display_config.hpp"

namespace facet::driver {

class PatternPresenter {
 public:
  virtual ~PatternPresenter() = default;

  virtual std::size_t output_count() const = 0;
  // Output size (W, H) in output pixels.
  virtual glm::ivec2 output_size(std::size_t output) const = 0;

  // Shows `grey` (W·H 8-bit values, row 0 at the top) on `output` and black on every other
  // output. Returns once the new image has been presented (windowed: after the buffer swap at
  // vsync and glFinish) and then the settle time has passed. Asserts on a wrong size.
  virtual void show(std::size_t output, std::span<const std::uint8_t> grey) = 0;
  // Black on every output (then the settle time).
  virtual void blank() = 0;
  // What `output` shows now: its presented framebuffer read back (the red channel), W·H bytes,
  // row 0 at the top. All zeros for an output that shows black.
  virtual const std::vector<std::uint8_t>& shown(std::size_t output) const = 0;
  // True once the user closed a window or pressed Escape (windowed); never for headless.
  virtual bool closed() = 0;
};

// One framebuffer object per output size, on a headless EGL context made here (current on the
// calling thread). Throws GlContextError when no context can be made.
std::unique_ptr<PatternPresenter> create_headless_presenter(
    std::vector<glm::ivec2> sizes, std::chrono::milliseconds settle = std::chrono::milliseconds(0));

// One window per projector of `display`, placed as `facet run` places it (place_output: monitor
// name, then recorded position and size, then `missing_monitor`): fullscreen on its monitor at
// the monitor's mode, vsync on. The window's framebuffer must be at least the projector's size;
// the image is drawn 1:1 at its top-left corner. Needs a display server (GlContextError without
// one); InputError for a missing monitor (as `facet run`) or a monitor smaller than its projector.
std::unique_ptr<PatternPresenter> create_windowed_presenter(
    const projection_io::DisplayConfig& display, const std::string& source,
    std::chrono::milliseconds settle);

}  // namespace facet::driver
