#pragma once
// The built-in test scene: a procedural city like the test model of Lorenz & Döllner's
// "Real-Time Piecewise Perspective Projections" (about 35,000 triangles in 14 material groups,
// with procedural textures), built around the world origin so that a 360° display sees streets
// and buildings in every direction.
//
// World frame: metres, y up, ground at y = 0; streets run along x and z on a 62 m grid through
// the origin, which is the centre of an intersection.
//
// Deterministic: the same options give bit-identical scenes on every machine (a fixed PCG32
// generator and only +, -, *, / and sqrt, compiled without fused multiply-add contraction).
#include <cstdint>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <vector>

#include "facet/driver/scene.hpp"

namespace facet::driver {

struct CityOptions {
  std::uint64_t seed = 2009;  // the paper's year; any value gives a different, valid city
  // Blocks along each side of the origin: the city has (2 * blocks_per_side)^2 blocks.
  int blocks_per_side = 4;
  int texture_size = 128;  // edge of each procedural texture, in texels (a power of two)
};

// The material groups of the city, in Scene::materials order.
enum class CityMaterial : std::uint32_t {
  grass,
  asphalt,
  sidewalk,
  road_marking,
  facade_brick,
  facade_glass,
  facade_concrete,
  facade_plaster,
  facade_stone,
  roof_flat,
  roof_tiles,
  bark,
  foliage,
  metal,
  count
};

// Builds the city. One Object per building, tree, lamp, block and street piece, each with
// identity T_world_object (vertices are in the world frame) and tight world bounds.
// Throws std::invalid_argument when blocks_per_side is not in [1, 16] or texture_size is not a
// power of two in [8, 1024].
Scene build_city(const CityOptions& options = {});

// The city's streets, blocks and buildings (every object but the countryside) as k × k tiles side
// by side, one Object per tile and original object, sharing the original primitives (offset by
// T_world_object only), and one countryside around them all. Tiles repeat every
// city_tile_period_m(options) metres along x and z; the tile at the origin is the original
// city, so CityCameraPath drives through it, and the tiles' avenues line up along x and z, so
// the view down a street sees many tiles. k = 1 is build_city(options) itself.
// Throws std::invalid_argument when k is not in [1, 64] (and as build_city does).
Scene build_city_tiles(int k, const CityOptions& options = {});
// Triangles of build_city_tiles(k, options), counted without building the tiles.
std::uint64_t city_tiles_triangle_count(int k, const CityOptions& options = {});
// Tile period of build_city_tiles: the city's width out to its outer sidewalks, metres.
double city_tile_period_m(const CityOptions& options = {});
// Offset, in tiles, of tile index i in [0, k): i - (k - 1) / 2, so tile (k - 1) / 2 is at the
// origin.
int city_tile_offset(int i, int k);

// A looping drive along the streets around the central blocks at eye height 1.7 m and a
// constant 8 m/s, turning through the intersections on smooth curves.
class CityCameraPath {
 public:
  explicit CityCameraPath(const CityOptions& options = {});
  // Seconds for one loop; pose(t) == pose(t + period_s()).
  double period_s() const { return length_m_ / speed_m_per_s_; }
  // The eye pose at time t (seconds, any real value): T_world_eye maps eye-frame points (x right,
  // y up, looking down -z) into the world. The eye looks along the path; its y axis is world up.
  glm::dmat4 T_world_eye(double time_s) const;

 private:
  struct Segment {
    glm::dvec2 p0, p1, p2;  // quadratic Bezier in the ground plane (x, z); straight if p1 mid
    double start_m = 0, length_m = 0;
    std::vector<double> arc_m;  // arc length at evenly spaced Bezier parameters, for inversion
  };
  std::vector<Segment> segments_;
  double length_m_ = 0;
  double speed_m_per_s_ = 8.0;
  double eye_height_m_ = 1.7;
};

}  // namespace facet::driver
