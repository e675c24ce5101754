#include "facet/driver/gl_context.hpp"

#include <epoxy/gl.h>

#include <string>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "facet/driver/gpu_scene.hpp"

namespace facet::driver {

namespace {

std::string gl_string(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s ? std::string(s) : std::string();
}

// Mesa's draw module (llvmpipe, softpipe) mallocs its shaded vertices for every draw and frees
// them at its end: tens of kilobytes at the heap's top. With glibc's default trim threshold
// (128 KiB) each free hands the top back to the kernel and the next draw faults it in again page
// by page: about 3,000 page faults and 12 MB per 400x300 cylinder frame of `facets`, 20 ms of
// system time. Keeping freed memory in the process (a trim threshold of 256 MiB; blocks up to
// 32 MiB from the heap rather than fresh mappings) removes them. It changes no result.
void keep_freed_heap_for_software_rasterizer() {
#if defined(__GLIBC__)
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
#endif
}

// `user` is the context's LogSink.
void GLAPIENTRY log_debug_message(GLenum /*source*/, GLenum /*type*/, GLuint /*id*/,
                                  GLenum severity, GLsizei length, const GLchar* message,
                                  const void* user) {
  if (severity != GL_DEBUG_SEVERITY_HIGH && severity != GL_DEBUG_SEVERITY_MEDIUM) return;
  const std::string text =
      length < 0 ? std::string(message) : std::string(message, static_cast<std::size_t>(length));
  (*static_cast<const LogSink*>(user))(LogLevel::warning, "GL debug: " + text);
}

}  // namespace

void GlContext::read_info_and_check(std::string platform) {
  info_.platform = std::move(platform);
  info_.vendor = gl_string(GL_VENDOR);
  info_.renderer = gl_string(GL_RENDERER);
  info_.version = gl_string(GL_VERSION);
  // epoxy_gl_version() parses GL_VERSION and works on contexts too old for GL_MAJOR_VERSION.
  const int version = epoxy_gl_version();
  info_.major = version / 10;
  info_.minor = version % 10;
  if (version < 45)
    throw GlContextError("GL context (" + info_.platform + ", " + info_.renderer +
                         ") offers OpenGL " + info_.version + "; facet needs 4.5 core");
  info_.glsl_version = gl_string(GL_SHADING_LANGUAGE_VERSION);
  GLint mask = 0, flags = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  info_.core_profile = (mask & GL_CONTEXT_CORE_PROFILE_BIT) != 0;
  info_.debug = (flags & GL_CONTEXT_FLAG_DEBUG_BIT) != 0;
  if (!info_.core_profile)
    throw GlContextError("GL context (" + info_.platform + ", " + info_.renderer +
                         ") is not a core profile context");
  if (is_software_renderer()) keep_freed_heap_for_software_rasterizer();
}

void GlContext::install_debug_output(LogSink log) {
  if (!log) return;
  debug_log_ = std::move(log);
  glEnable(GL_DEBUG_OUTPUT);
  // Synchronous, so that a message's stack trace points at the offending call.
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(log_debug_message, &debug_log_);
}

}  // namespace facet::driver
