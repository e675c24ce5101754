// The procedural city. Determinism matters more than variety here: tests hash the result, and
// benchmarks on different machines must draw the same triangles. Hence PCG32 instead of
// <random>'s distributions (whose output differs between standard libraries), integer texture
// noise, and no transcendental functions in the geometry (the octagon uses sqrt(1/2) only). This
// file is compiled with -ffp-contract=off (see driver/CMakeLists.txt).
#include "facet/driver/city.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <stdexcept>
#include <string>

namespace facet::driver {

namespace {

// ---------------------------------------------------------------------------------------------
// Random numbers: PCG32 (O'Neill), XSH-RR output. Same sequence on every platform.
class Pcg32 {
 public:
  explicit Pcg32(std::uint64_t seed, std::uint64_t stream = 54u) : increment_((stream << 1u) | 1u) {
    next();
    state_ += seed;
    next();
  }
  std::uint32_t next() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ull + increment_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rotation = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rotation) | (xorshifted << ((32u - rotation) & 31u));
  }
  // Uniform in [0, 1): 24 random bits, exactly representable in a float.
  float uniform() { return static_cast<float>(next() >> 8) * (1.0f / 16777216.0f); }
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
  // Uniform integer in [lo, hi].
  int integer(int lo, int hi) {
    const auto span = static_cast<std::uint32_t>(hi - lo + 1);
    return lo + static_cast<int>(next() % span);
  }
  bool chance(float p) { return uniform() < p; }

 private:
  std::uint64_t state_ = 0;
  std::uint64_t increment_;
};

// ---------------------------------------------------------------------------------------------
// Procedural textures, RGBA8 sRGB, tiling. Noise is integer hashing, so images are exact.

std::uint32_t hash3(std::uint32_t x, std::uint32_t y, std::uint32_t seed) {
  std::uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
  h ^= h >> 15;
  h *= 0x2c1b3c6du;
  h ^= h >> 12;
  h *= 0x297a2d39u;
  h ^= h >> 15;
  return h;
}

// Value noise in [0, 1] with lattice `cell` texels, periodic over `size` texels.
float value_noise(int x, int y, int cell, int size, std::uint32_t seed) {
  const int period = std::max(1, size / cell);
  const int cx = x / cell, cy = y / cell;
  const float fx = static_cast<float>(x % cell) / static_cast<float>(cell);
  const float fy = static_cast<float>(y % cell) / static_cast<float>(cell);
  auto lattice = [&](int i, int j) {
    return static_cast<float>(hash3(static_cast<std::uint32_t>(i % period),
                                    static_cast<std::uint32_t>(j % period), seed) >>
                              8) *
           (1.0f / 16777216.0f);
  };
  const float sx = fx * fx * (3.0f - 2.0f * fx), sy = fy * fy * (3.0f - 2.0f * fy);
  const float top = lattice(cx, cy) + (lattice(cx + 1, cy) - lattice(cx, cy)) * sx;
  const float bottom = lattice(cx, cy + 1) + (lattice(cx + 1, cy + 1) - lattice(cx, cy + 1)) * sx;
  return top + (bottom - top) * sy;
}

// Two octaves plus per-texel grain, in [0, 1].
float texture_noise(int x, int y, int size, std::uint32_t seed) {
  const float grain =
      static_cast<float>(
          hash3(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), seed + 7u) >> 24) /
      255.0f;
  return 0.5f * value_noise(x, y, std::max(1, size / 8), size, seed) +
         0.3f * value_noise(x, y, std::max(1, size / 32), size, seed + 1u) + 0.2f * grain;
}

struct Rgb {
  float r, g, b;  // sRGB-encoded, 0..1
};

Rgb mix(Rgb a, Rgb b, float t) {
  return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}
Rgb scale(Rgb a, float s) { return {a.r * s, a.g * s, a.b * s}; }

std::uint8_t to_byte(float v) {
  const float clamped = std::min(std::max(v, 0.0f), 1.0f);
  return static_cast<std::uint8_t>(clamped * 255.0f + 0.5f);
}

template <class Shade>
Image make_image(std::string name, int size, Shade shade) {
  Image image;
  image.name = std::move(name);
  image.width = image.height = size;
  image.rgba.resize(static_cast<std::size_t>(size) * static_cast<std::size_t>(size) * 4u);
  std::size_t i = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const Rgb c = shade(x, y);
      image.rgba[i++] = to_byte(c.r);
      image.rgba[i++] = to_byte(c.g);
      image.rgba[i++] = to_byte(c.b);
      image.rgba[i++] = 255;
    }
  return image;
}

// A façade tile is one bay wide and one floor high, rows from the top of the floor. The window
// occupies [wx0, wx1) x [wy0, wy1) as fractions of the tile.
struct Window {
  float x0, x1, y0, y1;
  bool contains(float u, float v) const { return u >= x0 && u < x1 && v >= y0 && v < y1; }
  bool frame(float u, float v, float width) const {
    return contains(u, v) &&
           !(u >= x0 + width && u < x1 - width && v >= y0 + width && v < y1 - width);
  }
};

Rgb glass(float u, float v, float n) {
  // Sky reflected in the glass: lighter towards the top of each pane.
  const Rgb sky = mix(Rgb{0.35f, 0.45f, 0.55f}, Rgb{0.12f, 0.16f, 0.22f}, v);
  return mix(sky, Rgb{0.20f, 0.22f, 0.25f}, 0.3f * n + 0.1f * u);
}

