#include "facet/driver/output_images.hpp"

#include <OpenImageIO/imageio.h>

#include <stdexcept>
#include <string>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {

namespace {

void write_image(const std::filesystem::path& path, const OIIO::ImageSpec& spec,
                 const void* pixels) {
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    auto out = OIIO::ImageOutput::create(path.string());
    // close() writes what is left: a full disk fails there.
    if (!out || !out->open(temporary.string(), spec) || !out->write_image(spec.format, pixels) ||
        !out->close()) {
      const std::string reason = out ? out->geterror() : OIIO::geterror();
      throw InputError(path.string(), "", "a writable image file (" + reason + ")");
    }
  });
}

}  // namespace

void write_png_rgba8(const std::filesystem::path& path, glm::ivec2 size,
                     std::span<const std::uint8_t> rgba) {
  if (rgba.size() != std::size_t(size.x) * size.y * 4)
    throw std::invalid_argument("write_png_rgba8: pixel count does not match the size");
  OIIO::ImageSpec spec(size.x, size.y, 4, OIIO::TypeDesc::UINT8);
  // The alpha channel is not a coverage to premultiply by: keep the bytes as they are.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  write_image(path, spec, rgba.data());
}

void write_ids_exr(const std::filesystem::path& path, glm::ivec2 size,
                   std::span<const std::uint32_t> ids) {
  if (ids.size() != std::size_t(size.x) * size.y)
    throw std::invalid_argument("write_ids_exr: pixel count does not match the size");
  OIIO::ImageSpec spec(size.x, size.y, 1, OIIO::TypeDesc::UINT32);
  spec.channelnames = {"id"};
  spec.attribute("compression", "zip");
  write_image(path, spec, ids.data());
}

void write_depth_exr(const std::filesystem::path& path, glm::ivec2 size,
                     std::span<const float> depth) {
  if (depth.size() != std::size_t(size.x) * size.y)
    throw std::invalid_argument("write_depth_exr: pixel count does not match the size");
  OIIO::ImageSpec spec(size.x, size.y, 1, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Z"};
  spec.attribute("compression", "zip");
  write_image(path, spec, depth.data());
}

}  // namespace facet::driver
