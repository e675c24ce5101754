#include "facet/driver/scene.hpp"

#include <cstring>
#include <glm/common.hpp>

namespace facet::driver {

void Aabb::extend(const glm::vec3& p) {
  p_min = glm::min(p_min, p);
  p_max = glm::max(p_max, p);
}

void Aabb::extend(const Aabb& box) {
  if (box.empty()) return;
  extend(box.p_min);
  extend(box.p_max);
}

bool Aabb::contains(const glm::vec3& p, float margin) const {
  return p.x >= p_min.x - margin && p.y >= p_min.y - margin && p.z >= p_min.z - margin &&
         p.x <= p_max.x + margin && p.y <= p_max.y + margin && p.z <= p_max.z + margin;
}

std::size_t Scene::triangle_count() const {
  std::size_t count = 0;
  for (const auto& object : objects)
    for (std::uint32_t i = 0; i < object.primitive_count; ++i)
      count += primitives[object.first_primitive + i].index_count / 3;
  return count;
}

Aabb Scene::bounds_world() const {
  Aabb box;
  for (const auto& object : objects) box.extend(object.bounds_world);
  return box;
}

void Scene::update_bounds() {
  for (auto& object : objects) {
    Aabb box;
    for (std::uint32_t i = 0; i < object.primitive_count; ++i) {
      const Primitive& primitive = primitives[object.first_primitive + i];
      for (std::uint32_t k = 0; k < primitive.index_count; ++k) {
        const glm::vec3& p_object = positions[indices[primitive.first_index + k]];
        box.extend(glm::vec3(object.T_world_object * glm::vec4(p_object, 1.0f)));
      }
    }
    object.bounds_world = box;
  }
}

namespace {

struct Fnv1a {
  std::uint64_t state = 14695981039346656037ull;
  void add(const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) {
      state ^= p[i];
      state *= 1099511628211ull;
    }
  }
  template <class T>
  void add_vector(const std::vector<T>& values) {
    const std::uint64_t count = values.size();
    add(&count, sizeof count);
    add(values.data(), values.size() * sizeof(T));
  }
};

}  // namespace

std::uint64_t geometry_hash(const Scene& scene) {
  Fnv1a hash;
  hash.add_vector(scene.positions);
  hash.add_vector(scene.normals);
  hash.add_vector(scene.uvs);
  hash.add_vector(scene.indices);
  for (const auto& primitive : scene.primitives) {
    hash.add(&primitive.first_index, sizeof primitive.first_index);
    hash.add(&primitive.index_count, sizeof primitive.index_count);
    hash.add(&primitive.material, sizeof primitive.material);
  }
  for (const auto& object : scene.objects) hash.add(&object.T_world_object, sizeof(glm::mat4));
  for (const auto& image : scene.images) hash.add_vector(image.rgba);
  return hash.state;
}

}  // namespace facet::driver
