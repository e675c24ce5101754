#pragma once
// Move-only owners of GL object names. No copies; a move leaves the source empty (name 0); the
// destructor deletes the object. Objects are made with the GL 4.5 direct-state-access glCreate*
// functions, so they exist (glIs* is true) before their first bind.
//
// A default-constructed wrapper is empty and touches no GL, so empty wrappers can live anywhere.
// Creating or destroying a non-empty one needs the context that made it to be current.
#include <epoxy/gl.h>

#include <cstddef>
#include <ranges>
#include <string>
#include <utility>

namespace facet::driver {

namespace detail {

// The name handling shared by all wrappers; Delete is the matching glDelete* call.
template <void (*Delete)(GLuint)>
class GlName {
 public:
  GlName() = default;
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  GlName(GlName&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
  GlName& operator=(GlName&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }
  ~GlName() { reset(); }

  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  // Deletes the object now and leaves the wrapper empty.
  void reset() {
    if (id_ != 0) Delete(std::exchange(id_, 0));
  }
  // Gives up ownership without deleting; the caller must delete the returned name.
  [[nodiscard]] GLuint release() { return std::exchange(id_, 0); }

 protected:
  explicit GlName(GLuint id) : id_(id) {}

 private:
  GLuint id_ = 0;
};

void delete_buffer(GLuint id);
void delete_texture(GLuint id);
void delete_renderbuffer(GLuint id);
void delete_framebuffer(GLuint id);
void delete_vertex_array(GLuint id);
void delete_shader(GLuint id);
void delete_program(GLuint id);
void delete_query(GLuint id);
void delete_transform_feedback(GLuint id);
void delete_sampler(GLuint id);

}  // namespace detail

class Buffer : public detail::GlName<detail::delete_buffer> {
 public:
  Buffer() = default;
  // A buffer with no storage yet.
  static Buffer create();
  // Immutable storage of `bytes` bytes (glNamedBufferStorage), initialised from `data` when it is
  // not null. `flags` as for glBufferStorage; the default allows sub_data updates.
  static Buffer create(std::size_t bytes, const void* data = nullptr,
                       GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
  // Immutable storage holding a copy of a contiguous range (std::vector, std::span, array).
  template <std::ranges::contiguous_range Range>
  static Buffer create_from(const Range& values, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT) {
    return create(std::ranges::size(values) * sizeof(std::ranges::range_value_t<Range>),
                  std::ranges::data(values), flags);
  }

  // Storage size in bytes (0 when created without storage).
  std::size_t size() const { return size_; }
  void sub_data(std::size_t offset, std::size_t bytes, const void* data);
  // Reads `bytes` bytes at `offset` back into `out` (waits for the GPU).
  void get_sub_data(std::size_t offset, std::size_t bytes, void* out) const;
  // glBindBufferBase for indexed targets (GL_SHADER_STORAGE_BUFFER, GL_UNIFORM_BUFFER,
  // GL_ATOMIC_COUNTER_BUFFER, GL_TRANSFORM_FEEDBACK_BUFFER).
  void bind_base(GLenum target, GLuint index) const;

  Buffer(Buffer&& other) noexcept
      : GlName(std::move(other)), size_(std::exchange(other.size_, 0)) {}
  Buffer& operator=(Buffer&& other) noexcept {
    GlName::operator=(std::move(other));
    size_ = std::exchange(other.size_, 0);
    return *this;
  }

 private:
  using GlName::GlName;
  std::size_t size_ = 0;
};

class Texture : public detail::GlName<detail::delete_texture> {
 public:
  Texture() = default;
  // A texture object of this target (GL_TEXTURE_2D, GL_TEXTURE_2D_ARRAY, ...) with no storage.
  static Texture create(GLenum target);
  // Immutable 2D storage, `levels` mip levels, sampling clamped to edge with linear filtering.
  static Texture create_2d(GLenum internal_format, int width, int height, int levels = 1);
  // A view of all levels of `source` (which must have immutable storage) reinterpreted as
  // `internal_format` of the same size class, e.g. an SRGB8_ALPHA8 texture as RGBA8 so that
  // compute shaders can load and store its raw bytes.
  static Texture create_view(const Texture& source, GLenum internal_format);
  // A buffer texture over all of `buffer` (texelFetch on a samplerBuffer) read as
  // `internal_format` (GL_RGBA32F, GL_RGB32F, GL_R32UI, ...) of `texel_bytes` bytes a texel.
  // Throws std::runtime_error where the buffer holds more texels than
  // GL_MAX_TEXTURE_BUFFER_SIZE.
  static Texture create_buffer_view(const Buffer& buffer, GLenum internal_format,
                                    std::size_t texel_bytes);

