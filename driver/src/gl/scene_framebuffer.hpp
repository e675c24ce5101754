#pragma once
// The framebuffers the scene is drawn into (output targets, the perspective baseline's image):
// colour at colour attachment 0, triangle IDs (R32UI) at 1, depth; fragment outputs 0 and 1
// write colour and IDs.
#include <epoxy/gl.h>

#include <glm/vec2.hpp>

#include "facet/driver/gl_objects.hpp"

namespace facet::driver::detail {

// Fragment outputs 0 and 1 go to colour attachments 0 and 1.
inline void draw_to_colour_and_ids(const Framebuffer& framebuffer) {
  const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glNamedFramebufferDrawBuffers(framebuffer.id(), 2, buffers);
}

// A texture of triangle IDs (R32UI), sampled nearest: IDs are not to be blended.
inline Texture create_id_texture(glm::ivec2 size) {
  Texture ids = Texture::create_2d(GL_R32UI, size.x, size.y);
  glTextureParameteri(ids.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(ids.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  return ids;
}

// A complete framebuffer of `colour`, `ids` and `depth` (textures or renderbuffers) that draws
// to colour and IDs.
template <class Image>
Framebuffer scene_framebuffer(const Image& colour, const Image& ids, const Image& depth) {
  Framebuffer framebuffer = Framebuffer::create();
  framebuffer.attach(GL_COLOR_ATTACHMENT0, colour);
  framebuffer.attach(GL_COLOR_ATTACHMENT1, ids);
  framebuffer.attach(GL_DEPTH_ATTACHMENT, depth);
  draw_to_colour_and_ids(framebuffer);
  framebuffer.check_complete();
  return framebuffer;
}

}  // namespace facet::driver::detail