std::vector<Image> city_textures(int size) {
  const float s = static_cast<float>(size);
  auto uv = [s](int x, int y) {
    return std::array<float, 2>{(static_cast<float>(x) + 0.5f) / s,
                                (static_cast<float>(y) + 0.5f) / s};
  };
  std::vector<Image> images;
  images.push_back(make_image("grass", size, [&](int x, int y) {
    const float n = texture_noise(x, y, size, 11u);
    return mix(Rgb{0.20f, 0.33f, 0.12f}, Rgb{0.36f, 0.50f, 0.20f}, n);
  }));
  images.push_back(make_image("asphalt", size, [&](int x, int y) {
    const float n = texture_noise(x, y, size, 12u);
    return scale(Rgb{0.30f, 0.30f, 0.32f}, 0.75f + 0.5f * n);
  }));
  images.push_back(make_image("sidewalk", size, [&](int x, int y) {
    // 4 x 4 paving slabs with grout.
    const auto [u, v] = uv(x, y);
    const float fu = u * 4.0f - std::floor(u * 4.0f), fv = v * 4.0f - std::floor(v * 4.0f);
    const bool grout = fu < 0.04f || fv < 0.04f;
    const float n = texture_noise(x, y, size, 13u);
    return grout ? Rgb{0.40f, 0.40f, 0.40f} : scale(Rgb{0.66f, 0.65f, 0.62f}, 0.85f + 0.3f * n);
  }));
  images.push_back(make_image("facade_brick", size, [&](int x, int y) {
    const auto [u, v] = uv(x, y);
    const Window window{0.28f, 0.72f, 0.22f, 0.78f};
    const float n = texture_noise(x, y, size, 14u);
    if (window.frame(u, v, 0.04f)) return Rgb{0.85f, 0.83f, 0.78f};
    if (window.contains(u, v)) return glass(u, v, n);
    // Running bond: 16 courses per floor, bricks offset by half on every other course.
    const float course = v * 16.0f;
    const int row = static_cast<int>(course);
    const float along = u * 4.0f + (row % 2 == 0 ? 0.0f : 0.5f);
    const bool mortar = course - std::floor(course) < 0.15f || along - std::floor(along) < 0.05f;
    const float tone =
        static_cast<float>(
            hash3(static_cast<std::uint32_t>(along), static_cast<std::uint32_t>(row), 5u) >> 24) /
        255.0f;
    return mortar ? Rgb{0.62f, 0.60f, 0.55f}
                  : scale(Rgb{0.55f, 0.25f, 0.18f}, 0.8f + 0.25f * tone + 0.1f * n);
  }));
  images.push_back(make_image("facade_glass", size, [&](int x, int y) {
    const auto [u, v] = uv(x, y);
    const float n = texture_noise(x, y, size, 15u);
    const bool mullion = u < 0.04f || u > 0.96f || (u > 0.48f && u < 0.52f);
    const bool spandrel = v > 0.82f;
    if (mullion) return Rgb{0.55f, 0.57f, 0.60f};
    if (spandrel) return scale(Rgb{0.25f, 0.28f, 0.32f}, 0.9f + 0.2f * n);
    return glass(u, v, n);
  }));
  images.push_back(make_image("facade_concrete", size, [&](int x, int y) {
    const auto [u, v] = uv(x, y);
    const float n = texture_noise(x, y, size, 16u);
    // A continuous window band across the bay.
    if (v > 0.30f && v < 0.70f && u > 0.03f) return glass(u, v, n);
    const bool joint = u < 0.015f || v < 0.015f;
    return joint ? Rgb{0.45f, 0.45f, 0.44f} : scale(Rgb{0.68f, 0.67f, 0.64f}, 0.85f + 0.3f * n);
  }));
  images.push_back(make_image("facade_plaster", size, [&](int x, int y) {
    const auto [u, v] = uv(x, y);
    const Window window{0.30f, 0.70f, 0.25f, 0.75f};
    const float n = texture_noise(x, y, size, 17u);
    if (window.frame(u, v, 0.035f)) return Rgb{0.95f, 0.95f, 0.93f};
    if (window.contains(u, v)) return glass(u, v, n);
    if (v > window.y1 && v < window.y1 + 0.05f && u > window.x0 - 0.05f && u < window.x1 + 0.05f)
      return Rgb{0.80f, 0.78f, 0.74f};  // sill
    return scale(Rgb{0.86f, 0.78f, 0.60f}, 0.9f + 0.15f * n);
  }));
  images.push_back(make_image("facade_stone", size, [&](int x, int y) {
    const auto [u, v] = uv(x, y);
    const Window window{0.33f, 0.67f, 0.15f, 0.85f};
    const float n = texture_noise(x, y, size, 18u);
    if (window.frame(u, v, 0.05f)) return Rgb{0.45f, 0.38f, 0.30f};
    if (window.contains(u, v)) return glass(u, v, n);
    const float course = v * 6.0f;
    const int row = static_cast<int>(course);
    const float along = u * 2.0f + (row % 2 == 0 ? 0.0f : 0.5f);
    const bool joint = course - std::floor(course) < 0.06f || along - std::floor(along) < 0.03f;
    return joint ? Rgb{0.50f, 0.47f, 0.42f} : scale(Rgb{0.76f, 0.70f, 0.58f}, 0.85f + 0.25f * n);
  }));
  images.push_back(make_image("roof_flat", size, [&](int x, int y) {
    const float n = texture_noise(x, y, size, 19u);
    return scale(Rgb{0.45f, 0.44f, 0.42f}, 0.6f + 0.6f * n);
  }));
  images.push_back(make_image("roof_tiles", size, [&](int x, int y) {
    const auto [u, v] = uv(x, y);
    const float rows = v * 8.0f;
    const int row = static_cast<int>(rows);
    const float along = u * 8.0f + (row % 2 == 0 ? 0.0f : 0.5f);
    const float f = rows - std::floor(rows);
    const float edge = along - std::floor(along);
    const float n = texture_noise(x, y, size, 20u);
    const float shade = (f > 0.8f ? 0.6f : 1.0f) * (edge < 0.06f ? 0.75f : 1.0f);
    return scale(Rgb{0.62f, 0.24f, 0.16f}, shade * (0.85f + 0.25f * n));
  }));
  images.push_back(make_image("bark", size, [&](int x, int y) {
    // Streaks along the trunk: noise stretched vertically.
    const float n = value_noise(x, y / 8, std::max(1, size / 16), size, 21u);
    return scale(Rgb{0.32f, 0.24f, 0.16f}, 0.6f + 0.6f * n);
  }));
  images.push_back(make_image("foliage", size, [&](int x, int y) {
    const float n = texture_noise(x, y, size, 22u);
    return mix(Rgb{0.10f, 0.25f, 0.08f}, Rgb{0.30f, 0.50f, 0.15f}, n);
  }));
  return images;
}

// ---------------------------------------------------------------------------------------------
// Geometry.

constexpr float root_half = 0.70710678118654752f;  // sqrt(1/2), the octagon's diagonal
constexpr std::array<glm::vec2, 8> octagon = {{{1, 0},
                                               {root_half, root_half},
                                               {0, 1},
                                               {-root_half, root_half},
                                               {-1, 0},
                                               {-root_half, -root_half},
                                               {0, -1},
                                               {root_half, -root_half}}};