  GLenum target() const { return target_; }
  void bind_unit(GLuint unit) const { glBindTextureUnit(unit, id()); }

  Texture(Texture&& other) noexcept
      : GlName(std::move(other)), target_(std::exchange(other.target_, GLenum{0})) {}
  Texture& operator=(Texture&& other) noexcept {
    GlName::operator=(std::move(other));
    target_ = std::exchange(other.target_, GLenum{0});
    return *this;
  }

 private:
  Texture(GLuint id, GLenum target) : GlName(id), target_(target) {}
  GLenum target_ = 0;
};

class Renderbuffer : public detail::GlName<detail::delete_renderbuffer> {
 public:
  Renderbuffer() = default;
  // `samples` 0 for single-sampled storage.
  static Renderbuffer create(GLenum internal_format, int width, int height, int samples = 0);

 private:
  using GlName::GlName;
};

class Framebuffer : public detail::GlName<detail::delete_framebuffer> {
 public:
  Framebuffer() = default;
  static Framebuffer create();
  void attach(GLenum attachment, const Texture& texture, int level = 0);
  void attach(GLenum attachment, const Renderbuffer& renderbuffer);
  // Throws std::runtime_error naming the status when the framebuffer is not complete.
  void check_complete() const;

 private:
  using GlName::GlName;
};

class VertexArray : public detail::GlName<detail::delete_vertex_array> {
 public:
  VertexArray() = default;
  static VertexArray create();

 private:
  using GlName::GlName;
};

class Shader : public detail::GlName<detail::delete_shader> {
 public:
  Shader() = default;
  // `type`: GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER, ...
  static Shader create(GLenum type);

 private:
  using GlName::GlName;
};

class Program : public detail::GlName<detail::delete_program> {
 public:
  Program() = default;
  static Program create();
  void use() const { glUseProgram(id()); }
  // Location of a uniform, or -1 when the linker removed or never saw it.
  GLint uniform_location(const char* name) const { return glGetUniformLocation(id(), name); }

 private:
  using GlName::GlName;
};

class Query : public detail::GlName<detail::delete_query> {
 public:
  Query() = default;
  // `target`: GL_TIME_ELAPSED, GL_TIMESTAMP, GL_SAMPLES_PASSED, GL_PRIMITIVES_GENERATED, ...
  static Query create(GLenum target);
  GLenum target() const { return target_; }
  // True once the result can be read without waiting.
  bool available() const;
  // The 64-bit result; waits for the GPU when it is not yet available.
  GLuint64 result() const;

  Query(Query&& other) noexcept
      : GlName(std::move(other)), target_(std::exchange(other.target_, GLenum{0})) {}
  Query& operator=(Query&& other) noexcept {
    GlName::operator=(std::move(other));
    target_ = std::exchange(other.target_, GLenum{0});
    return *this;
  }

 private:
  Query(GLuint id, GLenum target) : GlName(id), target_(target) {}
  GLenum target_ = 0;
};

class TransformFeedback : public detail::GlName<detail::delete_transform_feedback> {
 public:
  TransformFeedback() = default;
  static TransformFeedback create();
  // Binds `buffer` (whole) as output `index` of this transform feedback object.
  void attach(GLuint index, const Buffer& buffer);

 private:
  using GlName::GlName;
};

class Sampler : public detail::GlName<detail::delete_sampler> {
 public:
  Sampler() = default;
  static Sampler create();
  void bind_unit(GLuint unit) const { glBindSampler(unit, id()); }

 private:
  using GlName::GlName;
};

// The name of a GL error code ("GL_INVALID_OPERATION", ...).
std::string gl_error_name(GLenum error);

// Throws std::runtime_error("<where>: GL_...") when glGetError reports an error. For tests and
// for checking a step after the fact; it drains every pending error.
void check_gl_error(const char* where);

}  // namespace facet::driver
