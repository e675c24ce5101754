#include "facet/driver/gl_objects.hpp"

#include <stdexcept>
#include <string>

#include "facet/projection/errors.hpp"

namespace facet::driver {

namespace detail {

void delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
void delete_renderbuffer(GLuint id) { glDeleteRenderbuffers(1, &id); }
void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
void delete_shader(GLuint id) { glDeleteShader(id); }
void delete_program(GLuint id) { glDeleteProgram(id); }
void delete_query(GLuint id) { glDeleteQueries(1, &id); }
void delete_transform_feedback(GLuint id) { glDeleteTransformFeedbacks(1, &id); }
void delete_sampler(GLuint id) { glDeleteSamplers(1, &id); }

}  // namespace detail

namespace {

// glCreate* returns 0 only without a current context or on GL_OUT_OF_MEMORY.
GLuint checked(GLuint id, const char* what) {
  if (id == 0)
    throw std::runtime_error(std::string(what) + ": GL returned no object (no current context?)");
  return id;
}

}  // namespace

Buffer Buffer::create() {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  return Buffer(checked(id, "Buffer::create"));
}

Buffer Buffer::create(std::size_t bytes, const void* data, GLbitfield flags) {
  Buffer buffer = create();
  // GL rejects zero-sized storage; an empty buffer stays valid to bind and reports size 0.
  if (bytes > 0) {
    glNamedBufferStorage(buffer.id(), static_cast<GLsizeiptr>(bytes), data, flags);
    buffer.size_ = bytes;
  }
  return buffer;
}

void Buffer::sub_data(std::size_t offset, std::size_t bytes, const void* data) {
  if (bytes == 0) return;
  glNamedBufferSubData(id(), static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
}

void Buffer::get_sub_data(std::size_t offset, std::size_t bytes, void* out) const {
  if (bytes == 0) return;
  glGetNamedBufferSubData(id(), static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), out);
}

void Buffer::bind_base(GLenum target, GLuint index) const { glBindBufferBase(target, index, id()); }

Texture Texture::create(GLenum target) {
  GLuint id = 0;
  glCreateTextures(target, 1, &id);
  return Texture(checked(id, "Texture::create"), target);
}

Texture Texture::create_view(const Texture& source, GLenum internal_format) {
  GLint levels = 0;
  glGetTextureParameteriv(source.id(), GL_TEXTURE_IMMUTABLE_LEVELS, &levels);
  FACET_ASSERT(levels > 0);
  // glTextureView needs a name that was never bound, which glGenTextures gives and
  // glCreateTextures does not.
  GLuint id = 0;
  glGenTextures(1, &id);
  glTextureView(checked(id, "Texture::create_view"), source.target(), source.id(), internal_format,
                0, GLuint(levels), 0, 1);
  return Texture(id, source.target());
}

Texture Texture::create_buffer_view(const Buffer& buffer, GLenum internal_format,
                                    std::size_t texel_bytes) {
  GLint max_texels = 0;
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
  if (buffer.size() / texel_bytes > std::size_t(max_texels)) {
    throw std::runtime_error(
        "Texture::create_buffer_view: " + std::to_string(buffer.size() / texel_bytes) +
        " texels, more than GL_MAX_TEXTURE_BUFFER_SIZE (" + std::to_string(max_texels) + ")");
  }
  Texture texture = create(GL_TEXTURE_BUFFER);
  glTextureBuffer(texture.id(), internal_format, buffer.id());
  return texture;
}

Texture Texture::create_2d(GLenum internal_format, int width, int height, int levels) {
  Texture texture = create(GL_TEXTURE_2D);
  glTextureStorage2D(texture.id(), levels, internal_format, width, height);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER,
                      levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  return texture;
}

Renderbuffer Renderbuffer::create(GLenum internal_format, int width, int height, int samples) {
  GLuint id = 0;
  glCreateRenderbuffers(1, &id);
  Renderbuffer renderbuffer(checked(id, "Renderbuffer::create"));
  if (samples > 0)
    glNamedRenderbufferStorageMultisample(id, samples, internal_format, width, height);
  else
    glNamedRenderbufferStorage(id, internal_format, width, height);
  return renderbuffer;
}

Framebuffer Framebuffer::create() {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  return Framebuffer(checked(id, "Framebuffer::create"));
}

void Framebuffer::attach(GLenum attachment, const Texture& texture, int level) {
  glNamedFramebufferTexture(id(), attachment, texture.id(), level);
}

void Framebuffer::attach(GLenum attachment, const Renderbuffer& renderbuffer) {
  glNamedFramebufferRenderbuffer(id(), attachment, GL_RENDERBUFFER, renderbuffer.id());
}

void Framebuffer::check_complete() const {
  const GLenum status = glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER);
  if (status == GL_FRAMEBUFFER_COMPLETE) return;
  const char* name = "unknown status";
  switch (status) {
    case GL_FRAMEBUFFER_UNDEFINED:
      name = "GL_FRAMEBUFFER_UNDEFINED";
      break;
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT:
      name = "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
      break;
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT:
      name = "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
      break;
    case GL_FRAMEBUFFER_UNSUPPORTED:
      name = "GL_FRAMEBUFFER_UNSUPPORTED";
      break;
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE:
      name = "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
      break;
    default:
      break;
  }
  // An attachment the GL could not allocate (llvmpipe out of memory, a GPU out of video memory)
  // leaves it incomplete: the size asked for is too large for this machine.
  if (status == GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT || status == GL_FRAMEBUFFER_UNSUPPORTED) {
    throw ResourceExhausted(std::string("the GL could not allocate a framebuffer (") + name + ")");
  }
  throw std::runtime_error(std::string("Framebuffer::check_complete: ") + name);
}