constexpr glm::vec3 up{0, 1, 0};

constexpr std::uint32_t material_index(CityMaterial m) { return static_cast<std::uint32_t>(m); }
constexpr std::size_t material_count = static_cast<std::size_t>(CityMaterial::count);

class CityBuilder {
 public:
  Scene scene;

  void begin_object(std::string name) { object_name_ = std::move(name); }

  // Turns the triangles added since begin_object into one Object with a primitive per material.
  void end_object() {
    Object object;
    object.name = std::move(object_name_);
    object.first_primitive = static_cast<std::uint32_t>(scene.primitives.size());
    for (std::size_t m = 0; m < material_count; ++m) {
      auto& pending = pending_[m];
      if (pending.empty()) continue;
      Primitive primitive;
      primitive.first_index = static_cast<std::uint32_t>(scene.indices.size());
      primitive.index_count = static_cast<std::uint32_t>(pending.size());
      primitive.material = static_cast<std::uint32_t>(m);
      scene.indices.insert(scene.indices.end(), pending.begin(), pending.end());
      for (const std::uint32_t index : pending) object.bounds_world.extend(scene.positions[index]);
      scene.primitives.push_back(primitive);
      pending.clear();
    }
    object.primitive_count =
        static_cast<std::uint32_t>(scene.primitives.size()) - object.first_primitive;
    if (object.primitive_count > 0) scene.objects.push_back(std::move(object));
  }

  std::uint32_t vertex(const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv) {
    scene.positions.push_back(p);
    scene.normals.push_back(n);
    scene.uvs.push_back(uv);
    return static_cast<std::uint32_t>(scene.positions.size() - 1);
  }

  // A triangle facing `n_front`: the winding is chosen so that it is counter-clockwise seen
  // from that side. Vertex normals n0..n2 are stored as given.
  void triangle(CityMaterial m, std::array<glm::vec3, 3> p, std::array<glm::vec3, 3> n,
                std::array<glm::vec2, 3> uv, const glm::vec3& n_front) {
    const glm::vec3 n_geometric = glm::cross(p[1] - p[0], p[2] - p[0]);
    if (glm::dot(n_geometric, n_front) < 0) {
      std::swap(p[1], p[2]);
      std::swap(n[1], n[2]);
      std::swap(uv[1], uv[2]);
    }
    auto& out = pending_[material_index(m)];
    for (int i = 0; i < 3; ++i) out.push_back(vertex(p[i], n[i], uv[i]));
  }

  // A planar quad p0 p1 p2 p3 (in order around it) with one normal.
  void quad(CityMaterial m, const std::array<glm::vec3, 4>& p, const glm::vec3& n,
            const std::array<glm::vec2, 4>& uv) {
    quad(m, p, {n, n, n, n}, uv, n);
  }
  void quad(CityMaterial m, const std::array<glm::vec3, 4>& p, const std::array<glm::vec3, 4>& n,
            const std::array<glm::vec2, 4>& uv, const glm::vec3& n_front) {
    // Shared corner vertices keep the quad one piece for any later welding or tessellation.
    std::array<std::uint32_t, 4> v{};
    const bool flip = glm::dot(glm::cross(p[1] - p[0], p[3] - p[0]), n_front) < 0;
    for (int i = 0; i < 4; ++i)
      v[static_cast<std::size_t>(i)] =
          vertex(p[static_cast<std::size_t>(i)], n[static_cast<std::size_t>(i)],
                 uv[static_cast<std::size_t>(i)]);
    auto& out = pending_[material_index(m)];
    if (flip) {
      out.insert(out.end(), {v[0], v[2], v[1], v[0], v[3], v[2]});
    } else {
      out.insert(out.end(), {v[0], v[1], v[2], v[0], v[2], v[3]});
    }
  }

