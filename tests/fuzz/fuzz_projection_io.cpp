// Fuzz entry points of projection_io's readers: display.json, rig files, GLC cameras, warp and
// blend EXRs.
#include <cstdint>
#include <glm/glm.hpp>

#include "facet/projection/errors.hpp"
#include "facet/projection/warp.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/glc_file.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "fuzz_target.hpp"

namespace {
using facet::fuzz::scratch_folder;
using facet::fuzz::text_of;
using facet::fuzz::write_scratch;
}  // namespace

// Without checking referenced files, so that a valid document is validated to its end.
FACET_FUZZ_TARGET(display_json) {
  try {
    facet::projection_io::parse_display_config(std::string(text_of(bytes)), "fuzz/display.json",
                                               scratch_folder(), false);
  } catch (const facet::InputError&) {
  }
}

FACET_FUZZ_TARGET(rig_json) {
  try {
    facet::parse_rig(std::string(text_of(bytes)), "fuzz/rig.json");
  } catch (const facet::InputError&) {
  }
}

// A GLC camera that reads must also give its centre pixel's ray and project a point on it.
FACET_FUZZ_TARGET(glc_json) {
  try {
    const facet::PiecewiseGlc camera =
        facet::parse_glc_camera(std::string(text_of(bytes)), "fuzz/camera.glc.json");
    const auto ray = camera.ray(camera.size.x / 2, camera.size.y / 2);
    if (ray) {
      const std::int32_t piece =
          camera.piece_of_pixel[std::size_t(camera.size.y / 2) * std::size_t(camera.size.x) +
                                std::size_t(camera.size.x / 2)];
      camera.pieces[std::size_t(piece)].project(ray->origin + 2.0 * ray->direction);
    }
  } catch (const facet::InputError&) {
  }
}

// A warp that reads must also map its corners and centre, and project the view axis.
FACET_FUZZ_TARGET(warp_exr) {
  try {
    const facet::Warp warp = facet::read_warp(write_scratch("fuzz.warp.exr", bytes).string());
    for (const glm::dvec2 st : {glm::dvec2(0.0), glm::dvec2(0.5), glm::dvec2(1.0)}) {
      warp.q_from_st(st);
      warp.coverage_at(st);
      warp.v_eye_from_st(st);
    }
    warp.project(glm::dvec3(0.0, 0.0, -1.0));
  } catch (const facet::InputError&) {
  }
}

FACET_FUZZ_TARGET(blend_exr) {
  try {
    const auto map =
        facet::projection_io::read_blend_map(write_scratch("fuzz.blend.exr", bytes).string());
    map.sample(glm::dvec2(map.size) * 0.5);
  } catch (const facet::InputError&) {
  }
}
