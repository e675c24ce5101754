#include "image_map.hpp"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "facet/projection/errors.hpp"

namespace facet::interop {

projection_io::BlendMap decode_image_map(const std::string& bytes, const std::string& name,
                                         double gamma, glm::ivec2 size, const std::string& source) {
  OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
  auto input = OIIO::ImageInput::open(name, nullptr, &reader);
  if (!input) {
    (void)OIIO::geterror();
    throw InputError(source, name, "expected a PNG image");
  }
  const OIIO::ImageSpec spec = input->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 ||
      std::size_t(spec.width) * std::size_t(spec.height) > (std::size_t(1) << 26)) {
    throw InputError(source, name, "expected an image of at most 2^26 pixels");
  }
  std::vector<float> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    (void)input->geterror();
    throw InputError(source, name, "expected a readable PNG image");
  }
  const int channels = spec.nchannels >= 3 ? 3 : 1;
  projection_io::BlendMap result;
  result.size = size;
  result.channels = channels;
  result.values.resize(std::size_t(size.x) * size.y * channels);
  const auto texel = [&](int x, int y, int c) {
    x = std::clamp(x, 0, spec.width - 1);
    y = std::clamp(y, 0, spec.height - 1);
    return double(pixels[(std::size_t(y) * spec.width + x) * spec.nchannels + c]);
  };
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const double u = (x + 0.5) / size.x * spec.width - 0.5;
      const double v = (y + 0.5) / size.y * spec.height - 0.5;
      const int x0 = int(std::floor(u)), y0 = int(std::floor(v));
      const double fx = u - x0, fy = v - y0;
      for (int c = 0; c < channels; ++c) {
        double value = (texel(x0, y0, c) * (1 - fx) + texel(x0 + 1, y0, c) * fx) * (1 - fy) +
                       (texel(x0, y0 + 1, c) * (1 - fx) + texel(x0 + 1, y0 + 1, c) * fx) * fy;
        value = std::pow(std::clamp(value, 0.0, 1.0), gamma);
        result.at(x, y, c) = float(std::isfinite(value) ? value : 0.0);
      }
    }
  }
  return result;
}

std::string encode_png(const projection_io::BlendMap& map, int bits) {
  FACET_ASSERT(bits == 8 || bits == 16);
  std::vector<unsigned char> buffer;
  OIIO::Filesystem::IOVecOutput output(buffer);
  auto out = OIIO::ImageOutput::create("map.png", &output);
  FACET_ASSERT(out);
  OIIO::ImageSpec spec(map.size.x, map.size.y, map.channels,
                       bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  if (!out->open("map.png", spec) || !out->write_image(OIIO::TypeDesc::FLOAT, map.values.data()) ||
      !out->close()) {
    throw std::runtime_error("PNG encoding failed: " + out->geterror());
  }
  return std::string(buffer.begin(), buffer.end());
}

void collapse_equal_channels(projection_io::BlendMap& map) {
  if (map.channels != 3) return;
  const std::size_t pixels = std::size_t(map.size.x) * map.size.y;
  for (std::size_t k = 0; k < pixels; ++k) {
    const float* rgb = &map.values[3 * k];
    if (rgb[0] != rgb[1] || rgb[0] != rgb[2]) return;
  }
  for (std::size_t k = 0; k < pixels; ++k) map.values[k] = map.values[3 * k];
  map.values.resize(pixels);
  map.channels = 1;
}

}  // namespace facet::interop
