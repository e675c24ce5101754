#include "facet/projection_io/exr_header.hpp"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "facet/projection/errors.hpp"

namespace facet::projection_io {
namespace {

constexpr std::uint32_t kMagic = 20000630;        // OpenEXR's magic number, little-endian
constexpr std::uint32_t kMultiPartFlag = 0x1000;  // bit 12 of the version field
constexpr int kMaxAttributes = 100000;

std::uint32_t little_endian_u32(const unsigned char* bytes) {
  return std::uint32_t(bytes[0]) | std::uint32_t(bytes[1]) << 8 | std::uint32_t(bytes[2]) << 16 |
         std::uint32_t(bytes[3]) << 24;
}

}  // namespace

void check_exr_header(const std::string& path) {
  std::error_code error;
  const std::uintmax_t file_size = std::filesystem::file_size(path, error);
  if (error) return;  // the reader says what is wrong with the file itself
  std::ifstream in(path, std::ios::binary);
  unsigned char start[8];
  if (!in.read(reinterpret_cast<char*>(start), 8) || little_endian_u32(start) != kMagic) return;
  const bool multi_part = (little_endian_u32(start + 4) & kMultiPartFlag) != 0;
  std::uintmax_t at = 8;
  // A NUL-terminated name of 1 to 255 bytes; "" at the end of a header.
  auto read_name = [&](const char* what) {
    std::string name;
    for (char c = 0; in.get(c) && c != '\0';) {
      if (name.size() == 255)
        throw InputError(path, "EXR header",
                         std::string("an attribute ") + what + " of at most 255 bytes");
      name += c;
    }
    if (!in) throw InputError(path, "EXR header", "a complete header; the file ends inside it");
    at += name.size() + 1;
    return name;
  };
  for (int attributes = 0;;) {
    const std::string name = read_name("name");
    if (name.empty()) {
      // The end of a header: a multi-part file has another unless an empty one follows.
      if (!multi_part || in.peek() == 0 || in.peek() == std::char_traits<char>::eof()) return;
      continue;
    }
    const std::string type = read_name("type");
    if (type.empty()) throw InputError(path, "EXR header", "a type for attribute '" + name + "'");
    unsigned char size_bytes[4];
    if (!in.read(reinterpret_cast<char*>(size_bytes), 4))
      throw InputError(path, "EXR header", "a complete header; the file ends inside it");
    at += 4;
    const auto size = static_cast<std::int32_t>(little_endian_u32(size_bytes));
    if (size < 0 || std::uintmax_t(size) > file_size - at)
      throw InputError(path, "EXR header",
                       "attribute '" + name + "' of " + std::to_string(size) +
                           " bytes, but the file has " + std::to_string(file_size - at) +
                           " bytes left");
    at += std::uintmax_t(size);
    in.seekg(std::streamoff(at));
    if (++attributes > kMaxAttributes)
      throw InputError(path, "EXR header",
                       "at most " + std::to_string(kMaxAttributes) + " attributes");
  }
}

}  // namespace facet::projection_io
