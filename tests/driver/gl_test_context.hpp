#pragma once
// One headless GL context per test binary, made on first use and current on the main thread.
// Made once because every context costs llvmpipe a few milliseconds and some megabytes.
#include <gtest/gtest.h>

#include "facet/driver/gl_context.hpp"

namespace facet::driver::test {

inline GlContext& shared_context() {
  static std::unique_ptr<GlContext> context = create_headless_context({});
  context->make_current();
  return *context;
}

}  // namespace facet::driver::test
