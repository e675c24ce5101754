// EGL headless contexts: EGL_EXT_platform_device (NVIDIA and other GPUs), else Mesa's surfaceless
// platform. Plain eglGetDisplay(EGL_DEFAULT_DISPLAY) is avoided: with no X server it fails or
// picks a platform that needs a window system.
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "facet/driver/gl_context.hpp"

namespace facet::driver {

namespace {

bool has_extension(const char* list, std::string_view name) {
  if (!list) return false;
  std::string_view rest(list);
  while (!rest.empty()) {
    const auto space = rest.find(' ');
    if (rest.substr(0, space) == name) return true;
    if (space == std::string_view::npos) break;
    rest.remove_prefix(space + 1);
  }
  return false;
}

std::string egl_error_name(EGLint error) {
  switch (error) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default:
      return "EGL error 0x" + [&] {
        char buffer[16];
        std::snprintf(buffer, sizeof buffer, "%x", static_cast<unsigned>(error));
        return std::string(buffer);
      }();
  }
}

// EGL displays are process-wide singletons per (platform, device): two contexts on one device
// get the same EGLDisplay, and eglTerminate would pull it from under the other. Displays are
// therefore initialised once and kept until the process exits. Terminating them when the last
// context goes would also unload the driver (slow to load again), and Mesa loses some of its
// driver's allocations on that unload, which LeakSanitizer then reports.
class DisplayRegistry {
 public:
  static DisplayRegistry& instance() {
    static DisplayRegistry registry;
    return registry;
  }
  // Initializes the display on first use. Returns false (with EGL's error) when that fails.
  bool acquire(EGLDisplay display) {
    std::lock_guard lock(mutex_);
    if (initialized_.count(display)) return true;
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) return false;
    initialized_.insert(display);
    return true;
  }

 private:
  std::mutex mutex_;
  std::set<EGLDisplay> initialized_;
};

class EglHeadlessContext final : public GlContext {
 public:
  EglHeadlessContext(EGLDisplay display, EGLContext context, std::string platform,
                     const HeadlessOptions& options)
      : display_(display), context_(context) {
    try {
      make_current();
      read_info_and_check(std::move(platform));
      if (options.debug) install_debug_output(options.debug_log);
    } catch (...) {
      destroy();
      throw;
    }
  }
  ~EglHeadlessContext() override { destroy(); }

  void make_current() override {
    // The bound API is per thread, and a new thread starts with OpenGL ES.
    eglBindAPI(EGL_OPENGL_API);
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw GlContextError("eglMakeCurrent (surfaceless) failed: " + egl_error_name(eglGetError()));
  }
  void swap_buffers() override { glFlush(); }
  glm::ivec2 framebuffer_size() const override { return {0, 0}; }
  bool has_default_framebuffer() const override { return false; }

 private:
  void destroy() {
    if (!context_) return;
    eglBindAPI(EGL_OPENGL_API);  // eglGetCurrentContext answers for the bound API only
    if (eglGetCurrentContext() == context_)
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    context_ = EGL_NO_CONTEXT;
  }

  EGLDisplay display_;
  EGLContext context_;
};

struct Attempt {
  std::string platform;  // "egl-device" or "egl-surfaceless"
  std::string label;     // for error messages
  EGLDisplay display;
};