VertexArray VertexArray::create() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  return VertexArray(checked(id, "VertexArray::create"));
}

Shader Shader::create(GLenum type) {
  return Shader(checked(glCreateShader(type), "Shader::create"));
}

Program Program::create() { return Program(checked(glCreateProgram(), "Program::create")); }

Query Query::create(GLenum target) {
  GLuint id = 0;
  glCreateQueries(target, 1, &id);
  return Query(checked(id, "Query::create"), target);
}

bool Query::available() const {
  GLuint ready = GL_FALSE;
  glGetQueryObjectuiv(id(), GL_QUERY_RESULT_AVAILABLE, &ready);
  return ready == GL_TRUE;
}

GLuint64 Query::result() const {
  GLuint64 value = 0;
  glGetQueryObjectui64v(id(), GL_QUERY_RESULT, &value);
  return value;
}

TransformFeedback TransformFeedback::create() {
  GLuint id = 0;
  glCreateTransformFeedbacks(1, &id);
  return TransformFeedback(checked(id, "TransformFeedback::create"));
}

void TransformFeedback::attach(GLuint index, const Buffer& buffer) {
  glTransformFeedbackBufferBase(id(), index, buffer.id());
}

Sampler Sampler::create() {
  GLuint id = 0;
  glCreateSamplers(1, &id);
  return Sampler(checked(id, "Sampler::create"));
}

std::string gl_error_name(GLenum error) {
  switch (error) {
    case GL_NO_ERROR:
      return "GL_NO_ERROR";
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    case GL_STACK_UNDERFLOW:
      return "GL_STACK_UNDERFLOW";
    case GL_STACK_OVERFLOW:
      return "GL_STACK_OVERFLOW";
    default:
      return "GL error " + std::to_string(error);
  }
}

void check_gl_error(const char* where) {
  std::string errors;
  // Bounded: a lost context can report errors forever.
  for (int i = 0; i < 16; ++i) {
    const GLenum error = glGetError();
    if (error == GL_NO_ERROR) break;
    errors += (errors.empty() ? "" : ", ") + gl_error_name(error);
  }
  if (!errors.empty()) throw std::runtime_error(std::string(where) + ": " + errors);
}

}  // namespace facet::driver
