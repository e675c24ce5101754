#include "facet/projection_io/exr_header.hpp"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

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

// Bytes of the attribute types OpenEXR reads at a fixed size whatever size the file gives.
int fixed_size(const std::string& type) {
  static const std::pair<const char*, int> kSizes[] = {
      {"box2i", 16},      {"box2f", 16},   {"v2i", 8},       {"v2f", 8},
      {"v2d", 16},        {"v3i", 12},     {"v3f", 12},      {"v3d", 24},
      {"m33f", 36},       {"m33d", 72},    {"m44f", 64},     {"m44d", 128},
      {"int", 4},         {"float", 4},    {"double", 8},    {"rational", 8},
      {"compression", 1}, {"envmap", 1},   {"lineOrder", 1}, {"deepImageState", 1},
      {"keycode", 28},    {"timecode", 8}, {"tiledesc", 9},  {"chromaticities", 32}};
  for (const auto& [name, size] : kSizes) {
    if (type == name) return size;
  }
  return -1;
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
  auto refuse = [&](const std::string& expected) {
    throw InputError(path, "EXR header", expected);
  };
  auto truncated = [&] { refuse("a complete header; the file ends inside it"); };
  // A NUL-terminated name of 1 to 255 bytes; "" at the end of a header or a channel list.
  auto read_name = [&](const char* what) {
    std::string name;
    for (char c = 0; in.get(c) && c != '\0';) {
      if (name.size() == 255) refuse(std::string("names of at most 255 bytes (") + what + ")");
      name += c;
    }
    if (!in) truncated();
    return name;
  };
  auto read_u32 = [&] {
    unsigned char bytes[4];
    if (!in.read(reinterpret_cast<char*>(bytes), 4)) truncated();
    return little_endian_u32(bytes);
  };
  for (int attributes = 0;;) {
    const std::string name = read_name("an attribute");
    if (name.empty()) {
      // The end of a header: a multi-part file has another unless an empty one follows.
      if (!multi_part || in.peek() == 0 || in.peek() == std::char_traits<char>::eof()) return;
      continue;
    }
    const std::string type = read_name("a type");
    if (type.empty()) refuse("a type for attribute '" + name + "'");
    const auto size = static_cast<std::int32_t>(read_u32());
    const auto value_at = static_cast<std::uintmax_t>(in.tellg());
    const std::string attribute = "attribute '" + name + "' (" + type + ")";
    if (size < 0 || std::uintmax_t(size) > file_size - value_at)
      refuse(attribute + " of " + std::to_string(size) + " bytes within the file, which has " +
             std::to_string(file_size - value_at) + " bytes left");
    // OpenEXR reads these by their content, not by the size given: the two must agree, or it
    // reads the rest of the header from elsewhere than this walk does.
    std::uintmax_t content = std::uintmax_t(size);
    if (const int fixed = fixed_size(type); fixed >= 0) {
      content = std::uintmax_t(fixed);
    } else if (type == "chlist") {
      content = 0;
      for (std::string channel; !(channel = read_name("a channel")).empty();) {
        content += channel.size() + 1 + 16;
        in.seekg(16, std::ios::cur);
      }
      content += 1;
    } else if (type == "preview") {
      const std::uint64_t width = read_u32(), height = read_u32();
      const std::uint64_t pixels = width * height;  // < 2^64: both sides are below 2^32
      content = pixels > file_size ? file_size + 1 : 8 + 4 * pixels;
    } else if (type == "stringvector") {
      // Each string is its length, then its bytes; none may leave the attribute.
      for (std::uintmax_t used = 0; used < std::uintmax_t(size);) {
        if (std::uintmax_t(size) - used < 4) refuse(attribute + " holding whole strings");
        const std::uint32_t length = read_u32();
        used += 4;
        if (length > std::uintmax_t(size) - used) refuse(attribute + " holding whole strings");
        used += length;
        in.seekg(std::streamoff(length), std::ios::cur);
      }
    } else if (type == "idmanifest") {
      refuse(attribute + ": no compressed ID manifest (its unpacked size is not checked)");
    }
    if (content != std::uintmax_t(size))
      refuse(attribute + " of " + std::to_string(size) + " bytes, as its type reads " +
             std::to_string(content));
    in.clear();
    in.seekg(std::streamoff(value_at + std::uintmax_t(size)));
    if (++attributes > kMaxAttributes)
      refuse("at most " + std::to_string(kMaxAttributes) + " attributes");
  }
}

}  // namespace facet::projection_io
