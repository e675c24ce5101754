#include "facet/interop/pfm.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "facet/projection/errors.hpp"

namespace facet::interop {
namespace {

// Reads one header token; PFM headers separate tokens by any whitespace, and writers differ in
// whether W and H share a line.
std::string_view next_token(std::string_view bytes, std::size_t& pos) {
  while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
  const std::size_t start = pos;
  while (pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[pos])) &&
         pos - start < 32) {
    ++pos;
  }
  return bytes.substr(start, pos - start);
}

long parse_positive(std::string_view token, const std::string& source, const char* field) {
  if (token.empty() || token.size() > 9) {
    throw InputError(source, field, "expected a positive integer of at most 9 digits");
  }
  long value = 0;
  for (char c : token) {
    if (c < '0' || c > '9') throw InputError(source, field, "expected a positive integer");
    value = value * 10 + (c - '0');
  }
  if (value <= 0) throw InputError(source, field, "expected a positive integer");
  return value;
}

}  // namespace

PfmImage parse_pfm(std::string_view bytes, const std::string& source) {
  std::size_t pos = 0;
  const std::string_view magic = next_token(bytes, pos);
  PfmImage image;
  if (magic == "PF") {
    image.channels = 3;
  } else if (magic == "Pf") {
    image.channels = 1;
  } else {
    throw InputError(source, "header", "expected a PFM file starting with \"PF\" or \"Pf\"");
  }
  const long width = parse_positive(next_token(bytes, pos), source, "width");
  const long height = parse_positive(next_token(bytes, pos), source, "height");
  if (std::size_t(width) * std::size_t(height) > kMaxPfmPixels) {
    throw InputError(source, "width, height",
                     "expected at most " + std::to_string(kMaxPfmPixels) + " pixels");
  }
  const std::string scale_token(next_token(bytes, pos));
  char* end = nullptr;
  const double scale = std::strtod(scale_token.c_str(), &end);
  if (scale_token.empty() || end != scale_token.c_str() + scale_token.size() ||
      !std::isfinite(scale) || scale == 0) {
    throw InputError(source, "scale", "expected a non-zero number (negative: little-endian)");
  }
  // Exactly one whitespace byte ends the header.
  if (pos >= bytes.size() || !std::isspace(static_cast<unsigned char>(bytes[pos]))) {
    throw InputError(source, "scale", "expected a line break after the scale");
  }
  ++pos;
  image.width = int(width);
  image.height = int(height);
  const std::size_t count = std::size_t(width) * std::size_t(height) * std::size_t(image.channels);
  if (bytes.size() - pos < count * 4) {
    throw InputError(source, "data",
                     "expected " + std::to_string(count * 4) + " bytes of float32 values, found " +
                         std::to_string(bytes.size() - pos));
  }
  const bool little = scale < 0;
  const bool swap = little != (std::endian::native == std::endian::little);
  image.values.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    std::uint32_t word;
    std::memcpy(&word, bytes.data() + pos + 4 * k, 4);
    if (swap) word = __builtin_bswap32(word);
    std::memcpy(&image.values[k], &word, 4);
  }
  return image;
}

std::string format_pfm(const PfmImage& image) {
  std::string out = (image.channels == 1 ? "Pf\n" : "PF\n") + std::to_string(image.width) + " " +
                    std::to_string(image.height) + "\n-1.0\n";
  const std::size_t header = out.size();
  out.resize(header + image.values.size() * 4);
  for (std::size_t k = 0; k < image.values.size(); ++k) {
    std::uint32_t word;
    std::memcpy(&word, &image.values[k], 4);
    if constexpr (std::endian::native == std::endian::big) word = __builtin_bswap32(word);
    std::memcpy(out.data() + header + 4 * k, &word, 4);
  }
  return out;
}

}  // namespace facet::interop