  // A horizontal rectangle at height y, split into cells of at most max_cell metres, facing up.
  // Texture coordinates are world x, z divided by uv_metres.
  void ground(CityMaterial m, float x0, float x1, float z0, float z1, float y, float max_cell,
              float uv_metres) {
    const int nx = std::max(1, static_cast<int>(std::ceil((x1 - x0) / max_cell)));
    const int nz = std::max(1, static_cast<int>(std::ceil((z1 - z0) / max_cell)));
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < nz; ++j) {
        const float xa = x0 + (x1 - x0) * static_cast<float>(i) / static_cast<float>(nx);
        const float xb = x0 + (x1 - x0) * static_cast<float>(i + 1) / static_cast<float>(nx);
        const float za = z0 + (z1 - z0) * static_cast<float>(j) / static_cast<float>(nz);
        const float zb = z0 + (z1 - z0) * static_cast<float>(j + 1) / static_cast<float>(nz);
        quad(m, {glm::vec3{xa, y, za}, {xb, y, za}, {xb, y, zb}, {xa, y, zb}}, up,
             {glm::vec2{xa, za} / uv_metres, glm::vec2{xb, za} / uv_metres,
              glm::vec2{xb, zb} / uv_metres, glm::vec2{xa, zb} / uv_metres});
      }
  }

  // A vertical wall from a to b (ground-plane points x, z) between heights y0 and y1, facing
  // to the right of a -> b seen from above (outward for a footprint listed counter-clockwise
  // seen from above). Split into `rows` x ceil(length / max_width) panels. Texture: one tile per
  // bay (the wall holds a whole number of bays) and per `floor_height`, tile tops at floor tops.
  void wall(CityMaterial m, glm::vec2 a, glm::vec2 b, float y0, float y1, int rows, float max_width,
            float nominal_bay, float floor_height) {
    const glm::vec2 d = b - a;
    const float length = glm::length(d);
    if (length <= 0) return;
    const glm::vec3 n = glm::vec3{-d.y, 0, d.x} / length;
    const int columns = std::max(1, static_cast<int>(std::ceil(length / max_width)));
    const float bays = std::max(1.0f, std::floor(length / nominal_bay + 0.5f));
    for (int c = 0; c < columns; ++c) {
      const float s0 = static_cast<float>(c) / static_cast<float>(columns);
      const float s1 = static_cast<float>(c + 1) / static_cast<float>(columns);
      const glm::vec2 pa = a + d * s0, pb = a + d * s1;
      for (int r = 0; r < rows; ++r) {
        const float ya = y0 + (y1 - y0) * static_cast<float>(r) / static_cast<float>(rows);
        const float yb = y0 + (y1 - y0) * static_cast<float>(r + 1) / static_cast<float>(rows);
        quad(m, {glm::vec3{pa.x, ya, pa.y}, {pb.x, ya, pb.y}, {pb.x, yb, pb.y}, {pa.x, yb, pa.y}},
             n,
             {glm::vec2{s0 * bays, -ya / floor_height},
              {s1 * bays, -ya / floor_height},
              {s1 * bays, -yb / floor_height},
              {s0 * bays, -yb / floor_height}});
      }
    }
  }

  // The four walls of an axis-aligned footprint [x0, x1] x [z0, z1], facing outwards.
  void walls(CityMaterial m, float x0, float x1, float z0, float z1, float y0, float y1, int rows,
             float max_width, float nominal_bay, float floor_height) {
    const std::array<glm::vec2, 4> corners = {{{x0, z1}, {x1, z1}, {x1, z0}, {x0, z0}}};
    for (std::size_t i = 0; i < 4; ++i)
      wall(m, corners[i], corners[(i + 1) % 4], y0, y1, rows, max_width, nominal_bay, floor_height);
  }

  // A closed box (all six faces, or five without the bottom), texture in metres / uv_metres.
  void box(CityMaterial m, glm::vec3 p_min, glm::vec3 p_max, float uv_metres, bool bottom) {
    walls(m, p_min.x, p_max.x, p_min.z, p_max.z, p_min.y, p_max.y, 1, 1e9f, uv_metres, uv_metres);
    ground(m, p_min.x, p_max.x, p_min.z, p_max.z, p_max.y, 1e9f, uv_metres);
    if (bottom) {
      const float y = p_min.y;
      quad(m,
           {glm::vec3{p_min.x, y, p_min.z},
            {p_max.x, y, p_min.z},
            {p_max.x, y, p_max.z},
            {p_min.x, y, p_max.z}},
           -up, {glm::vec2{0, 0}, {1, 0}, {1, 1}, {0, 1}});
    }
  }

  // An open octagonal prism around the vertical axis through c (ground-plane x, z).
  void prism(CityMaterial m, glm::vec2 c, float radius, float y0, float y1) {
    for (std::size_t i = 0; i < 8; ++i) {
      const glm::vec2 da = octagon[i], db = octagon[(i + 1) % 8];
      const glm::vec3 na{da.x, 0, da.y}, nb{db.x, 0, db.y};
      const float ua = static_cast<float>(i) / 8.0f, ub = static_cast<float>(i + 1) / 8.0f;
      const float v = (y1 - y0) / (radius * 6.0f);
      quad(m,
           {glm::vec3{c.x + radius * da.x, y0, c.y + radius * da.y},
            {c.x + radius * db.x, y0, c.y + radius * db.y},
            {c.x + radius * db.x, y1, c.y + radius * db.y},
            {c.x + radius * da.x, y1, c.y + radius * da.y}},
           {na, nb, nb, na}, {glm::vec2{ua, v}, {ub, v}, {ub, 0}, {ua, 0}}, na + nb);
    }
  }

  // A closed lathe around the vertical axis through c: `profile` holds (radius, height) pairs
  // from the bottom apex to the top apex (first and last radius 0).
  void lathe(CityMaterial m, glm::vec2 c, const std::vector<glm::vec2>& profile,
             glm::vec3 p_centre) {
    for (std::size_t k = 0; k + 1 < profile.size(); ++k) {
      const glm::vec2 lo = profile[k], hi = profile[k + 1];
      for (std::size_t i = 0; i < 8; ++i) {
        const glm::vec2 da = octagon[i], db = octagon[(i + 1) % 8];
        auto point = [&](glm::vec2 d, glm::vec2 rh) {
          return glm::vec3{c.x + rh.x * d.x, rh.y, c.y + rh.x * d.y};
        };
        auto normal = [&](const glm::vec3& p) { return glm::normalize(p - p_centre); };
        const glm::vec3 p0 = point(da, lo), p1 = point(db, lo), p2 = point(db, hi),
                        p3 = point(da, hi);
        const float ua = static_cast<float>(i) / 4.0f, ub = static_cast<float>(i + 1) / 4.0f;
        const float va = lo.y / 2.0f, vb = hi.y / 2.0f;
        const glm::vec3 n_front = normal(0.25f * (p0 + p1 + p2 + p3));
        if (lo.x == 0) {
          triangle(m, {p0, p2, p3}, {normal(p0), normal(p2), normal(p3)},
                   {glm::vec2{0.5f * (ua + ub), -va}, {ub, -vb}, {ua, -vb}}, n_front);
        } else if (hi.x == 0) {
          triangle(m, {p0, p1, p2}, {normal(p0), normal(p1), normal(p2)},
                   {glm::vec2{ua, -va}, {ub, -va}, {0.5f * (ua + ub), -vb}}, n_front);
        } else {
          quad(m, {p0, p1, p2, p3}, {normal(p0), normal(p1), normal(p2), normal(p3)},
               {glm::vec2{ua, -va}, {ub, -va}, {ub, -vb}, {ua, -vb}}, n_front);
        }
      }
    }
  }

 private:
  std::string object_name_;
  std::array<std::vector<std::uint32_t>, material_count> pending_;
};

// ---------------------------------------------------------------------------------------------
// Layout: streets on lines x = k * pitch and z = k * pitch, |k| <= blocks_per_side; blocks
// between them. Cross-section of a street from its centre line: asphalt to 4 m, sidewalk (raised
// 0.15 m) to 7 m, then the block's lot.

constexpr float pitch = 62.0f;
constexpr float asphalt_half = 4.0f;
constexpr float street_half = 7.0f;
constexpr float kerb = 0.15f;

void add_tree(CityBuilder& city, Pcg32& rng, glm::vec2 c, float base_y, const std::string& name) {
  const float s = rng.uniform(0.8f, 1.25f);
  const float trunk = 2.2f * s;
  city.begin_object(name);
  city.prism(CityMaterial::bark, c, 0.18f * s, base_y, base_y + trunk + 0.5f);
  const float r = 2.2f * s, h = 4.5f * s;
  const float y0 = base_y + trunk;
  const std::vector<glm::vec2> profile = {{0, y0},
                                          {0.75f * r, y0 + 0.12f * h},
                                          {r, y0 + 0.40f * h},
                                          {0.7f * r, y0 + 0.78f * h},
                                          {0, y0 + h}};
  city.lathe(CityMaterial::foliage, c, profile, glm::vec3{c.x, y0 + 0.45f * h, c.y});
  city.end_object();
}

