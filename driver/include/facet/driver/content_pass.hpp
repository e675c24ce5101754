#pragma once
// Mode 2, image through warp: content an application or a file gives as a fisheye dome master,
// an equirectangular panorama, a cube map or a per-projector perspective image
// (projection/content_projection.hpp), resampled into every projector output through the
// display's exact warp. Each output pixel samples the content at its exact eye direction (the
// warp inverse at its centre, as `facet lookup` writes it) in linear light: bicubic where the
// content is coarser than the output, trilinear over mip levels and anisotropic where it is
// finer (cube maps: trilinear and anisotropic, bilinear when magnified). The caller then applies
// the output's BlendPass, as sessions do (ContentPlayer does both).
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <span>
#include <stop_token>
#include <vector>

#include "facet/driver/direction_cache.hpp"
#include "facet/driver/gl_objects.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/projection/content_projection.hpp"

namespace facet::driver {

// One decoded content image, row 0 at the top. A cube map is its 6:1 strip (ContentFormat).
struct ContentImage {
  enum class Pixels {
    srgb8,       // 8 bits a channel, sRGB-encoded (PNG, JPEG, video)
    linear_f32,  // linear light, float (EXR)
  };
  glm::ivec2 size{0, 0};
  int channels = 3;  // 1 (grey), 3 or 4 (alpha is ignored)
  bool bgr = false;  // channels 3 and 4 in blue, green, red order (OpenCV's frames)
  Pixels pixels = Pixels::srgb8;
  std::vector<std::uint8_t> bytes;  // srgb8: size.x · size.y · channels
  std::vector<float> values;        // linear_f32: size.x · size.y · channels
};

// A content image on the GPU with its mip levels: SRGB8_ALPHA8 for 8-bit images, RGBA16F for
// float ones (RGBA32F with `full_float`, for tests that read coordinates back); a GL cube map
// for ContentFormat::cubemap. Needs a current context.
class ContentTexture {
 public:
  ContentTexture() = default;
  // InputError(source, "image", ...) when the image does not fit the format (a cube strip that
  // is not 6:1) or the GL (GL_MAX_TEXTURE_SIZE, GL_MAX_CUBE_MAP_TEXTURE_SIZE).
  ContentTexture(ContentFormat format, glm::ivec2 image_size, ContentImage::Pixels pixels,
                 const std::string& source, bool full_float = false);
  // Uploads `image` (the size and pixel kind given at construction) and rebuilds the mip levels.
  void upload(const ContentImage& image);

  ContentFormat format() const { return format_; }
  glm::ivec2 image_size() const { return image_size_; }
  const Texture& texture() const { return texture_; }

 private:
  ContentFormat format_ = ContentFormat::fisheye;
  glm::ivec2 image_size_{0, 0};
  ContentImage::Pixels pixels_ = ContentImage::Pixels::srgb8;
  Texture texture_;
};

struct ResampleOptions {
  // Most trilinear taps along a footprint's major axis (1: isotropic trilinear), 1 to 64. The
  // shader spreads them itself, the same on every GL.
  int max_anisotropy = 16;
  // Leave anisotropy to the sampler instead (GL_EXT_ or GL_ARB_texture_filter_anisotropic, when
  // present), one tap in the shader. Off by default: llvmpipe's returns stray texels.
  bool hardware_anisotropy = false;
  bool bicubic_when_magnifying = true;
  // A folder keeping each output's direction lookup between starts (direction_cache.hpp): read
  // back when it holds one for the same warp, else computed and written there. Empty: always
  // computed, nothing written.
  std::filesystem::path direction_cache;
  // The most bytes of lookups the folder keeps; the least recently used beyond are removed.
  std::uint64_t direction_cache_budget = kDefaultDirectionCacheBudget;
};

// Every output's direction lookup as its texture holds it: GL rows from the bottom, the unit eye
// direction and 1 where the warp covers the pixel, 0 elsewhere. The CPU half of ContentPass,
// without GL, so that it can run on another thread while the content opens.
struct ContentLookups {
  std::vector<glm::ivec2> sizes;
  std::vector<std::vector<glm::vec4>> texels;
  std::size_t from_cache = 0;  // outputs read from the cache folder rather than computed
  bool stopped = false;        // stopped on request: no sizes or texels, for no output
};
// Inverts every output's warp at its pixel centres (WarpInverse, all hardware threads), or reads
// the directions from options.direction_cache. Thread-safe: touches no GL and no shared state
// besides the cache folder, whose files are written atomically. Once `stop` is requested it
// returns within a row of the inverse under way, `stopped`, writing no cache file for the
// output it stopped in.
ContentLookups prepare_content_lookups(std::span<const OutputSpec> outputs,
                                       const ResampleOptions& options, std::stop_token stop = {});

class ContentPass {
 public:
  ContentPass() = default;
  // Inverts every output's warp at its pixel centres (WarpInverse, all hardware threads) into a
  // direction lookup texture per output, or reads them from options.direction_cache. Needs a
  // current context.
  explicit ContentPass(std::span<const OutputSpec> outputs, ResampleOptions options = {});
  // The same from lookups already prepared (prepare_content_lookups with these options).
  ContentPass(ContentLookups lookups, ResampleOptions options);

  // Draws output `output`'s pixels into the bound framebuffer (its size the output's; the
  // viewport is set here). Pixels the warp does not cover are left as they are, and covered
  // ones whose direction the content has no value for are black.
  void draw(std::size_t output, const ContentTexture& content,
            const ContentProjection& projection) const;

  std::size_t output_count() const { return lookups_.size(); }
  glm::ivec2 output_size(std::size_t output) const { return sizes_.at(output); }
  int max_anisotropy() const { return max_anisotropy_; }
  // How many outputs' direction lookups were read from the cache rather than computed.
  std::size_t lookups_from_cache() const { return lookups_from_cache_; }
  // The sampler's anisotropy (1 unless ResampleOptions::hardware_anisotropy and the GL has it).
  float hardware_anisotropy() const { return hardware_anisotropy_; }

 private:
  std::vector<Texture> lookups_;
  std::vector<glm::ivec2> sizes_;
  ResampleOptions options_;
  int max_anisotropy_ = 1;
  std::size_t lookups_from_cache_ = 0;
  float hardware_anisotropy_ = 1;
  bool sampler_has_anisotropy_ = false;
  Program program_;
  VertexArray vertex_array_;
};

}  // namespace facet::driver
