// The small city and view the GLC methods' tests render, and a GLC camera as a render output.
#pragma once

#include <glm/glm.hpp>
#include <memory>

#include "facet/driver/city.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/projection/glc.hpp"

namespace facet::test {

struct GlcTestCity {
  driver::Scene scene = driver::build_city({.blocks_per_side = 2, .texture_size = 16});
  glm::dmat4 T_eye_world =
      glm::inverse(driver::CityCameraPath({.blocks_per_side = 2}).T_world_eye(3.0));
};

// Built once per test program.
inline const GlcTestCity& glc_test_city() {
  static const GlcTestCity city;
  return city;
}

// `camera` as an output: its warp carries only the output size.
inline driver::OutputSpec glc_output(const PiecewiseGlc& camera) {
  return {"glc", Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), camera.size),
          std::make_shared<const PiecewiseGlc>(camera)};
}

}  // namespace facet::test