void add_lamp(CityBuilder& city, glm::vec2 c, glm::vec2 towards_street, const std::string& name) {
  city.begin_object(name);
  const float height = 6.5f;
  city.prism(CityMaterial::metal, c, 0.09f, kerb, height);
  const glm::vec2 head = c + towards_street * 1.2f;
  const glm::vec2 lo = glm::min(c, head) - glm::vec2(0.15f),
                  hi = glm::max(c, head) + glm::vec2(0.15f);
  city.box(CityMaterial::metal, {lo.x, height - 0.25f, lo.y}, {hi.x, height, hi.y}, 1.0f, true);
  city.end_object();
}

struct Style {
  CityMaterial facade;
  float floor_height;
  float bay;
  int min_floors, max_floors;
  bool pitched_roof;
};

void add_building(CityBuilder& city, Pcg32& rng, float x0, float x1, float z0, float z1, float ring,
                  const std::string& name) {
  // Downtown (ring 0-1) is tall glass and concrete; then stone, brick and concrete; the outer
  // rings are low plastered and brick houses with pitched roofs.
  Style style{};
  if (ring <= 1.0f) {
    style = rng.chance(0.6f) ? Style{CityMaterial::facade_glass, 3.6f, 3.0f, 10, 24, false}
                             : Style{CityMaterial::facade_concrete, 3.4f, 3.5f, 7, 16, false};
  } else if (ring <= 2.0f) {
    const int pick = rng.integer(0, 2);
    style = pick == 0   ? Style{CityMaterial::facade_stone, 3.8f, 3.2f, 4, 7, false}
            : pick == 1 ? Style{CityMaterial::facade_brick, 3.2f, 3.0f, 4, 8, false}
                        : Style{CityMaterial::facade_concrete, 3.4f, 3.5f, 5, 10, false};
  } else {
    style = rng.chance(0.55f) ? Style{CityMaterial::facade_plaster, 3.0f, 3.2f, 2, 4, true}
                              : Style{CityMaterial::facade_brick, 3.2f, 3.0f, 2, 5, true};
  }
  const int floors = rng.integer(style.min_floors, style.max_floors);
  const float base = kerb;
  const float top = base + static_cast<float>(floors) * style.floor_height;
  // Panels at most two floors high and 11 m wide: fine enough for per-vertex projection
  // baselines, coarse enough to keep the triangle budget.
  const int rows = std::max(1, (floors + 1) / 2);
  city.begin_object(name);
  city.walls(style.facade, x0, x1, z0, z1, base, top, rows, 11.0f, style.bay, style.floor_height);
  if (style.pitched_roof) {
    const float rise = 0.35f * std::min(x1 - x0, z1 - z0);
    const bool along_x = (x1 - x0) >= (z1 - z0);
    // Ridge along the longer side; slopes on the long sides, gables (façade) on the short ones.
    const float half = along_x ? 0.5f * (z1 - z0) : 0.5f * (x1 - x0);
    const float slope = std::sqrt(half * half + rise * rise);
    const float ridge_y = top + rise;
    const float zc = 0.5f * (z0 + z1), xc = 0.5f * (x0 + x1);
    if (along_x) {
      const float u1 = (x1 - x0) / 2.0f, v1 = slope / 2.0f;
      city.quad(CityMaterial::roof_tiles,
                {glm::vec3{x0, top, z1}, {x1, top, z1}, {x1, ridge_y, zc}, {x0, ridge_y, zc}},
                glm::normalize(glm::vec3{0, half, rise}),
                {glm::vec2{0, v1}, {u1, v1}, {u1, 0}, {0, 0}});
      city.quad(CityMaterial::roof_tiles,
                {glm::vec3{x1, top, z0}, {x0, top, z0}, {x0, ridge_y, zc}, {x1, ridge_y, zc}},
                glm::normalize(glm::vec3{0, half, -rise}),
                {glm::vec2{0, v1}, {u1, v1}, {u1, 0}, {0, 0}});
      for (const float x : {x0, x1}) {
        const glm::vec3 n{x == x0 ? -1.0f : 1.0f, 0, 0};
        city.triangle(style.facade, {glm::vec3{x, top, z0}, {x, top, z1}, {x, ridge_y, zc}},
                      {n, n, n},
                      {glm::vec2{0, -top / style.floor_height},
                       {1, -top / style.floor_height},
                       {0.5f, -ridge_y / style.floor_height}},
                      n);
      }
    } else {
      const float u1 = (z1 - z0) / 2.0f, v1 = slope / 2.0f;
      city.quad(CityMaterial::roof_tiles,
                {glm::vec3{x1, top, z1}, {x1, top, z0}, {xc, ridge_y, z0}, {xc, ridge_y, z1}},
                glm::normalize(glm::vec3{rise, half, 0}),
                {glm::vec2{0, v1}, {u1, v1}, {u1, 0}, {0, 0}});
      city.quad(CityMaterial::roof_tiles,
                {glm::vec3{x0, top, z0}, {x0, top, z1}, {xc, ridge_y, z1}, {xc, ridge_y, z0}},
                glm::normalize(glm::vec3{-rise, half, 0}),
                {glm::vec2{0, v1}, {u1, v1}, {u1, 0}, {0, 0}});
      for (const float z : {z0, z1}) {
        const glm::vec3 n{0, 0, z == z0 ? -1.0f : 1.0f};
        city.triangle(style.facade, {glm::vec3{x0, top, z}, {x1, top, z}, {xc, ridge_y, z}},
                      {n, n, n},
                      {glm::vec2{0, -top / style.floor_height},
                       {1, -top / style.floor_height},
                       {0.5f, -ridge_y / style.floor_height}},
                      n);
      }
    }
  } else {
    city.ground(CityMaterial::roof_flat, x0, x1, z0, z1, top, 24.0f, 4.0f);
    // Roof-top plant rooms on some flat roofs.
    if (rng.chance(0.6f)) {
      // At most 40% of the roof each way, so the plant room stays on the roof.
      const float w = std::min(rng.uniform(3.0f, 6.0f), 0.4f * (x1 - x0));
      const float d = std::min(rng.uniform(3.0f, 6.0f), 0.4f * (z1 - z0));
      const float cx = rng.uniform(x0 + w, x1 - w), cz = rng.uniform(z0 + d, z1 - d);
      city.box(CityMaterial::metal, {cx - 0.5f * w, top, cz - 0.5f * d},
               {cx + 0.5f * w, top + rng.uniform(2.0f, 3.5f), cz + 0.5f * d}, 2.0f, false);
    }
  }
  city.end_object();
}

