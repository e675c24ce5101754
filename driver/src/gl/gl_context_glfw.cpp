// GLFW window contexts. GL functions still come from libepoxy, so GLFW must not include GL
// headers of its own.
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <mutex>
#include <string>

#include "facet/driver/gl_context.hpp"
#include "facet/driver/monitors.hpp"

namespace facet::driver {

namespace {

// glfwInit/glfwTerminate are process-wide: count the open windows and terminate after the last.
std::mutex glfw_mutex;
int glfw_windows = 0;
std::string glfw_last_error;

void record_glfw_error(int code, const char* description) {
  glfw_last_error = "GLFW error " + std::to_string(code) + ": " + (description ? description : "");
}

GLFWwindow* as_window(void* window) { return static_cast<GLFWwindow*>(window); }

void key_callback(GLFWwindow* window, int key, int /*scancode*/, int action, int /*mods*/) {
  if (key == GLFW_KEY_ESCAPE && action == GLFW_PRESS) glfwSetWindowShouldClose(window, GLFW_TRUE);
}

}  // namespace

GlfwWindowContext::GlfwWindowContext(const WindowOptions& options) {
  {
    std::lock_guard lock(glfw_mutex);
    glfwSetErrorCallback(record_glfw_error);
    if (glfw_windows == 0 && !glfwInit())
      throw GlContextError("GlfwWindowContext: glfwInit failed (no display server?): " +
                           glfw_last_error);
    ++glfw_windows;
  }
  try {
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, options.debug ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_DECORATED, options.decorated ? GLFW_TRUE : GLFW_FALSE);
    // Projector outputs are linear-light framebuffers converted on write.
    glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_TRUE);

    GLFWmonitor* monitor = nullptr;
    int width = options.width, height = options.height;
    if (options.monitor >= 0) {
      int count = 0;
      GLFWmonitor** monitors = glfwGetMonitors(&count);
      if (options.monitor >= count)
        throw GlContextError("GlfwWindowContext: monitor " + std::to_string(options.monitor) +
                             " requested but GLFW sees " + std::to_string(count));
      monitor = monitors[options.monitor];
      // Full screen at the monitor's current mode, so the projector keeps its native timing.
      const GLFWvidmode* mode = glfwGetVideoMode(monitor);
      width = mode->width;
      height = mode->height;
      glfwWindowHint(GLFW_REFRESH_RATE, mode->refreshRate);
    }
    GLFWwindow* share = options.share ? as_window(options.share->native_window()) : nullptr;
    GLFWwindow* window = glfwCreateWindow(width, height, options.title.c_str(), monitor, share);
    if (!window)
      throw GlContextError("GlfwWindowContext: no GL 4.5 core window could be made: " +
                           glfw_last_error);
    window_ = window;
    if (!monitor && options.position)
      glfwSetWindowPos(window, options.position->x, options.position->y);
    glfwSetKeyCallback(window, key_callback);
    glfwMakeContextCurrent(window);
    glfwSwapInterval(options.vsync ? 1 : 0);
    read_info_and_check("glfw");
    if (options.debug) install_debug_output(options.debug_log);
  } catch (...) {
    if (window_) glfwDestroyWindow(as_window(window_));
    window_ = nullptr;
    std::lock_guard lock(glfw_mutex);
    if (--glfw_windows == 0) glfwTerminate();
    throw;
  }
}

GlfwWindowContext::~GlfwWindowContext() {
  if (glfwGetCurrentContext() == as_window(window_)) glfwMakeContextCurrent(nullptr);
  glfwDestroyWindow(as_window(window_));
  std::lock_guard lock(glfw_mutex);
  if (--glfw_windows == 0) glfwTerminate();
}

void GlfwWindowContext::make_current() { glfwMakeContextCurrent(as_window(window_)); }

void GlfwWindowContext::swap_buffers() { glfwSwapBuffers(as_window(window_)); }

glm::ivec2 GlfwWindowContext::framebuffer_size() const {
  glm::ivec2 size{0, 0};
  glfwGetFramebufferSize(as_window(window_), &size.x, &size.y);
  return size;
}

bool GlfwWindowContext::should_close() const {
  return glfwWindowShouldClose(as_window(window_)) == GLFW_TRUE;
}

void GlfwWindowContext::poll_events() { glfwPollEvents(); }

std::vector<MonitorInfo> list_monitors() {
  std::lock_guard lock(glfw_mutex);
  glfwSetErrorCallback(record_glfw_error);
  if (glfw_windows == 0 && !glfwInit())
    throw GlContextError("list_monitors: glfwInit failed (no display server?): " + glfw_last_error);
  std::vector<MonitorInfo> result;
  int count = 0;
  GLFWmonitor** monitors = glfwGetMonitors(&count);
  for (int i = 0; i < count; ++i) {
    MonitorInfo info;
    info.index = i;
    const char* name = glfwGetMonitorName(monitors[i]);
    info.name = name ? name : "";
    glfwGetMonitorPos(monitors[i], &info.position.x, &info.position.y);
    if (const GLFWvidmode* mode = glfwGetVideoMode(monitors[i])) {
      info.size = {mode->width, mode->height};
      info.refresh_hz = mode->refreshRate;
    }
    result.push_back(std::move(info));
  }
  if (glfw_windows == 0) glfwTerminate();
  return result;
}

std::unique_ptr<GlContext> create_window_context(const WindowOptions& options) {
  return std::make_unique<GlfwWindowContext>(options);
}

}  // namespace facet::driver