// Tries to make a GL 4.5 core context on one display. Returns null and appends to `failures`
// when this display cannot; throws only for errors that are not about this display.
std::unique_ptr<GlContext> try_display(const Attempt& attempt, const HeadlessOptions& options,
                                       std::vector<std::string>& failures) {
  auto fail = [&](const std::string& why) {
    failures.push_back(attempt.label + ": " + why);
    return nullptr;
  };
  if (attempt.display == EGL_NO_DISPLAY)
    return fail("no display (" + egl_error_name(eglGetError()) + ")");
  auto& registry = DisplayRegistry::instance();
  if (!registry.acquire(attempt.display))
    return fail("eglInitialize failed (" + egl_error_name(eglGetError()) + ")");
  const char* extensions = eglQueryString(attempt.display, EGL_EXTENSIONS);
  if (!has_extension(extensions, "EGL_KHR_surfaceless_context"))
    return fail("no EGL_KHR_surfaceless_context");
  if (!has_extension(extensions, "EGL_KHR_create_context"))
    return fail("no EGL_KHR_create_context");
  if (!eglBindAPI(EGL_OPENGL_API)) return fail("eglBindAPI(EGL_OPENGL_API) failed");

  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!has_extension(extensions, "EGL_KHR_no_config_context")) {
    const EGLint config_attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0,
                                        EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(attempt.display, config_attributes, &config, 1, &count) || count < 1)
      return fail("no EGL config for desktop OpenGL");
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION_KHR,
                                       4,
                                       EGL_CONTEXT_MINOR_VERSION_KHR,
                                       5,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR,
                                       EGL_CONTEXT_FLAGS_KHR,
                                       options.debug ? EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR : 0,
                                       EGL_NONE};
  EGLContext context =
      eglCreateContext(attempt.display, config, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT)
    return fail("eglCreateContext(GL 4.5 core) failed (" + egl_error_name(eglGetError()) + ")");
  try {
    return std::make_unique<EglHeadlessContext>(attempt.display, context, attempt.platform,
                                                options);
  } catch (const GlContextError& e) {
    failures.push_back(attempt.label + ": " + e.what());
    return nullptr;
  }
}

EglPlatform platform_from_environment(EglPlatform requested) {
  if (requested != EglPlatform::automatic) return requested;
  const char* value = std::getenv("FACET_EGL_PLATFORM");
  if (!value || !*value) return requested;
  if (std::strcmp(value, "device") == 0) return EglPlatform::device;
  if (std::strcmp(value, "surfaceless") == 0) return EglPlatform::surfaceless;
  throw GlContextError(std::string("FACET_EGL_PLATFORM='") + value +
                       "': expected 'device' or 'surfaceless'");
}

}  // namespace

std::unique_ptr<GlContext> create_headless_context(const HeadlessOptions& options) {
  if (!epoxy_has_egl()) throw GlContextError("create_headless_context: libEGL could not be loaded");
  const EglPlatform platform = platform_from_environment(options.platform);
  const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_extension(client_extensions, "EGL_EXT_platform_base"))
    throw GlContextError("create_headless_context: EGL lacks EGL_EXT_platform_base");
  std::vector<std::string> failures;

  if (platform != EglPlatform::surfaceless) {
    if (has_extension(client_extensions, "EGL_EXT_platform_device") &&
        has_extension(client_extensions, "EGL_EXT_device_enumeration")) {
      EGLint count = 0;
      eglQueryDevicesEXT(0, nullptr, &count);
      std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(std::max(count, 0)));
      if (count > 0) eglQueryDevicesEXT(count, devices.data(), &count);
      for (EGLint i = 0; i < count; ++i) {
        if (options.device_index >= 0 && i != options.device_index) continue;
        const EGLDeviceEXT device = devices[static_cast<std::size_t>(i)];
        const char* device_extensions = eglQueryDeviceStringEXT(device, EGL_EXTENSIONS);
        const std::string label = "EGL device " + std::to_string(i);
        // Mesa's software device is llvmpipe again; automatic mode reaches it via surfaceless.
        if (platform == EglPlatform::automatic && options.device_index < 0 &&
            has_extension(device_extensions, "EGL_MESA_device_software")) {
          failures.push_back(label + ": software device, skipped");
          continue;
        }
        const Attempt attempt{"egl-device", label,
                              eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, nullptr)};
        if (auto context = try_display(attempt, options, failures)) return context;
      }
      if (count == 0) failures.push_back("EGL_EXT_platform_device: no devices");
    } else {
      failures.push_back("EGL_EXT_platform_device: not supported");
    }
  }

  if (platform != EglPlatform::device) {
    if (has_extension(client_extensions, "EGL_MESA_platform_surfaceless")) {
      const Attempt attempt{
          "egl-surfaceless", "EGL_MESA_platform_surfaceless",
          eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr)};
      if (auto context = try_display(attempt, options, failures)) return context;
    } else {
      failures.push_back("EGL_MESA_platform_surfaceless: not supported");
    }
  }

  std::string message = "create_headless_context: no OpenGL 4.5 core context could be made";
  for (const auto& failure : failures) message += "\n  " + failure;
  throw GlContextError(message);
}

}  // namespace facet::driver
