// The headless context: GL 4.5 core on whatever EGL offers (llvmpipe here), typed errors, and
// more than one context per process.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "facet/driver/gl_objects.hpp"
#include "gl_test_context.hpp"

namespace facet::driver {
namespace {

TEST(GlContext, HeadlessIsGl45Core) {
  GlContext& context = test::shared_context();
  const GlInfo& info = context.info();
  std::printf("GL: %s | %s | %s | GLSL %s | %s\n", info.vendor.c_str(), info.renderer.c_str(),
              info.version.c_str(), info.glsl_version.c_str(), info.platform.c_str());
  EXPECT_GE(info.major * 10 + info.minor, 45);
  EXPECT_TRUE(info.core_profile);
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_FALSE(info.vendor.empty());
  EXPECT_FALSE(context.has_default_framebuffer());
  EXPECT_EQ(context.framebuffer_size(), glm::ivec2(0, 0));
  // The live context agrees with what was recorded.
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  EXPECT_EQ(major, info.major);
  EXPECT_EQ(minor, info.minor);
  EXPECT_NO_THROW(check_gl_error("HeadlessIsGl45Core"));
}

TEST(GlContext, TwoContextsCoexist) {
  GlContext& first = test::shared_context();
  Buffer in_first = Buffer::create(16);
  {
    auto second = create_headless_context({});
    ASSERT_TRUE(second);
    second->make_current();
    Buffer in_second = Buffer::create(16);
    EXPECT_TRUE(glIsBuffer(in_second.id()));
    in_second.reset();
  }  // destroying the second context must leave the shared EGL display usable
  first.make_current();
  EXPECT_TRUE(glIsBuffer(in_first.id()));
  Buffer again = Buffer::create(16);
  EXPECT_TRUE(glIsBuffer(again.id()));
  EXPECT_NO_THROW(check_gl_error("TwoContextsCoexist"));
}

TEST(GlContext, NoMatchingDeviceGivesTypedError) {
  HeadlessOptions options;
  options.platform = EglPlatform::device;
  options.device_index = 100000;  // no machine has this many EGL devices
  try {
    auto context = create_headless_context(options);
    ADD_FAILURE() << "expected GlContextError";
  } catch (const GlContextError& e) {
    EXPECT_NE(std::string(e.what()).find("no OpenGL 4.5 core context"), std::string::npos)
        << e.what();
  }
  test::shared_context();  // the failed attempt must not disturb the current context
  EXPECT_NO_THROW(check_gl_error("NoMatchingDeviceGivesTypedError"));
}

TEST(GlContext, ExplicitPlatformsReportThemselves) {
  HeadlessOptions options;
  options.platform = EglPlatform::surfaceless;
  // Mesa's surfaceless platform exists wherever Mesa is the EGL vendor; NVIDIA-only machines
  // lack it, and must then say so with GlContextError.
  try {
    auto context = create_headless_context(options);
    EXPECT_EQ(context->info().platform, "egl-surfaceless");
  } catch (const GlContextError& e) {
    EXPECT_NE(std::string(e.what()).find("EGL_MESA_platform_surfaceless"), std::string::npos)
        << e.what();
  }
  options.platform = EglPlatform::device;
  try {
    auto context = create_headless_context(options);
    EXPECT_EQ(context->info().platform, "egl-device");
  } catch (const GlContextError& e) {
    const std::string message = e.what();
    EXPECT_TRUE(message.find("EGL_EXT_platform_device") != std::string::npos ||
                message.find("EGL device") != std::string::npos)
        << message;
  }
  test::shared_context();
}

TEST(GlContext, DebugContextCanBeRequested) {
  HeadlessOptions options;
  options.debug = true;
  auto context = create_headless_context(options);
  EXPECT_TRUE(context->info().debug);
  context.reset();
  test::shared_context();
}

// A debug context's messages reach its log sink, as warnings: here the one Mesa gives for an
// error forced by binding a buffer name that glGenBuffers never returned (GL_INVALID_OPERATION
// in a core profile).
TEST(GlContext, DebugMessagesGoToTheContextsLogSink) {
  std::vector<std::pair<LogLevel, std::string>> lines;
  HeadlessOptions options;
  options.debug = true;
  options.debug_log = [&lines](LogLevel level, const std::string& line) {
    lines.emplace_back(level, line);
  };
  auto context = create_headless_context(options);
  ASSERT_TRUE(lines.empty());
  glBindBuffer(GL_ARRAY_BUFFER, 4242);
  EXPECT_EQ(glGetError(), GLenum(GL_INVALID_OPERATION));
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].first, LogLevel::warning);
  EXPECT_TRUE(lines[0].second.starts_with("GL debug: ")) << lines[0].second;
  EXPECT_GT(lines[0].second.size(), std::string("GL debug: ").size());
  context.reset();
  test::shared_context();
}

}  // namespace
}  // namespace facet::driver
