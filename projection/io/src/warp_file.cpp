#include "facet/projection_io/warp_file.hpp"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "facet/projection/warp.hpp"
#include "facet/projection_io/exr_header.hpp"
#include "json_fields.hpp"

namespace facet {
namespace {

using nlohmann::json;
constexpr const char* kFormat = "facet-warp/1";
constexpr const char* kAttribute = "facet:warp";

template <std::size_t N>
std::array<double, N> numbers(const json& meta, const char* field, const std::string& path) {
  const auto it = meta.find(field);
  if (it == meta.end() || !it->is_array() || it->size() != N) {
    throw InputError(path, std::string(kAttribute) + "." + field,
                     "expected an array of " + std::to_string(N) + " numbers");
  }
  std::array<double, N> values{};
  for (std::size_t k = 0; k < N; ++k) {
    if (!(*it)[k].is_number()) {
      throw InputError(path, std::string(kAttribute) + "." + field, "expected numbers");
    }
    values[k] = (*it)[k].get<double>();
  }
  return values;
}

json base_to_json(const Warp& warp) {
  const BaseProjection& base = warp.base;
  json meta = {{"format", kFormat},
               {"output_size", {warp.output_size.x, warp.output_size.y}},
               {"base", to_string(base.kind)}};
  meta["rotation"] = json_fields::from_dmat3(warp.R_eye_base);
  json_fields::put_base_parameters(base, meta);
  if (warp.eye) meta["eye"] = {warp.eye->x, warp.eye->y, warp.eye->z};
  return meta;
}

void base_from_json(const json& meta, const std::string& path, Warp& warp) {
  const std::string field_prefix = std::string(kAttribute) + ".";
  if (!meta.is_object()) throw InputError(path, kAttribute, "expected a JSON object");
  if (meta.value("format", std::string()) != kFormat) {
    throw InputError(path, field_prefix + "format", std::string("expected \"") + kFormat + "\"");
  }
  const auto size = numbers<2>(meta, "output_size", path);
  if (size[0] < 1 || size[1] < 1 || size[0] != std::floor(size[0]) ||
      size[1] != std::floor(size[1])) {
    throw InputError(path, field_prefix + "output_size", "expected two positive integers");
  }
  warp.output_size = {int(size[0]), int(size[1])};
  if (!meta.contains("base") || !meta["base"].is_string()) {
    throw InputError(path, field_prefix + "base", "expected a string");
  }
  warp.base.kind =
      base_kind_from_string(meta["base"].get<std::string>(), path, field_prefix + "base");
  if (meta.contains("rotation")) {
    warp.R_eye_base = json_fields::to_dmat3(
        meta["rotation"], json_fields::FieldPath(path, field_prefix + "rotation"));
  }
  warp.base = json_fields::to_base_parameters(meta, warp.base.kind,
                                              json_fields::FieldPath(path, kAttribute));
  if (meta.contains("eye")) {
    const auto eye = numbers<3>(meta, "eye", path);
    warp.eye = glm::dvec3(eye[0], eye[1], eye[2]);
  }
}

}  // namespace

Warp read_warp(const std::string& path) {
  const Activity activity("reading the warp " + path);
  require_regular_file(path);
  projection_io::check_exr_header(path);
  auto input = OIIO::ImageInput::open(path);
  if (!input) {
    throw InputError(path, "", "cannot open as an image: " + OIIO::geterror());
  }
  const OIIO::ImageSpec& spec = input->spec();
  const int channel_r = spec.channelindex("R"), channel_g = spec.channelindex("G"),
            channel_a = spec.channelindex("A");
  if (channel_r < 0 || channel_g < 0 || channel_a < 0) {
    throw InputError(path, "channels", "expected channels R (dx), G (dy) and A (coverage)");
  }
  const std::string meta_text = spec.get_string_attribute(kAttribute);
  if (meta_text.empty()) {
    throw InputError(path, kAttribute, "expected the header attribute holding the warp's JSON");
  }
  json meta;
  try {
    meta = json::parse(meta_text);
  } catch (const json::exception& e) {
    throw InputError(path, kAttribute, std::string("expected valid JSON: ") + e.what());
  }
  Warp warp;
  base_from_json(meta, path, warp);
  warp.grid_size = {spec.width, spec.height};
  // A node grid no larger than an image (kMaxImagePixels), and only R, G and A read: a header may
  // claim any size and any number of channels.
  check_image_size(warp.grid_size, path, "grid size");
  const int first = std::min({channel_r, channel_g, channel_a});
  const int end = std::max({channel_r, channel_g, channel_a}) + 1;
  const std::size_t span = std::size_t(end - first);
  const std::size_t nodes = std::size_t(spec.width) * std::size_t(spec.height);
  std::vector<float> pixels(nodes * span);
  if (!input->read_image(0, 0, first, end, OIIO::TypeDesc::FLOAT, pixels.data())) {
    throw InputError(path, "pixels", "cannot read the image data: " + input->geterror());
  }
  warp.offset_px.resize(nodes);
  warp.coverage.resize(nodes);
  for (std::size_t k = 0; k < nodes; ++k) {
    const float* pixel = &pixels[k * span];
    warp.offset_px[k] = {pixel[channel_r - first], pixel[channel_g - first]};
    warp.coverage[k] = pixel[channel_a - first];
  }
  warp.validate(path);
  return warp;
}

void write_warp(const std::string& path, const Warp& warp) {
  warp.validate(path);
  OIIO::ImageSpec spec(warp.grid_size.x, warp.grid_size.y, 3, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "A"};
  spec.alpha_channel = 2;
  spec.attribute("compression", "zip");
  spec.attribute(kAttribute, base_to_json(warp).dump());
  std::vector<float> pixels;
  pixels.reserve(warp.offset_px.size() * 3);
  for (std::size_t k = 0; k < warp.offset_px.size(); ++k) {
    pixels.insert(pixels.end(), {warp.offset_px[k].x, warp.offset_px[k].y, warp.coverage[k]});
  }
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    auto output = OIIO::ImageOutput::create("openexr");
    if (!output || !output->open(temporary.string(), spec)) {
      throw InputError(path, "", "cannot create the file: " + OIIO::geterror());
    }
    if (!output->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !output->close()) {
      throw InputError(path, "", "cannot write the file: " + output->geterror());
    }
  });
}

}  // namespace facet