void add_block(CityBuilder& city, Pcg32& rng, int bx, int bz) {
  const float x0 = static_cast<float>(bx) * pitch, z0 = static_cast<float>(bz) * pitch;
  const float x1 = x0 + pitch, z1 = z0 + pitch;
  const std::string id = std::to_string(bx) + "," + std::to_string(bz);
  // Ring 0 holds the four blocks around the origin, ring n the blocks n steps further out.
  const float ring = static_cast<float>(std::max(std::max(bx, -bx - 1), std::max(bz, -bz - 1)));

  // Sidewalk ring (raised) with kerbs facing the streets, then the lot inside it.
  city.begin_object("block " + id + " sidewalk");
  const float ax0 = x0 + asphalt_half, ax1 = x1 - asphalt_half;
  const float az0 = z0 + asphalt_half, az1 = z1 - asphalt_half;
  const float lx0 = x0 + street_half, lx1 = x1 - street_half;
  const float lz0 = z0 + street_half, lz1 = z1 - street_half;
  city.ground(CityMaterial::sidewalk, ax0, ax1, az0, lz0, kerb, 30.0f, 3.0f);
  city.ground(CityMaterial::sidewalk, ax0, ax1, lz1, az1, kerb, 30.0f, 3.0f);
  city.ground(CityMaterial::sidewalk, ax0, lx0, lz0, lz1, kerb, 30.0f, 3.0f);
  city.ground(CityMaterial::sidewalk, lx1, ax1, lz0, lz1, kerb, 30.0f, 3.0f);
  city.walls(CityMaterial::sidewalk, ax0, ax1, az0, az1, 0.0f, kerb, 1, 30.0f, 1.0f, 1.0f);
  city.end_object();

  const bool central = ring == 0.0f;
  const bool park = !central && rng.chance(0.14f);
  city.begin_object("block " + id + " lot");
  city.ground(CityMaterial::grass, lx0, lx1, lz0, lz1, kerb, 24.0f, 4.0f);
  city.end_object();

  if (park) {
    // Trees on a jittered 4 x 4 grid, some left out for clearings.
    int tree = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        if (!rng.chance(0.75f)) continue;
        const float cx =
            lx0 + (static_cast<float>(i) + 0.5f) * (lx1 - lx0) / 4.0f + rng.uniform(-3, 3);
        const float cz =
            lz0 + (static_cast<float>(j) + 0.5f) * (lz1 - lz0) / 4.0f + rng.uniform(-3, 3);
        add_tree(city, rng, {cx, cz}, kerb, "park " + id + " tree " + std::to_string(tree++));
      }
    return;
  }

  // Lots: the block split in 1 to 3 parts along each axis (one large lot downtown).
  const int nx = central || ring <= 1.0f ? rng.integer(1, 2) : rng.integer(2, 3);
  const int nz = central || ring <= 1.0f ? rng.integer(1, 2) : rng.integer(2, 3);
  int building = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nz; ++j) {
      const float cx0 = lx0 + (lx1 - lx0) * static_cast<float>(i) / static_cast<float>(nx);
      const float cx1 = lx0 + (lx1 - lx0) * static_cast<float>(i + 1) / static_cast<float>(nx);
      const float cz0 = lz0 + (lz1 - lz0) * static_cast<float>(j) / static_cast<float>(nz);
      const float cz1 = lz0 + (lz1 - lz0) * static_cast<float>(j + 1) / static_cast<float>(nz);
      // Set back from the lot edges by 1 to 3 m, so buildings do not touch.
      const float inset = rng.uniform(1.0f, 3.0f);
      add_building(city, rng, cx0 + inset, cx1 - inset, cz0 + inset, cz1 - inset, ring,
                   "building " + id + "." + std::to_string(building++));
    }
}

void add_streets(CityBuilder& city, Pcg32& rng, int n) {
  const float extent = static_cast<float>(n) * pitch;
  for (int k = -n; k <= n; ++k) {
    const float c = static_cast<float>(k) * pitch;
    for (int m = -n; m < n; ++m) {
      const float a = static_cast<float>(m) * pitch + asphalt_half;
      const float b = static_cast<float>(m + 1) * pitch - asphalt_half;
      // Street pieces between intersections, along z (x = c) and along x (z = c).
      for (int axis = 0; axis < 2; ++axis) {
        city.begin_object("street " + std::to_string(axis) + ":" + std::to_string(k) + ":" +
                          std::to_string(m));
        if (axis == 0)
          city.ground(CityMaterial::asphalt, c - asphalt_half, c + asphalt_half, a, b, 0.0f, 12.0f,
                      8.0f);
        else
          city.ground(CityMaterial::asphalt, a, b, c - asphalt_half, c + asphalt_half, 0.0f, 12.0f,
                      8.0f);
        // Dashed centre line: 3 m dashes every 9 m, 5 mm above the asphalt.
        for (float s = a + 3.0f; s + 3.0f <= b; s += 9.0f) {
          const float y = 0.005f;
          if (axis == 0)
            city.ground(CityMaterial::road_marking, c - 0.08f, c + 0.08f, s, s + 3.0f, y, 1e9f,
                        1.0f);
          else
            city.ground(CityMaterial::road_marking, s, s + 3.0f, c - 0.08f, c + 0.08f, y, 1e9f,
                        1.0f);
        }
        city.end_object();
      }
    }
    for (int m = -n; m <= n; ++m) {
      const float d = static_cast<float>(m) * pitch;
      city.begin_object("intersection " + std::to_string(k) + ":" + std::to_string(m));
      city.ground(CityMaterial::asphalt, c - asphalt_half, c + asphalt_half, d - asphalt_half,
                  d + asphalt_half, 0.0f, 12.0f, 8.0f);
      city.end_object();
    }
  }
  // The outer sidewalk around the whole grid, kerbs facing inwards.
  const float e0 = extent + asphalt_half, e1 = extent + street_half;
  city.begin_object("outer sidewalk");
  city.ground(CityMaterial::sidewalk, -e1, e1, -e1, -e0, kerb, 30.0f, 3.0f);
  city.ground(CityMaterial::sidewalk, -e1, e1, e0, e1, kerb, 30.0f, 3.0f);
  city.ground(CityMaterial::sidewalk, -e1, -e0, -e0, e0, kerb, 30.0f, 3.0f);
  city.ground(CityMaterial::sidewalk, e0, e1, -e0, e0, kerb, 30.0f, 3.0f);
  // Walls listed the other way round face into the street.
  const std::array<glm::vec2, 4> corners = {{{-e0, -e0}, {e0, -e0}, {e0, e0}, {-e0, e0}}};
  for (std::size_t i = 0; i < 4; ++i)
    city.wall(CityMaterial::sidewalk, corners[i], corners[(i + 1) % 4], 0.0f, kerb, 1, 30.0f, 1.0f,
              1.0f);
  city.end_object();

  // Avenues through the origin: trees and lamps alternating on both sidewalks.
  int lamp = 0, tree = 0;
  for (int axis = 0; axis < 2; ++axis)
    for (int m = -n; m < n; ++m)
      for (int slot = 0; slot < 3; ++slot) {
        const float s =
            static_cast<float>(m) * pitch + street_half + 8.0f + 16.0f * static_cast<float>(slot);
        for (const float side : {-1.0f, 1.0f}) {
          const float offset = side * (asphalt_half + 1.5f);
          const glm::vec2 p = axis == 0 ? glm::vec2{offset, s} : glm::vec2{s, offset};
          const glm::vec2 towards = axis == 0 ? glm::vec2{-side, 0} : glm::vec2{0, -side};
          if (slot == 1)
            add_lamp(city, p, towards, "lamp " + std::to_string(lamp++));
          else
            add_tree(city, rng, p, kerb, "avenue tree " + std::to_string(tree++));
        }
      }
}

