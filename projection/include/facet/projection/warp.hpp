#pragma once
// Camera-texture offset maps (FORMATS.md §2): the exact map P from an eye-frame direction to an
// output pixel, as a base projection plus bilinearly interpolated pixel offsets.
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/projection/base_projection.hpp"
#include "facet/projection/errors.hpp"

namespace facet {

// The largest image size facet accepts anywhere a WxH is given (outputs, cameras, node grids):
// 16384 a side and 2^26 pixels (8192×8192) in all, beyond any projector or camera. A GL may
// allow less for outputs (OutputTarget checks it).
inline constexpr int kMaxImageSide = 16384;
inline constexpr std::int64_t kMaxImagePixels = std::int64_t(1) << 26;

// InputError naming `source` and `field` unless both sides are at least 1 and the size is within
// kMaxImageSide and kMaxImagePixels.
void check_image_size(glm::ivec2 size, const std::string& source, const InputField& field);

struct Warp {
  BaseProjection base;
  glm::dmat3 R_eye_base{1.0};        // base-frame directions into the eye frame
  glm::ivec2 output_size{0, 0};      // W, H in output pixels
  glm::ivec2 grid_size{2, 2};        // Gw, Gh nodes, each >= 2
  std::vector<glm::vec2> offset_px;  // (dx, dy) per node, row-major: index j * Gw + i
  std::vector<float> coverage;       // A per node, same layout
  std::optional<glm::dvec3> eye;     // eye point in the display's world frame, metres

  // A display with zero offsets and full coverage.
  static Warp analytic(const BaseProjection& base, glm::ivec2 output_size,
                       glm::ivec2 grid_size = {2, 2}, const glm::dmat3& R_eye_base = glm::dmat3(1));

  // Throws InputError naming `source`: sizes, non-finite values (naming the first bad node),
  // base parameters, and folds (see find_fold).
  void validate(const std::string& source = {}) const;
  // The first node, in row-major order, at which a covered cell of the node grid maps to the
  // output with reversed orientation or zero area; nullopt when the map is injective on the grid.
  std::optional<glm::ivec2> find_fold() const;

  std::size_t node_index(int i, int j) const { return std::size_t(j) * grid_size.x + i; }
  // Bilinear offset in output pixels at st; st is clamped to [0,1]².
  glm::dvec2 offset_at(glm::dvec2 st) const;
  double coverage_at(glm::dvec2 st) const;
  // Output pixel q = (s·W, t·H) + offset(s, t).
  glm::dvec2 q_from_st(glm::dvec2 st) const;
  glm::dvec3 v_eye_from_st(glm::dvec2 st) const { return R_eye_base * base.direction(st); }
  glm::dvec3 p_eye_surface_from_st(glm::dvec2 st) const {
    return R_eye_base * base.surface_point(st);
  }

  struct Projected {
    glm::dvec2 q;   // output pixel
    glm::dvec2 st;  // base-image coordinates
    bool covered;   // st in [0,1]² and coverage >= 0.5
  };
  // The exact map P for an eye-frame direction. nullopt where the base has no value.
  std::optional<Projected> project(glm::dvec3 v_eye,
                                   double s_hint = std::numeric_limits<double>::quiet_NaN()) const;
};

}  // namespace facet
