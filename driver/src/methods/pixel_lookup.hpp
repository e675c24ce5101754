#pragma once
// The per-output-pixel lookup textures of the image-based baselines (cubemap, perspective).
#include <functional>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <optional>

#include "facet/driver/gl_objects.hpp"
#include "facet/projection/warp.hpp"

namespace facet::driver::detail {

// An RGBA32F texture, nearest filtered, one texel per output pixel of `warp` (GL rows from the
// bottom): value(v_eye) at each pixel the warp covers, v_eye its exact eye direction through the
// warp inverse; zero elsewhere and where value gives none. Needs a current context.
Texture pixel_lookup_texture(
    const Warp& warp,
    const std::function<std::optional<glm::vec4>(const glm::dvec3& v_eye)>& value);

}  // namespace facet::driver::detail
