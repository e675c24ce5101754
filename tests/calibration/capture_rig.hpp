#pragma once
// The small dome of the calibration replay tests (replay_test.cpp) and the live-capture tests:
// two 128×96 projectors ("left", "right") on a 4 m sphere, 70° wide, aimed 25° left and right and
// 20° up with 20° overlap; a 320×256 stereographic camera (160°) at the eye looking 15° up. The
// rig's image effects are the calibration target's defaults (noise 1%, defocus 1 px, gamma 2.2,
// ambient 5%, 16-bit, phase 16 px in 4 steps).
#include <cmath>
#include <glm/glm.hpp>

#include "facet/projection/rig.hpp"

namespace facet::test {

inline Rig capture_test_rig() {
  auto look = [](const glm::dvec3& from, const glm::dvec3& to) {
    const glm::dvec3 forward = glm::normalize(to - from);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
    return glm::dmat3(right, glm::cross(forward, right), forward);
  };
  Rig rig;
  rig.screen.type = Screen::Type::sphere;
  rig.screen.radius = 4;
  for (int side = 0; side < 2; ++side) {
    ProjectorModel p;
    p.name = side == 0 ? "left" : "right";
    p.size = {128, 96};
    const double f = 64 / std::tan(glm::radians(35.0));
    p.focal_px = {f, f};
    p.principal_px = {64, 48};
    p.k = {-0.02, 0.002, 0};
    p.gamma = 2.2;
    p.t_eye_projector = {side == 0 ? 0.2 : -0.2, -0.3, 0.8};
    const double azimuth = glm::radians(side == 0 ? -25.0 : 25.0), elevation = glm::radians(20.0);
    const glm::dvec3 ahead(std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
                           -std::cos(azimuth) * std::cos(elevation));
    p.R_eye_projector = look(p.t_eye_projector, 4.0 * ahead);
    rig.projectors.push_back(p);
  }
  rig.camera.lensmodel = "LENSMODEL_STEREOGRAPHIC";
  rig.camera.size = {320, 256};
  rig.camera.fov_deg = 160;
  const glm::dvec3 forward(0, std::sin(glm::radians(15.0)), -std::cos(glm::radians(15.0)));
  const glm::dvec3 right(1, 0, 0);
  rig.camera.R_eye_camera = glm::dmat3(right, glm::cross(forward, right), forward);
  return rig;
}

}  // namespace facet::test