// Grass between the box [x0, x1] x [z0, z1] (the outer sidewalks' edge) and the box
// [gx0, gx1] x [gz0, gz1] around it, as four strips.
void add_grass_frame(CityBuilder& city, float x0, float x1, float z0, float z1, float gx0,
                     float gx1, float gz0, float gz1) {
  const std::array<std::array<float, 4>, 4> strips = {
      {{gx0, gx1, gz0, z0}, {gx0, gx1, z1, gz1}, {gx0, x0, z0, z1}, {x1, gx1, z0, z1}}};
  int index = 0;
  for (const auto& s : strips) {
    city.begin_object("countryside " + std::to_string(index++));
    city.ground(CityMaterial::grass, s[0], s[1], s[2], s[3], 0.0f, 62.0f, 4.0f);
    city.end_object();
  }
}

// Half the width of a city of n blocks per side out to its outer sidewalks, and how far from the
// centre its countryside reaches (a horizon ring 4 blocks further, at least 600 m), metres.
float city_half_extent(int n) { return static_cast<float>(n) * pitch + street_half; }
float countryside_reach(int n) { return std::max(600.0f, city_half_extent(n) + 4.0f * pitch); }

void add_countryside(CityBuilder& city, int n) {
  const float e = city_half_extent(n), r = countryside_reach(n);
  add_grass_frame(city, -e, e, -e, e, -r, r, -r, r);
}

std::vector<Material> city_materials() {
  auto textured = [](std::string name, int texture) {
    Material m;
    m.name = std::move(name);
    m.texture = texture;
    return m;
  };
  std::vector<Material> materials = {
      textured("grass", 0),
      textured("asphalt", 1),
      textured("sidewalk", 2),
      Material{"road_marking", {0.85f, 0.85f, 0.80f, 1.0f}, -1, true},
      textured("facade_brick", 3),
      textured("facade_glass", 4),
      textured("facade_concrete", 5),
      textured("facade_plaster", 6),
      textured("facade_stone", 7),
      textured("roof_flat", 8),
      textured("roof_tiles", 9),
      textured("bark", 10),
      textured("foliage", 11),
      Material{"metal", {0.35f, 0.37f, 0.40f, 1.0f}, -1, true}};
  return materials;
}

// The countryside of k x k tiles: as wide a margin beyond the outer tiles' sidewalks as one
// city has beyond its own.
void add_tiles_countryside(CityBuilder& city, int k, const CityOptions& options) {
  const float period = static_cast<float>(city_tile_period_m(options));
  const float e1 = 0.5f * period;
  const float lo = static_cast<float>(city_tile_offset(0, k)) * period - e1;
  const float hi = static_cast<float>(city_tile_offset(k - 1, k)) * period + e1;
  const int n = options.blocks_per_side;
  const float margin = countryside_reach(n) - city_half_extent(n);
  add_grass_frame(city, lo, hi, lo, hi, lo - margin, hi + margin, lo - margin, hi + margin);
}

void check_city_options(const CityOptions& options) {
  if (options.blocks_per_side < 1 || options.blocks_per_side > 16)
    throw std::invalid_argument("build_city: blocks_per_side must be in [1, 16], got " +
                                std::to_string(options.blocks_per_side));
  const int t = options.texture_size;
  if (t < 8 || t > 1024 || (t & (t - 1)) != 0)
    throw std::invalid_argument(
        "build_city: texture_size must be a power of two in [8, 1024], got " + std::to_string(t));
}

// The city without its countryside: streets, blocks, buildings, trees and lamps.
CityBuilder city_core(const CityOptions& options) {
  check_city_options(options);
  CityBuilder city;
  city.scene.name = "facet city (seed " + std::to_string(options.seed) + ")";
  city.scene.materials = city_materials();
  city.scene.images = city_textures(options.texture_size);
  Pcg32 rng(options.seed);
  const int n = options.blocks_per_side;
  add_streets(city, rng, n);
  for (int bx = -n; bx < n; ++bx)
    for (int bz = -n; bz < n; ++bz) add_block(city, rng, bx, bz);
  return city;
}

}  // namespace

Scene build_city(const CityOptions& options) {
  CityBuilder city = city_core(options);
  add_countryside(city, options.blocks_per_side);
  return std::move(city.scene);
}

double city_tile_period_m(const CityOptions& options) {
  return 2.0 * (double(options.blocks_per_side) * pitch + street_half);
}

int city_tile_offset(int i, int k) { return i - (k - 1) / 2; }

