#pragma once
// Files of rendered outputs: colour as 8-bit PNG (the bytes sent to the projector), triangle IDs
// and depth as single-channel EXR. Images are top row first, as OutputTarget::read_* return them.
// Every writer writes a temporary file and renames it, so a failure leaves no partial file.
#include <cstdint>
#include <filesystem>
#include <glm/vec2.hpp>
#include <span>

namespace facet::driver {

// `rgba` holds size.x * size.y * 4 bytes. Throws InputError naming the file when it cannot be
// written.
void write_png_rgba8(const std::filesystem::path& path, glm::ivec2 size,
                     std::span<const std::uint8_t> rgba);
// IDs as a UINT channel "id" (exact for every 32-bit value).
void write_ids_exr(const std::filesystem::path& path, glm::ivec2 size,
                   std::span<const std::uint32_t> ids);
// Reversed-Z depth as a FLOAT channel "Z".
void write_depth_exr(const std::filesystem::path& path, glm::ivec2 size,
                     std::span<const float> depth);

}  // namespace facet::driver
