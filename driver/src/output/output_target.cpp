#include <algorithm>
#include <cstring>
#include <string>

#include "../gl/image_rows.hpp"
#include "../gl/scene_framebuffer.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {

OutputTarget OutputTarget::create(glm::ivec2 size, int msaa_samples) {
  FACET_ASSERT(size.x > 0 && size.y > 0);
  // What the GL can hold, as an input error rather than an incomplete framebuffer.
  GLint max_texture = 0, max_width = 0, max_height = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &max_width);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_HEIGHT, &max_height);
  const int max_x = std::min(max_texture, max_width), max_y = std::min(max_texture, max_height);
  if (size.x > max_x || size.y > max_y) {
    throw InputError("output", "size",
                     "at most " + std::to_string(max_x) + "x" + std::to_string(max_y) +
                         " pixels on this GL; got " + std::to_string(size.x) + "x" +
                         std::to_string(size.y));
  }
  // Likewise the samples every attachment can have (the IDs are R32UI, an integer format).
  GLint max_samples = 0, max_integer_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  glGetIntegerv(GL_MAX_INTEGER_SAMPLES, &max_integer_samples);
  const int max_msaa = std::min(max_samples, max_integer_samples);
  if (msaa_samples > 1 && msaa_samples > max_msaa) {
    throw InputError("output", "msaa",
                     "at most " + std::to_string(max_msaa) + " samples per pixel on this GL; got " +
                         std::to_string(msaa_samples));
  }
  const Activity activity("allocating the framebuffers of a " + std::to_string(size.x) + "x" +
                          std::to_string(size.y) + " output");
  OutputTarget target;
  target.size_ = size;
  target.msaa_samples_ = msaa_samples > 1 ? msaa_samples : 0;
  target.colour_ = Texture::create_2d(GL_SRGB8_ALPHA8, size.x, size.y);
  target.ids_ = detail::create_id_texture(size);
  target.depth_ = Texture::create_2d(GL_DEPTH_COMPONENT32F, size.x, size.y);
  target.framebuffer_ = detail::scene_framebuffer(target.colour_, target.ids_, target.depth_);
  if (target.msaa_samples_ > 0) {
    const int s = target.msaa_samples_;
    target.msaa_colour_ = Renderbuffer::create(GL_SRGB8_ALPHA8, size.x, size.y, s);
    target.msaa_ids_ = Renderbuffer::create(GL_R32UI, size.x, size.y, s);
    target.msaa_depth_ = Renderbuffer::create(GL_DEPTH_COMPONENT32F, size.x, size.y, s);
    target.msaa_framebuffer_ =
        detail::scene_framebuffer(target.msaa_colour_, target.msaa_ids_, target.msaa_depth_);
  }
  return target;
}

void OutputTarget::clear(const glm::vec4& background) {
  glEnable(GL_FRAMEBUFFER_SRGB);
  const GLuint zero_id[4] = {0, 0, 0, 0};
  const float far_depth = 0.0f;
  for (const Framebuffer* fb : {&framebuffer_, &msaa_framebuffer_}) {
    if (!*fb) continue;
    glClearNamedFramebufferfv(fb->id(), GL_COLOR, 0, &background.x);
    glClearNamedFramebufferuiv(fb->id(), GL_COLOR, 1, zero_id);
    glClearNamedFramebufferfv(fb->id(), GL_DEPTH, 0, &far_depth);
  }
}

void OutputTarget::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, msaa_framebuffer_ ? msaa_framebuffer_.id() : framebuffer_.id());
  glViewport(0, 0, size_.x, size_.y);
  glEnable(GL_FRAMEBUFFER_SRGB);
}

void OutputTarget::resolve() const {
  if (!msaa_framebuffer_) return;
  const int w = size_.x, h = size_.y;
  // Colour is averaged; integer IDs and depth cannot be, so NEAREST takes one sample.
  glNamedFramebufferReadBuffer(msaa_framebuffer_.id(), GL_COLOR_ATTACHMENT0);
  glNamedFramebufferDrawBuffer(framebuffer_.id(), GL_COLOR_ATTACHMENT0);
  glBlitNamedFramebuffer(msaa_framebuffer_.id(), framebuffer_.id(), 0, 0, w, h, 0, 0, w, h,
                         GL_COLOR_BUFFER_BIT, GL_LINEAR);
  glNamedFramebufferReadBuffer(msaa_framebuffer_.id(), GL_COLOR_ATTACHMENT1);
  glNamedFramebufferDrawBuffer(framebuffer_.id(), GL_COLOR_ATTACHMENT1);
  glBlitNamedFramebuffer(msaa_framebuffer_.id(), framebuffer_.id(), 0, 0, w, h, 0, 0, w, h,
                         GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBlitNamedFramebuffer(msaa_framebuffer_.id(), framebuffer_.id(), 0, 0, w, h, 0, 0, w, h,
                         GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  glNamedFramebufferReadBuffer(msaa_framebuffer_.id(), GL_COLOR_ATTACHMENT0);
  detail::draw_to_colour_and_ids(framebuffer_);
}

std::vector<std::uint8_t> OutputTarget::read_colour_rgba8() const {
  std::vector<std::uint8_t> pixels(std::size_t(size_.x) * size_.y * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(colour_.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(pixels.size()),
                    pixels.data());
  flip_rows(pixels, std::size_t(size_.x) * 4);
  return pixels;
}

std::vector<std::uint32_t> OutputTarget::read_ids() const {
  std::vector<std::uint32_t> pixels(std::size_t(size_.x) * size_.y);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(ids_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT,
                    GLsizei(pixels.size() * sizeof(std::uint32_t)), pixels.data());
  flip_rows(pixels, std::size_t(size_.x));
  return pixels;
}

std::vector<float> OutputTarget::read_depth() const {
  std::vector<float> pixels(std::size_t(size_.x) * size_.y);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(depth_.id(), 0, GL_DEPTH_COMPONENT, GL_FLOAT,
                    GLsizei(pixels.size() * sizeof(float)), pixels.data());
  flip_rows(pixels, std::size_t(size_.x));
  return pixels;
}

}  // namespace facet::driver
