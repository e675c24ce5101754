#include "facet/driver/content_pass.hpp"

#include <algorithm>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>

#include "../gl/image_rows.hpp"
#include "facet/driver/direction_cache.hpp"
#include "facet/driver/program.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {

namespace {

int mip_levels(glm::ivec2 size) {
  return 1 + int(std::floor(std::log2(double(std::max(size.x, size.y)))));
}

GLenum pixel_format(const ContentImage& image) {
  switch (image.channels) {
    case 1:
      return GL_RED;
    case 3:
      return image.bgr ? GL_BGR : GL_RGB;
    default:
      return image.bgr ? GL_BGRA : GL_RGBA;
  }
}

bool has_anisotropic_filtering() {
  return epoxy_gl_version() >= 46 || epoxy_has_gl_extension("GL_ARB_texture_filter_anisotropic") ||
         epoxy_has_gl_extension("GL_EXT_texture_filter_anisotropic");
}

}  // namespace

ContentTexture::ContentTexture(ContentFormat format, glm::ivec2 image_size,
                               ContentImage::Pixels pixels, const std::string& source,
                               bool full_float)
    : format_(format), image_size_(image_size), pixels_(pixels) {
  const GLenum internal = pixels == ContentImage::Pixels::srgb8 ? GL_SRGB8_ALPHA8
                          : full_float                          ? GL_RGBA32F
                                                                : GL_RGBA16F;
  if (format == ContentFormat::cubemap) {
    const int face = image_size.y;
    if (image_size.x != 6 * face)
      throw InputError(source, "image",
                       "a cube map as six square faces side by side (width 6 × height); got " +
                           std::to_string(image_size.x) + "x" + std::to_string(image_size.y));
    GLint max_face = 0;
    glGetIntegerv(GL_MAX_CUBE_MAP_TEXTURE_SIZE, &max_face);
    if (face > max_face)
      throw InputError(source, "image",
                       "cube faces of at most " + std::to_string(max_face) + " pixels; got " +
                           std::to_string(face));
    texture_ = Texture::create(GL_TEXTURE_CUBE_MAP);
    glTextureStorage2D(texture_.id(), mip_levels({face, face}), internal, face, face);
  } else {
    GLint max_side = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_side);
    if (image_size.x > max_side || image_size.y > max_side)
      throw InputError(source, "image",
                       "an image of at most " + std::to_string(max_side) +
                           " pixels a side for this GL; got " + std::to_string(image_size.x) + "x" +
                           std::to_string(image_size.y));
    texture_ = Texture::create(GL_TEXTURE_2D);
    glTextureStorage2D(texture_.id(), mip_levels(image_size), internal, image_size.x, image_size.y);
  }
  check_gl_error("content texture");
}