std::uint64_t city_tiles_triangle_count(int k, const CityOptions& options) {
  if (k < 1 || k > 64)
    throw std::invalid_argument("city_tiles_triangle_count: k must be in [1, 64], got " +
                                std::to_string(k));
  if (k == 1) return build_city(options).triangle_count();
  const std::uint64_t tile = city_core(options).scene.triangle_count();
  CityBuilder countryside;
  add_tiles_countryside(countryside, k, options);
  return tile * std::uint64_t(k) * std::uint64_t(k) + countryside.scene.triangle_count();
}

Scene build_city_tiles(int k, const CityOptions& options) {
  if (k < 1 || k > 64)
    throw std::invalid_argument("build_city_tiles: k must be in [1, 64], got " + std::to_string(k));
  if (k == 1) return build_city(options);
  CityBuilder city = city_core(options);
  const std::vector<Object> tile = std::move(city.scene.objects);
  city.scene.objects.clear();
  city.scene.objects.reserve(tile.size() * std::size_t(k) * std::size_t(k) + 4);
  const float period = static_cast<float>(city_tile_period_m(options));  // exact: 2 (n 62 + 7)
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const glm::vec3 offset(static_cast<float>(city_tile_offset(i, k)) * period, 0.0f,
                             static_cast<float>(city_tile_offset(j, k)) * period);
      const std::string prefix = "tile " + std::to_string(city_tile_offset(i, k)) + "," +
                                 std::to_string(city_tile_offset(j, k)) + " ";
      for (const Object& original : tile) {
        Object object = original;
        object.name = prefix + original.name;
        object.T_world_object[3] = glm::vec4(offset, 1.0f);
        // Translations by whole metres move every vertex by exactly the offset's rounding, so
        // the moved box is the box of the moved vertices.
        object.bounds_world.p_min += offset;
        object.bounds_world.p_max += offset;
        city.scene.objects.push_back(std::move(object));
      }
    }
  add_tiles_countryside(city, k, options);
  city.scene.name += ", " + std::to_string(k) + "x" + std::to_string(k) + " tiles";
  return std::move(city.scene);
}

// ---------------------------------------------------------------------------------------------
// Camera path.

namespace {

glm::dvec2 bezier(const glm::dvec2& p0, const glm::dvec2& p1, const glm::dvec2& p2, double t) {
  const double s = 1.0 - t;
  return s * s * p0 + 2.0 * s * t * p1 + t * t * p2;
}

glm::dvec2 bezier_tangent(const glm::dvec2& p0, const glm::dvec2& p1, const glm::dvec2& p2,
                          double t) {
  return 2.0 * (1.0 - t) * (p1 - p0) + 2.0 * t * (p2 - p1);
}

constexpr int arc_samples = 256;

}  // namespace

CityCameraPath::CityCameraPath(const CityOptions& options) {
  (void)options;  // the route uses the streets next to the origin, which every city has
  const double p = pitch;
  // Intersections visited, in order (x, z); the loop closes back to the first. Every leg runs
  // along a street centre line.
  const std::vector<glm::dvec2> corners = {{0, 0}, {0, -p}, {p, -p}, {p, p}, {-p, p}, {-p, 0}};
  const double turn_radius = 6.0;
  const std::size_t n = corners.size();
  auto add = [&](glm::dvec2 a, glm::dvec2 control, glm::dvec2 b) {
    Segment segment{a, control, b, length_m_, 0, {}};
    segment.arc_m.resize(arc_samples + 1);
    glm::dvec2 previous = a;
    double arc = 0;
    for (int i = 0; i <= arc_samples; ++i) {
      const glm::dvec2 q = bezier(a, control, b, static_cast<double>(i) / arc_samples);
      arc += glm::length(q - previous);
      previous = q;
      segment.arc_m[static_cast<std::size_t>(i)] = arc;
    }
    segment.length_m = arc;
    length_m_ += arc;
    segments_.push_back(std::move(segment));
  };
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec2 corner = corners[i];
    const glm::dvec2 next = corners[(i + 1) % n];
    const glm::dvec2 after = corners[(i + 2) % n];
    const glm::dvec2 d_in = glm::normalize(next - corner);
    const glm::dvec2 d_out = glm::normalize(after - next);
    // Straight leg from the end of this corner's curve to the start of the next one's.
    const glm::dvec2 a = corner + d_in * turn_radius, b = next - d_in * turn_radius;
    add(a, 0.5 * (a + b), b);
    add(b, next, next + d_out * turn_radius);
  }
}

glm::dmat4 CityCameraPath::T_world_eye(double time_s) const {
  double s = std::fmod(time_s * speed_m_per_s_, length_m_);
  if (s < 0) s += length_m_;
  const auto it = std::upper_bound(segments_.begin(), segments_.end(), s,
                                   [](double v, const Segment& seg) { return v < seg.start_m; });
  const Segment& seg = *(it == segments_.begin() ? it : it - 1);
  // Invert the arc-length table: find the Bezier parameter at distance s - start along it.
  const double local = std::min(std::max(s - seg.start_m, 0.0), seg.length_m);
  const auto k = std::upper_bound(seg.arc_m.begin(), seg.arc_m.end(), local);
  const auto i =
      static_cast<int>(std::clamp<std::ptrdiff_t>(k - seg.arc_m.begin(), 1, arc_samples));
  const double a0 = seg.arc_m[static_cast<std::size_t>(i - 1)],
               a1 = seg.arc_m[static_cast<std::size_t>(i)];
  const double f = a1 > a0 ? (local - a0) / (a1 - a0) : 0.0;
  const double t = (static_cast<double>(i - 1) + f) / arc_samples;

  const glm::dvec2 q = bezier(seg.p0, seg.p1, seg.p2, t);
  const glm::dvec2 tangent = glm::normalize(bezier_tangent(seg.p0, seg.p1, seg.p2, t));
  const glm::dvec3 forward{tangent.x, 0, tangent.y};
  const glm::dvec3 y_axis{0, 1, 0};
  const glm::dvec3 x_axis = glm::cross(forward, y_axis);  // right of the direction of travel
  glm::dmat4 T_world_eye(1.0);
  T_world_eye[0] = glm::dvec4(x_axis, 0);
  T_world_eye[1] = glm::dvec4(y_axis, 0);
  T_world_eye[2] = glm::dvec4(-forward, 0);  // the eye looks down its -z
  T_world_eye[3] = glm::dvec4(q.x, eye_height_m_, q.y, 1);
  return T_world_eye;
}

}  // namespace facet::driver
