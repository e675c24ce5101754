#pragma once
// Shared between the EGL and GLFW contexts; not part of the public API.

namespace facet::driver::detail {

// Routes KHR_debug messages of medium and high severity to stderr. The context must be current.
void install_debug_output();

}  // namespace facet::driver::detail
