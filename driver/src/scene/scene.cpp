#include "facet/driver/scene.hpp"

#include <cstring>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <stdexcept>
#include <string>
#include <type_traits>

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

std::array<glm::dvec4, 4> frustum_side_planes(const glm::dmat4& T_clip_frame) {
  const glm::dmat4 M = glm::transpose(T_clip_frame);  // M[k]: row k of T_clip_frame
  return {M[3] + M[0], M[3] - M[0], M[3] + M[1], M[3] - M[1]};
}

bool sphere_outside_a_plane(const BoundingSphere& sphere, std::span<const glm::dvec4> planes) {
  for (const glm::dvec4& plane : planes) {
    const glm::dvec3 normal(plane);
    if (glm::dot(normal, sphere.centre) + plane.w < -sphere.radius * glm::length(normal))
      return true;
  }
  return false;
}

std::vector<BoundingSphere> object_spheres(const Scene& scene, const glm::dmat4& T_frame_world) {
  std::vector<BoundingSphere> spheres(scene.objects.size());
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Aabb& box = scene.objects[o].bounds_world;
    if (box.empty()) continue;
    const glm::dvec3 p_min(box.p_min), p_max(box.p_max);
    spheres[o].centre = glm::dvec3(T_frame_world * glm::dvec4(0.5 * (p_min + p_max), 1.0));
    spheres[o].radius = 0.5 * glm::length(p_max - p_min);
  }
  return spheres;
}

void Scene::update_bounds() {
  // Each vertex an object's indices name is transformed once for that object (a mesh names a
  // vertex about six times): the stamp is the object's number + 1 once it has been.
  std::vector<std::uint32_t> stamp(positions.size(), 0u);
  for (std::size_t o = 0; o < objects.size(); ++o) {
    Object& object = objects[o];
    const auto mark = std::uint32_t(o + 1);
    Aabb box;
    for (std::uint32_t i = 0; i < object.primitive_count; ++i) {
      const Primitive& primitive = primitives[object.first_primitive + i];
      for (std::uint32_t k = 0; k < primitive.index_count; ++k) {
        const std::uint32_t v = indices[primitive.first_index + k];
        if (stamp[v] == mark) continue;
        stamp[v] = mark;
        box.extend(glm::vec3(object.T_world_object * glm::vec4(positions[v], 1.0f)));
      }
    }
    object.bounds_world = box;
  }
}

Scene subdivide_triangles(const Scene& scene, int n) {
  if (n < 1 || n > 64)
    throw std::invalid_argument("subdivide_triangles: n must be in [1, 64], got " +
                                std::to_string(n));
  Scene out;
  out.name = scene.name;
  out.objects = scene.objects;
  out.materials = scene.materials;
  out.images = scene.images;
  out.cameras = scene.cameras;
  out.animation = scene.animation;
  const std::uint64_t pieces = std::uint64_t(n) * std::uint64_t(n);
  const std::uint64_t corners = std::uint64_t(n + 1) * std::uint64_t(n + 2) / 2;
  std::uint64_t triangles = 0;
  for (const Primitive& p : scene.primitives) triangles += p.index_count / 3;
  const std::uint64_t max32 = std::numeric_limits<std::uint32_t>::max();
  if (triangles * pieces * 3 > max32 || triangles * corners > max32)
    throw std::invalid_argument("subdivide_triangles: " + std::to_string(triangles) +
                                " triangles cut " + std::to_string(pieces) +
                                " ways need more than 2^32 - 1 indices");
  out.positions.reserve(triangles * corners);
  out.normals.reserve(triangles * corners);
  out.uvs.reserve(triangles * corners);
  out.indices.reserve(triangles * pieces * 3);
  const bool has_normals = scene.normals.size() == scene.positions.size();
  const bool has_uvs = scene.uvs.size() == scene.positions.size();
  // Row j (0..n) of a triangle's corner grid starts at this offset and holds n + 1 - j corners.
  auto corner = [n](int i, int j) { return std::uint32_t(j * (n + 1) - j * (j - 1) / 2 + i); };
  for (const Primitive& primitive : scene.primitives) {
    Primitive p = primitive;
    p.first_index = static_cast<std::uint32_t>(out.indices.size());
    for (std::uint32_t t = 0; t + 2 < primitive.index_count; t += 3) {
      const std::uint32_t a = scene.indices[primitive.first_index + t];
      const std::uint32_t b = scene.indices[primitive.first_index + t + 1];
      const std::uint32_t c = scene.indices[primitive.first_index + t + 2];
      const std::uint32_t base = static_cast<std::uint32_t>(out.positions.size());
      // Corner (i, j) = a + (b - a) i/n + (c - a) j/n, i + j <= n.
      for (int j = 0; j <= n; ++j)
        for (int i = 0; i + j <= n; ++i) {
          // Weights k / n in double, rounded to float once: a point on an edge comes out on it
          // (the weights sum to 1 within 1e-16) and bit-identical from both triangles that share
          // the edge (the same two products, added in either order).
          const double u = double(i) / n, v = double(j) / n, w = double(n - i - j) / n;
          auto mix = [&](const auto& values) {
            using Vec = std::decay_t<decltype(values[a])>;
            if (i == 0 && j == 0) return values[a];
            if (i == n) return values[b];
            if (j == n) return values[c];
            using Dvec = glm::vec<Vec::length(), double>;
            return Vec(w * Dvec(values[a]) + u * Dvec(values[b]) + v * Dvec(values[c]));
          };
          out.positions.push_back(mix(scene.positions));
          if (has_normals) {
            const glm::vec3 normal = mix(scene.normals);
            const float length = glm::length(normal);
            out.normals.push_back(length > 0 ? normal / length : scene.normals[a]);
          }
          if (has_uvs) out.uvs.push_back(mix(scene.uvs));
        }
      // Upright pieces (i, j) (i+1, j) (i, j+1) and inverted ones (i+1, j) (i+1, j+1) (i, j+1):
      // the original winding.
      for (int j = 0; j < n; ++j)
        for (int i = 0; i + j < n; ++i) {
          out.indices.insert(out.indices.end(), {base + corner(i, j), base + corner(i + 1, j),
                                                 base + corner(i, j + 1)});
          if (i + j + 1 < n)
            out.indices.insert(
                out.indices.end(),
                {base + corner(i + 1, j), base + corner(i + 1, j + 1), base + corner(i, j + 1)});
        }
    }
    p.index_count = static_cast<std::uint32_t>(out.indices.size()) - p.first_index;
    out.primitives.push_back(p);
  }
  out.update_bounds();
  return out;
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
