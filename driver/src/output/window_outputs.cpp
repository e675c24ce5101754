#include "window_outputs.hpp"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <string>

#include "facet/projection/interrupt.hpp"

namespace facet::driver::detail {

std::vector<OutputPlacement> place_display_outputs(const SessionDisplay& display,
                                                   std::span<const MonitorInfo> monitors) {
  std::vector<OutputPlacement> placements;
  for (std::size_t i = 0; i < display.outputs.size(); ++i) {
    placements.push_back(place_output(display.outputs[i].placement, monitors,
                                      display.missing_monitor,
                                      display.outputs[i].spec.warp.output_size, display.source,
                                      "projectors[" + std::to_string(i) + "].output.monitor"));
  }
  return placements;
}

std::vector<OutputsWindow> open_outputs_windows(std::span<const OutputPlacement> placements,
                                                bool span, const std::string& title,
                                                const std::function<void(GLFWwindow*)>& on_open) {
  std::vector<OutputsWindow> windows;
  for (const OutputWindow& layout : output_windows(placements, span)) {
    OutputsWindow window;
    WindowOptions options = layout.options;
    options.share = windows.empty() ? nullptr : windows.front().context.get();
    options.title = title;
    window.context = std::make_unique<GlfwWindowContext>(options);
    on_open(static_cast<GLFWwindow*>(window.context->native_window()));
    window.outputs = layout.outputs;
    for (glm::ivec4 viewport : layout.viewports) {
      if (viewport.z == 0) viewport = glm::ivec4(0, 0, window.context->framebuffer_size());
      window.viewports.push_back(viewport);
    }
    windows.push_back(std::move(window));
  }
  return windows;
}

bool poll_run_ends(std::span<const OutputsWindow> windows, const bool& quit, int& interrupted_by) {
  glfwPollEvents();
  interrupted_by = interrupt_signal();
  if (interrupted_by) return true;
  bool closing = quit;
  for (const OutputsWindow& window : windows) closing = closing || window.context->should_close();
  return closing;
}

WindowPresenter::WindowPresenter(std::span<const OutputTarget> targets) : targets_(targets) {
  for (const OutputTarget& target : targets)
    raw_views_.push_back(Texture::create_view(target.colour(), GL_RGBA8));
  present_ = ProgramBuilder().shader("output/present.vert").shader("output/present.frag").link();
}

void WindowPresenter::present(glm::ivec2 framebuffer_size, const VertexArray& vertex_array,
                              std::span<const std::size_t> outputs,
                              std::span<const glm::ivec4> viewports) const {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDisable(GL_FRAMEBUFFER_SRGB);  // the views hold the encoded bytes already
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glViewport(0, 0, framebuffer_size.x, framebuffer_size.y);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  present_.use();
  glBindVertexArray(vertex_array.id());
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const glm::ivec4& v = viewports[k];
    const glm::ivec2 output_size = targets_[outputs[k]].size();
    glViewport(v.x, v.y, v.z, v.w);
    glUniform2i(0, v.x, v.y);
    glUniform2f(1, float(output_size.x) / float(v.z), float(output_size.y) / float(v.w));
    raw_views_[outputs[k]].bind_unit(0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
}

}  // namespace facet::driver::detail
