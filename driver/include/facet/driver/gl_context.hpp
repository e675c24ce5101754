#pragma once
// An OpenGL 4.5 core context behind one interface: EGL headless (no display; render into FBOs)
// or a GLFW window. GL functions are loaded through libepoxy, so any code that includes
// <epoxy/gl.h> may call GL once a context is current on the calling thread.
#include <glm/vec2.hpp>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "facet/driver/log.hpp"

namespace facet::driver {

// No OpenGL 4.5 core context could be made (no EGL/GLFW platform, no suitable device or driver,
// or the driver offers an older GL). The message says which step failed and why.
class GlContextError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What the driver reports about the current context.
struct GlInfo {
  std::string vendor;         // GL_VENDOR, e.g. "NVIDIA Corporation" or "Mesa"
  std::string renderer;       // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version;        // GL_VERSION
  std::string glsl_version;   // GL_SHADING_LANGUAGE_VERSION
  int major = 0, minor = 0;   // GL_MAJOR_VERSION / GL_MINOR_VERSION
  bool core_profile = false;  // GL_CONTEXT_CORE_PROFILE_BIT is set
  bool debug = false;         // GL_CONTEXT_FLAG_DEBUG_BIT is set
  std::string platform;       // how the context was made: "egl-device", "egl-surfaceless", "glfw"
};

class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Makes this context current on the calling thread. A context is current on at most one thread.
  virtual void make_current() = 0;
  // Presents the default framebuffer. Headless contexts have none; there it only flushes.
  virtual void swap_buffers() = 0;
  // Size in pixels of the default framebuffer; (0,0) for headless contexts, which draw into FBOs.
  virtual glm::ivec2 framebuffer_size() const = 0;
  // True when the default framebuffer (object 0) exists and can be drawn to.
  virtual bool has_default_framebuffer() const = 0;

  // Vendor, renderer and version of this context (read once, when it was made).
  const GlInfo& info() const { return info_; }

 protected:
  GlContext() = default;
  // Reads GlInfo from the current context and throws GlContextError when it is not GL >= 4.5
  // core. Call once from the derived constructor after making the context current.
  void read_info_and_check(std::string platform);
  // Routes the KHR_debug messages of medium and high severity of this context, which must be
  // current, to `log` as warnings ("GL debug: MESSAGE"), synchronously; nothing when `log` is
  // empty.
  void install_debug_output(LogSink log);

 private:
  GlInfo info_;
  LogSink debug_log_;  // the debug callback's user pointer: lives as long as the context
};

enum class EglPlatform {
  automatic,    // a GPU device through EGL_EXT_platform_device, else EGL_MESA_platform_surfaceless
  device,       // only EGL_EXT_platform_device (including Mesa's software device)
  surfaceless,  // only EGL_MESA_platform_surfaceless (Mesa, e.g. llvmpipe)
};

struct HeadlessOptions {
  EglPlatform platform = EglPlatform::automatic;
  // Index into eglQueryDevicesEXT's list, or -1 to take the first device that gives GL 4.5 core.
  int device_index = -1;
  // Requests a debug context (GL_CONTEXT_FLAG_DEBUG_BIT).
  bool debug = false;
  // A debug context's KHR_debug messages of medium and high severity, as warnings
  // ("GL debug: MESSAGE"); empty: none are reported.
  LogSink debug_log;
};

// Makes an EGL context with no surface (EGL_KHR_surfaceless_context) and makes it current on the
// calling thread. Draw into framebuffer objects. With EglPlatform::automatic it tries every EGL
// device that is not Mesa's software device, then Mesa's surfaceless platform (llvmpipe on a
// machine with no GPU). The environment variable FACET_EGL_PLATFORM=device|surfaceless overrides
// `automatic`. Throws GlContextError when no GL 4.5 core context can be made.
std::unique_ptr<GlContext> create_headless_context(const HeadlessOptions& options = {});

class GlfwWindowContext;

struct WindowOptions {
  int width = 1280, height = 720;  // window size in screen coordinates (windowed mode)
  std::string title = "facet";
  int monitor = -1;  // -1: windowed; otherwise full screen on this GLFW monitor index
  // Windowed mode: the desktop position of the window's content area (top-left, y down); unset
  // lets the window system choose.
  std::optional<glm::ivec2> position;
  bool decorated = true;  // windowed mode: title bar and borders
  bool vsync = true;      // swap interval 1 (else 0)
  bool visible = true;
  bool debug = false;  // as in HeadlessOptions
  LogSink debug_log;   // as in HeadlessOptions
  // Shares textures and buffers (not framebuffers or vertex arrays) with this window's context.
  const GlfwWindowContext* share = nullptr;
};

// A GLFW window with a GL 4.5 core context, current on the calling thread after construction.
// GLFW needs a display server (X11 or Wayland), so this is not available on headless machines;
// there it throws GlContextError. GLFW allows windows on the main thread only.
class GlfwWindowContext : public GlContext {
 public:
  explicit GlfwWindowContext(const WindowOptions& options = {});
  ~GlfwWindowContext() override;

  void make_current() override;
  void swap_buffers() override;
  glm::ivec2 framebuffer_size() const override;
  bool has_default_framebuffer() const override { return true; }

  // True once the user asked to close the window (close button, or Escape).
  bool should_close() const;
  // Processes pending window events; call once per frame.
  void poll_events();
  // The GLFWwindow*, for code that needs GLFW directly (input callbacks).
  void* native_window() const { return window_; }

 private:
  void* window_ = nullptr;  // GLFWwindow*, kept opaque so this header needs no GLFW
};

// Convenience: a GlfwWindowContext behind the common interface.
std::unique_ptr<GlContext> create_window_context(const WindowOptions& options = {});

}  // namespace facet::driver
