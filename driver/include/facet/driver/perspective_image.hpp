#pragma once
// The one perspective image of the "perspective" baseline (view deformation's image-based form):
// a frustum from covering_frustum (projection/content_projection.hpp), its size in texels, its
// reversed-Z projection and where a direction falls in it. No GL.
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <optional>

#include "facet/projection/content_projection.hpp"

namespace facet::driver {

// Texels of the image: `larger_side` along the frustum's wider tangent span, the other side in
// proportion (at least 1 each).
glm::ivec2 perspective_image_size(const Frustum& frustum, int larger_side);

// Clip coordinates of an eye-frame point (metres): window x, y span the image from the frustum's
// left and bottom tangents (GL rows from the bottom), depth z_near / distance along the axis,
// reversed-Z (clip control zero to one), infinite far plane.
glm::dmat4 perspective_image_clip_from_eye(const Frustum& frustum, double z_near);

// Texture coordinates in [0, 1]² (t = 0 the bottom row) of an eye direction; none when it does
// not lie in front of the image plane.
std::optional<glm::dvec2> perspective_image_st(const Frustum& frustum, const glm::dvec3& v_eye);

}  // namespace facet::driver
