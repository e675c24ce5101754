#include "facet/projection_io/blend_file.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "facet/projection/warp.hpp"
#include "facet/projection_io/exr_header.hpp"

namespace facet::projection_io {
namespace {

constexpr const char* kFormat = "facet-blend/1";
constexpr const char* kAttribute = "facet:blend";

}  // namespace

BlendMap BlendMap::constant(glm::ivec2 size, float value, int channels) {
  BlendMap map;
  map.size = size;
  map.channels = channels;
  map.values.assign(std::size_t(std::max(size.x, 0)) * std::max(size.y, 0) * channels, value);
  return map;
}

double BlendMap::sample(glm::dvec2 q, int channel) const {
  const double x = std::clamp(q.x - 0.5, 0.0, double(size.x - 1));
  const double y = std::clamp(q.y - 0.5, 0.0, double(size.y - 1));
  const int x0 = std::min(int(x), std::max(size.x - 2, 0));
  const int y0 = std::min(int(y), std::max(size.y - 2, 0));
  const int x1 = std::min(x0 + 1, size.x - 1), y1 = std::min(y0 + 1, size.y - 1);
  const double fx = x - x0, fy = y - y0;
  return (at(x0, y0, channel) * (1 - fx) + at(x1, y0, channel) * fx) * (1 - fy) +
         (at(x0, y1, channel) * (1 - fx) + at(x1, y1, channel) * fx) * fy;
}

void BlendMap::validate(const std::string& source) const {
  if (size.x < 1 || size.y < 1) throw InputError(source, "size", "a positive width and height");
  if (channels != 1 && channels != 3) {
    throw InputError(source, "channels", "Y, or R, G and B (1 or 3 channels)");
  }
  if (values.size() != std::size_t(size.x) * size.y * channels) {
    throw InputError(source, "pixels", "one value per pixel and channel");
  }
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!(values[k] >= 0.0f && values[k] <= 1.0f)) {
      const std::size_t pixel = k / channels;
      throw InputError(
          source,
          "pixel (" + std::to_string(pixel % size.x) + ", " + std::to_string(pixel / size.x) + ")",
          "a finite value in [0,1] (linear light), got " + std::to_string(values[k]));
    }
  }
}

BlendMap read_blend_map(const std::string& path, std::optional<glm::ivec2> expected_size) {
  const Activity activity("reading the blend map " + path);
  require_regular_file(path);
  check_exr_header(path);
  auto input = OIIO::ImageInput::open(path);
  if (!input) throw InputError(path, "", "cannot open as an image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = input->spec();
  const std::string meta_text = spec.get_string_attribute(kAttribute);
  if (meta_text.empty()) {
    throw InputError(path, kAttribute,
                     std::string("the header attribute {\"format\": \"") + kFormat + "\"}");
  }
  const auto meta = nlohmann::json::parse(meta_text, nullptr, false);
  if (meta.is_discarded() || !meta.is_object() || !meta.contains("format") ||
      meta["format"] != kFormat) {
    throw InputError(path, std::string(kAttribute) + ".format", std::string("\"") + kFormat + "\"");
  }
  std::vector<int> wanted;
  if (const int y = spec.channelindex("Y"); y >= 0) {
    wanted = {y};
  } else {
    wanted = {spec.channelindex("R"), spec.channelindex("G"), spec.channelindex("B")};
    if (std::find(wanted.begin(), wanted.end(), -1) != wanted.end()) {
      throw InputError(path, "channels", "channel Y, or channels R, G and B");
    }
  }
  if (expected_size && (spec.width != expected_size->x || spec.height != expected_size->y)) {
    throw InputError(path, "size",
                     std::to_string(expected_size->x) + "x" + std::to_string(expected_size->y) +
                         " pixels (the projector's output size), got " +
                         std::to_string(spec.width) + "x" + std::to_string(spec.height));
  }
  // An output's size at most (kMaxImagePixels), and only the channels the map keeps are read:
  // a header may claim any size and any number of channels.
  check_image_size({spec.width, spec.height}, path, "size");
  const int first = *std::min_element(wanted.begin(), wanted.end());
  const int end = *std::max_element(wanted.begin(), wanted.end()) + 1;
  const std::size_t pixel_count = std::size_t(spec.width) * std::size_t(spec.height);
  BlendMap map;
  map.size = {spec.width, spec.height};
  map.channels = int(wanted.size());
  bool in_order = end - first == map.channels;
  for (int c = 0; c < map.channels; ++c) in_order = in_order && wanted[std::size_t(c)] == first + c;
  std::vector<float> read(in_order ? 0 : pixel_count * std::size_t(end - first));
  map.values.resize(pixel_count * std::size_t(map.channels));
  float* into = in_order ? map.values.data() : read.data();
  if (!input->read_image(0, 0, first, end, OIIO::TypeDesc::FLOAT, into)) {
    throw InputError(path, "pixels", "readable image data: " + input->geterror());
  }
  if (!in_order) {
    const std::size_t span = std::size_t(end - first);
    for (std::size_t k = 0; k < pixel_count; ++k) {
      for (int c = 0; c < map.channels; ++c) {
        map.values[k * map.channels + c] =
            read[k * span + std::size_t(wanted[std::size_t(c)] - first)];
      }
    }
  }
  map.validate(path);
  return map;
}

void write_blend_map(const std::string& path, const BlendMap& map) {
  map.validate(path);
  OIIO::ImageSpec spec(map.size.x, map.size.y, map.channels, OIIO::TypeDesc::FLOAT);
  spec.channelnames =
      map.channels == 1 ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"};
  spec.attribute("compression", "zip");
  spec.attribute(kAttribute, nlohmann::json{{"format", kFormat}}.dump());
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    auto output = OIIO::ImageOutput::create("openexr");
    if (!output || !output->open(temporary.string(), spec)) {
      throw InputError(path, "", "cannot create the file: " + OIIO::geterror());
    }
    if (!output->write_image(OIIO::TypeDesc::FLOAT, map.values.data()) || !output->close()) {
      throw InputError(path, "", "cannot write the file: " + output->geterror());
    }
  });
}

}  // namespace facet::projection_io