void ContentTexture::upload(const ContentImage& image) {
  FACET_ASSERT(texture_ && image.size == image_size_ && image.pixels == pixels_);
  FACET_ASSERT(image.channels == 1 || image.channels == 3 || image.channels == 4);
  const std::size_t values = std::size_t(image.size.x) * image.size.y * image.channels;
  const bool is_float = pixels_ == ContentImage::Pixels::linear_f32;
  FACET_ASSERT(is_float ? image.values.size() == values : image.bytes.size() == values);
  const void* data = is_float ? static_cast<const void*>(image.values.data())
                              : static_cast<const void*>(image.bytes.data());
  const GLenum format = pixel_format(image);
  const GLenum type = is_float ? GL_FLOAT : GL_UNSIGNED_BYTE;
  // Grey images: every colour channel reads the one channel.
  const GLint swizzle[4] = {GL_RED, image.channels == 1 ? GL_RED : GL_GREEN,
                            image.channels == 1 ? GL_RED : GL_BLUE, GL_ONE};
  glTextureParameteriv(texture_.id(), GL_TEXTURE_SWIZZLE_RGBA, swizzle);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (format_ == ContentFormat::cubemap) {
    const int face = image_size_.y;
    glPixelStorei(GL_UNPACK_ROW_LENGTH, image_size_.x);
    for (int f = 0; f < 6; ++f) {
      glPixelStorei(GL_UNPACK_SKIP_PIXELS, f * face);
      glTextureSubImage3D(texture_.id(), 0, 0, 0, f, face, face, 1, format, type, data);
    }
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
  } else {
    glTextureSubImage2D(texture_.id(), 0, 0, 0, image_size_.x, image_size_.y, format, type, data);
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glGenerateTextureMipmap(texture_.id());
  check_gl_error("content upload");
}

ContentLookups prepare_content_lookups(std::span<const OutputSpec> outputs,
                                       const ResampleOptions& options, std::stop_token stop) {
  ContentLookups lookups;
  for (const OutputSpec& output : outputs) {
    const glm::ivec2 size = output.warp.output_size;
    const DirectionLookup directions = direction_lookup(output.warp, options.direction_cache,
                                                        options.direction_cache_budget, stop);
    if (directions.stopped) {
      ContentLookups none;
      none.stopped = true;
      return none;
    }
    lookups.from_cache += directions.from_cache ? 1 : 0;
    const std::vector<glm::vec3>& v_eye = directions.v_eye;
    // GL rows start at the bottom.
    std::vector<glm::vec4> texels(v_eye.size(), glm::vec4(0));
    for (int y = 0; y < size.y; ++y) {
      const glm::vec3* from = v_eye.data() + std::size_t(y) * size.x;
      glm::vec4* to = texels.data() + flipped_row_start(y, size.y, size.x);
      for (int x = 0; x < size.x; ++x)
        if (!std::isnan(from[x].x)) to[x] = glm::vec4(from[x], 1.0f);
    }
    lookups.sizes.push_back(size);
    lookups.texels.push_back(std::move(texels));
  }
  return lookups;
}

ContentPass::ContentPass(std::span<const OutputSpec> outputs, ResampleOptions options)
    : ContentPass(prepare_content_lookups(outputs, options), options) {}

ContentPass::ContentPass(ContentLookups lookups, ResampleOptions options) : options_(options) {
  FACET_ASSERT(lookups.sizes.size() == lookups.texels.size());
  lookups_from_cache_ = lookups.from_cache;
  for (std::size_t i = 0; i < lookups.sizes.size(); ++i) {
    const glm::ivec2 size = lookups.sizes[i];
    FACET_ASSERT(lookups.texels[i].size() == std::size_t(size.x) * size.y);
    Texture texture = Texture::create_2d(GL_RGBA32F, size.x, size.y);
    glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureSubImage2D(texture.id(), 0, 0, 0, size.x, size.y, GL_RGBA, GL_FLOAT,
                        lookups.texels[i].data());
    // The GL has its copy.
    std::vector<glm::vec4>().swap(lookups.texels[i]);
    lookups_.push_back(std::move(texture));
    sizes_.push_back(size);
  }
  max_anisotropy_ = std::clamp(options.max_anisotropy, 1, 64);
  sampler_has_anisotropy_ = has_anisotropic_filtering();
  if (options.hardware_anisotropy && sampler_has_anisotropy_) {
    float most = 1;
    glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &most);
    hardware_anisotropy_ = std::clamp(float(options.max_anisotropy), 1.0f, most);
  }
  program_ =
      ProgramBuilder().shader("baselines/fullscreen.vert").shader("output/content.frag").link();
  vertex_array_ = VertexArray::create();
  check_gl_error("content pass");
}

void ContentPass::draw(std::size_t output, const ContentTexture& content,
                       const ContentProjection& projection) const {
  FACET_ASSERT(output < lookups_.size());
  const GLuint texture = content.texture().id();
  const bool cube = content.format() == ContentFormat::cubemap;
  FACET_ASSERT(cube == (projection.format == ContentFormat::cubemap));
  glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  const GLint wrap_s = projection.format == ContentFormat::equirect ? GL_REPEAT : GL_CLAMP_TO_EDGE;
  glTextureParameteri(texture, GL_TEXTURE_WRAP_S, wrap_s);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  if (sampler_has_anisotropy_)
    glTextureParameterf(texture, GL_TEXTURE_MAX_ANISOTROPY, hardware_anisotropy_);
  if (cube) glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);

  const glm::ivec2 size = sizes_[output];
  glViewport(0, 0, size.x, size.y);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  program_.use();
  lookups_[output].bind_unit(0);
  content.texture().bind_unit(cube ? 2 : 1);
  const glm::mat3 R_content_eye(glm::transpose(projection.R_eye_content));
  glUniformMatrix3fv(0, 1, GL_FALSE, glm::value_ptr(R_content_eye));
  int format = 0;
  glm::vec4 params(0);
  switch (projection.format) {
    case ContentFormat::fisheye:
      format = 0;
      params.x = float(2.0 / (projection.fov_deg * M_PI / 180.0));
      break;
    case ContentFormat::equirect:
      format = 1;
      break;
    case ContentFormat::cubemap:
      format = 2;
      break;
    case ContentFormat::perspective:
      format = 3;
      params = glm::vec4(glm::dvec4(projection.tan_extent[0], projection.tan_extent[1],
                                    projection.tan_extent[2], projection.tan_extent[3]));
      break;
  }
  glUniform1i(1, format);
  glUniform4fv(2, 1, glm::value_ptr(params));
  glUniform1i(3, options_.bicubic_when_magnifying ? 1 : 0);
  glUniform1i(4, hardware_anisotropy_ > 1 ? 1 : max_anisotropy_);
  glBindVertexArray(vertex_array_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glBindTextureUnit(1, 0);
  glBindTextureUnit(2, 0);
  check_gl_error("content draw");
}

}  // namespace facet::driver
