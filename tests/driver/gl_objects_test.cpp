// The move-only GL object wrappers: moves leave the source empty, destruction deletes, and no
// wrapper can be copied.
#include "facet/driver/gl_objects.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <type_traits>

#include "facet/driver/gpu_timer.hpp"
#include "gl_test_context.hpp"

namespace facet::driver {
namespace {

template <class T>
constexpr bool move_only =
    !std::is_copy_constructible_v<T> && !std::is_copy_assignable_v<T> &&
    std::is_nothrow_move_constructible_v<T> && std::is_nothrow_move_assignable_v<T>;
static_assert(move_only<Buffer>);
static_assert(move_only<Texture>);
static_assert(move_only<Renderbuffer>);
static_assert(move_only<Framebuffer>);
static_assert(move_only<VertexArray>);
static_assert(move_only<Shader>);
static_assert(move_only<Program>);
static_assert(move_only<Query>);
static_assert(move_only<TransformFeedback>);
static_assert(move_only<Sampler>);

// For each wrapper: made objects exist; a move transfers the name and empties the source; move
// assignment deletes the target's old object; destruction deletes.
template <class T, class Make, class Exists>
void check_lifecycle(Make make, Exists exists) {
  T a = make();
  const GLuint a_id = a.id();
  ASSERT_NE(a_id, 0u);
  EXPECT_TRUE(exists(a_id));

  T b(std::move(a));
  EXPECT_EQ(a.id(), 0u);  // NOLINT(bugprone-use-after-move): the moved-from state is the point
  EXPECT_FALSE(static_cast<bool>(a));
  EXPECT_EQ(b.id(), a_id);
  EXPECT_TRUE(exists(a_id));

  T c = make();
  const GLuint c_id = c.id();
  c = std::move(b);
  EXPECT_EQ(b.id(), 0u);  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(c.id(), a_id);
  EXPECT_FALSE(exists(c_id)) << "move assignment must delete the target's previous object";
  EXPECT_TRUE(exists(a_id));

  T& alias = c;
  c = std::move(alias);  // self-move keeps the object
  EXPECT_EQ(c.id(), a_id);
  EXPECT_TRUE(exists(a_id));

  { T d(std::move(c)); }
  EXPECT_FALSE(exists(a_id)) << "destruction must delete the object";

  T f = make();
  const GLuint f_id = f.id();
  f.reset();
  EXPECT_FALSE(exists(f_id));
  EXPECT_EQ(f.id(), 0u);
  check_gl_error("check_lifecycle");
}

TEST(GlObjects, BufferLifecycle) {
  test::shared_context();
  check_lifecycle<Buffer>([] { return Buffer::create(64); },
                          [](GLuint id) { return glIsBuffer(id) == GL_TRUE; });
  Buffer sized = Buffer::create(256);
  EXPECT_EQ(sized.size(), 256u);
  Buffer moved = std::move(sized);
  EXPECT_EQ(moved.size(), 256u);
  EXPECT_EQ(sized.size(), 0u);  // NOLINT(bugprone-use-after-move)

  Buffer owner = Buffer::create(16);
  const GLuint id = owner.id();
  GLuint released = owner.release();
  EXPECT_EQ(released, id);
  EXPECT_EQ(owner.id(), 0u);
  EXPECT_TRUE(glIsBuffer(released)) << "release() must not delete";
  glDeleteBuffers(1, &released);
}

TEST(GlObjects, TextureLifecycle) {
  test::shared_context();
  check_lifecycle<Texture>([] { return Texture::create_2d(GL_RGBA8, 4, 4); },
                           [](GLuint id) { return glIsTexture(id) == GL_TRUE; });
  Texture t = Texture::create(GL_TEXTURE_2D_ARRAY);
  Texture u = std::move(t);
  EXPECT_EQ(u.target(), static_cast<GLenum>(GL_TEXTURE_2D_ARRAY));
  EXPECT_EQ(t.target(), 0u);  // NOLINT(bugprone-use-after-move)
}

TEST(GlObjects, RenderbufferLifecycle) {
  test::shared_context();
  check_lifecycle<Renderbuffer>([] { return Renderbuffer::create(GL_DEPTH_COMPONENT32F, 4, 4); },
                                [](GLuint id) { return glIsRenderbuffer(id) == GL_TRUE; });
}

TEST(GlObjects, FramebufferLifecycle) {
  test::shared_context();
  check_lifecycle<Framebuffer>([] { return Framebuffer::create(); },
                               [](GLuint id) { return glIsFramebuffer(id) == GL_TRUE; });
}

TEST(GlObjects, VertexArrayLifecycle) {
  test::shared_context();
  check_lifecycle<VertexArray>([] { return VertexArray::create(); },
                               [](GLuint id) { return glIsVertexArray(id) == GL_TRUE; });
}

TEST(GlObjects, ShaderAndProgramLifecycle) {
  test::shared_context();
  check_lifecycle<Shader>([] { return Shader::create(GL_FRAGMENT_SHADER); },
                          [](GLuint id) { return glIsShader(id) == GL_TRUE; });
  check_lifecycle<Program>([] { return Program::create(); },
                           [](GLuint id) { return glIsProgram(id) == GL_TRUE; });
}

TEST(GlObjects, QueryLifecycle) {
  test::shared_context();
  check_lifecycle<Query>([] { return Query::create(GL_TIME_ELAPSED); },
                         [](GLuint id) { return glIsQuery(id) == GL_TRUE; });
}

TEST(GlObjects, TransformFeedbackAndSamplerLifecycle) {
  test::shared_context();
  check_lifecycle<TransformFeedback>(
      [] { return TransformFeedback::create(); },
      [](GLuint id) { return glIsTransformFeedback(id) == GL_TRUE; });
  check_lifecycle<Sampler>([] { return Sampler::create(); },
                           [](GLuint id) { return glIsSampler(id) == GL_TRUE; });
}

TEST(GlObjects, EmptyWrappersNeedNoContext) {
  // Default-constructed and moved-from wrappers never call GL, so they are safe anywhere.
  Buffer a;
  Buffer b(std::move(a));
  EXPECT_EQ(b.id(), 0u);
  b.reset();
}

TEST(GlObjects, FramebufferCompletenessIsChecked) {
  test::shared_context();
  Framebuffer empty = Framebuffer::create();
  EXPECT_THROW(empty.check_complete(), std::runtime_error);
  Texture colour = Texture::create_2d(GL_RGBA32F, 8, 8);
  Framebuffer fbo = Framebuffer::create();
  fbo.attach(GL_COLOR_ATTACHMENT0, colour);
  EXPECT_NO_THROW(fbo.check_complete());
}

TEST(GpuTimer, ReportsEveryPassOfAFrame) {
  test::shared_context();
  Texture colour = Texture::create_2d(GL_RGBA8, 16, 16);
  Framebuffer fbo = Framebuffer::create();
  fbo.attach(GL_COLOR_ATTACHMENT0, colour);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
  for (const GpuTimer::Clock clock : {GpuTimer::Clock::queries, GpuTimer::Clock::wall_clock}) {
    SCOPED_TRACE(clock == GpuTimer::Clock::queries ? "queries" : "wall clock");
    GpuTimer timer(clock);
    for (int frame = 0; frame < 2; ++frame) {
      {
        auto pass = timer.scope("clear");
        glClearColor(0.1f, 0.2f, 0.3f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
      }
      timer.begin("flush");
      glFlush();
      timer.end();
      timer.end_frame();
    }
    EXPECT_EQ(timer.pending_frames(), 2u);
    for (int frame = 0; frame < 2; ++frame) {
      const auto times = timer.poll(true);
      ASSERT_TRUE(times.has_value());
      ASSERT_EQ(times->size(), 2u);
      EXPECT_EQ((*times)[0].pass, "clear");
      EXPECT_EQ((*times)[1].pass, "flush");
      for (const auto& t : *times) EXPECT_GE(t.milliseconds, 0.0);
    }
    EXPECT_FALSE(timer.poll(true).has_value());
  }
  const auto t0 = GpuTimer::timestamp_ns();
  const auto t1 = GpuTimer::timestamp_ns();
  EXPECT_GE(t1, t0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl_error("ReportsEveryPassOfAFrame");
}

// The wall clock spans the whole pass, including what the CPU does inside it: a pass that sleeps
// 20 ms reports at least 20 ms (a lower bound, which no load on the machine can break).
TEST(GpuTimer, WallClockSpansThePass) {
  test::shared_context();
  GpuTimer timer(GpuTimer::Clock::wall_clock);
  {
    auto pass = timer.scope("sleep");
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  timer.end_frame();
  const auto times = timer.poll(false);  // ready at once: nothing is left to query
  ASSERT_TRUE(times.has_value());
  ASSERT_EQ(times->size(), 1u);
  EXPECT_GE((*times)[0].milliseconds, 20.0);
}

}  // namespace
}  // namespace facet::driver
