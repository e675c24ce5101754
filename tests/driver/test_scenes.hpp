// Small scenes the driver's GL tests share.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>

#include "facet/driver/scene.hpp"

namespace facet::test {

// An inward-facing UV sphere of `radius` metres about the origin (the eye): every direction sees
// it. Its triangles are counter-clockwise seen from the centre; `material` is its one material.
inline driver::Scene background_sphere(int slices, int stacks, float radius,
                                       driver::Material material = {}) {
  driver::Scene scene;
  scene.materials.push_back(material);
  for (int j = 0; j <= stacks; ++j) {
    const double theta = M_PI * j / stacks;
    for (int i = 0; i <= slices; ++i) {
      const double phi = 2 * M_PI * i / slices;
      const glm::vec3 d(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                        float(std::sin(theta) * std::sin(phi)));
      scene.positions.push_back(radius * d);
      scene.normals.push_back(-d);
      scene.uvs.push_back({float(i) / float(slices), float(j) / float(stacks)});
    }
  }
  for (int j = 0; j < stacks; ++j) {
    for (int i = 0; i < slices; ++i) {
      const std::uint32_t a = std::uint32_t(j * (slices + 1) + i), b = a + 1,
                          c = a + std::uint32_t(slices + 1), d = c + 1;
      for (std::uint32_t v : {a, c, b, b, c, d}) scene.indices.push_back(v);
    }
  }
  scene.primitives.push_back({0, std::uint32_t(scene.indices.size()), 0});
  driver::Object object;
  object.primitive_count = 1;
  scene.objects.push_back(object);
  scene.update_bounds();
  return scene;
}

}  // namespace facet::test
