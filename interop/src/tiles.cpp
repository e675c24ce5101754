#include "facet/interop/tiles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <tuple>

#include "facet/interop/inverse_grid.hpp"
#include "facet/projection/errors.hpp"
#include "json_fields.hpp"

namespace facet::interop {
namespace {

using json_fields::FieldPath;
using json_fields::Fields;
using json_fields::Json;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;
// Grids and vertex lists past these are not tile screens but mistakes.
constexpr int kMaxGridSide = 1025;
constexpr std::size_t kMaxVertices = 1 << 20;
constexpr std::size_t kMaxTriangles = 1 << 21;
// Weights and zooms past this are not meaningful.
constexpr double kMaxFactor = 1e6;
// The lattice of output positions whose directions choose the base: at most this many a side.
constexpr int kMaxLatticeNodes = 257;
// The forward warp grid is refined while a sample misses by more than this, output px.
constexpr double kCheckBoundPx = 0.008;
constexpr int kMaxWarpGrid = 1025;

glm::dvec3 from_angles(double phi_deg, double theta_deg) {
  const double phi = phi_deg * kDeg, theta = theta_deg * kDeg;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

// Divides the angle between d and the view axis −z by `zoom`, keeping the plane through the axis.
glm::dvec3 zoomed(glm::dvec3 d, double zoom) {
  const double alpha = std::acos(std::clamp(-d.z, -1.0, 1.0));
  const double psi = std::atan2(d.y, d.x);
  const double a = alpha / zoom;
  return {std::sin(a) * std::cos(psi), std::sin(a) * std::sin(psi), -std::cos(a)};
}

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Weighted sum of unit directions, normalised; nullopt where it vanishes.
std::optional<glm::dvec3> blend(const glm::dvec3* d, const double* w, int n, glm::dvec3 O) {
  glm::dvec3 sum(0.0);
  for (int k = 0; k < n; ++k) sum += w[k] * d[k];
  const double length = glm::length(sum);
  if (!(length > 1e-9)) return std::nullopt;
  const glm::dvec3 v = sum / length + O;
  const double l2 = glm::length(v);
  if (!(l2 > 1e-9)) return std::nullopt;
  return v / l2;
}

TileFeature read_feature(const Json& value, const FieldPath& at) {
  const std::vector<double> e = json_fields::to_numbers(
      value, at, 4, 6, "[x, y, φ, θ] or [x, y, φ, θ, s, f], finite numbers");
  TileFeature f{e[0], e[1], e[2], e[3], e.size() > 4 ? e[4] : 1.0, e.size() > 5 ? e[5] : 1.0};
  if (!(f.x >= 0 && f.x <= 1 && f.y >= 0 && f.y <= 1)) {
    at.fail("x and y in [0, 1] (normalised output position)", value);
  }
  if (!(std::abs(f.phi_deg) <= 360)) at.fail("φ in [−360, 360] degrees", value);
  if (!(f.theta_deg >= 0 && f.theta_deg <= 180)) at.fail("θ in [0, 180] degrees", value);
  if (!(f.s > 0 && f.s <= kMaxFactor)) at.fail("a zoom s in (0, 1e6]", value);
  if (!(f.f > 0 && f.f <= kMaxFactor)) at.fail("a weight f in (0, 1e6]", value);
  return f;
}

TileLens read_lens(const Json& value, const FieldPath& at) {
  Fields fields(value, at);
  TileLens lens;
  const std::string kind = json_fields::to_string(
      fields.required("kind", "\"fisheye-polynomial\" or \"mixed\""), fields.path("kind"));
  if (kind == "fisheye-polynomial") {
    lens.kind = TileLens::Kind::fisheye_polynomial;
    if (const Json* c = fields.optional("centre")) {
      lens.centre = json_fields::to_dvec2(*c, fields.path("centre"), "[x, y], normalised");
      if (!(glm::all(glm::greaterThanEqual(lens.centre, glm::dvec2(-1))) &&
            glm::all(glm::lessThanEqual(lens.centre, glm::dvec2(2))))) {
        fields.path("centre").fail("[x, y] within [−1, 2]", *c);
      }
    }
    if (const Json* r = fields.optional("radius")) {
      lens.radius = json_fields::to_number(*r, fields.path("radius"));
      if (!(lens.radius >= 0.01 && lens.radius <= 100)) {
        fields.path("radius").fail("a radius in [0.01, 100] output heights", *r);
      }
    }
  } else if (kind == "mixed") {
    lens.kind = TileLens::Kind::mixed;
    if (const Json* v = fields.optional("fov")) {
      lens.fov_deg = json_fields::to_number(*v, fields.path("fov"));
      if (!(lens.fov_deg > 0 && lens.fov_deg <= 300)) {
        fields.path("fov").fail("a horizontal field of view in (0, 300] degrees", *v);
      }
    }
    if (const Json* v = fields.optional("planar")) {
      lens.planar = json_fields::to_number(*v, fields.path("planar"));
      if (!(lens.planar >= 0 && lens.planar <= 1)) {
        fields.path("planar").fail("a planar half-width in [0, 1]", *v);
      }
    }
    if (const Json* v = fields.optional("band")) {
      lens.band = json_fields::to_number(*v, fields.path("band"));
      if (!(lens.band > 0 && lens.band <= 2)) fields.path("band").fail("a band in (0, 2]", *v);
    }
  } else {
    fields.path("kind").fail("\"fisheye-polynomial\" or \"mixed\"", *fields.optional("kind"));
  }
  fields.finish();
  return lens;
}

// Fails unless every pair of the directions lies less than 90° apart.
void check_tile(const std::vector<glm::dvec3>& d, std::initializer_list<int> corners,
                const FieldPath& at) {
  for (int a : corners) {
    for (int b : corners) {
      if (a < b && !(glm::dot(d[std::size_t(a)], d[std::size_t(b)]) > 1e-6)) {
        at.fail("the features of one tile less than 90° apart (features " + std::to_string(a) +
                " and " + std::to_string(b) +
                "; interpolation on the sphere needs them in one "
                "hemisphere): use a finer grid");
      }
    }
  }
}

// Catmull-Rom weights of the features at −1, 0, 1, 2 for t in [0, 1]: they interpolate the
// features and are C1 across tile edges.
glm::dvec4 catmull_rom(double t) {
  const double t2 = t * t, t3 = t2 * t;
  return {(-t3 + 2 * t2 - t) / 2, (3 * t3 - 5 * t2 + 2) / 2, (-3 * t3 + 4 * t2 + t) / 2,
          (t3 - t2) / 2};
}

double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

// Barycentric weights of p in triangle (a, b, c).
glm::dvec3 barycentric(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
  const double area = cross2(b - a, c - a);
  const double wb = cross2(p - a, c - a) / area;
  const double wc = cross2(b - a, p - a) / area;
  return {1 - wb - wc, wb, wc};
}

// Distance from p to triangle (a, b, c) in normalised units scaled by `scale` (0 inside).
double distance_to_triangle(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b, glm::dvec2 c,
                            glm::dvec2 scale) {
  const glm::dvec3 w = barycentric(p, a, b, c);
  if (w.x >= 0 && w.y >= 0 && w.z >= 0) return 0;
  const auto segment = [&](glm::dvec2 u, glm::dvec2 v) {
    const glm::dvec2 us = u * scale, vs = v * scale, ps = p * scale;
    const double t = std::clamp(glm::dot(ps - us, vs - us) / glm::dot(vs - us, vs - us), 0.0, 1.0);
    return glm::length(ps - (us + t * (vs - us)));
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

}  // namespace

double fisheye_lens_theta(double r) {
  const double r2 = r * r;
  return r * (1.411269 + r2 * (-0.094389 + r2 * 0.25674));
}

glm::dvec3 lens_direction(const TileLens& lens, glm::dvec2 xy, double aspect) {
  if (lens.kind == TileLens::Kind::fisheye_polynomial) {
    // Output pixels are square: positions in output heights.
    const glm::dvec2 p{(xy.x - lens.centre.x) * aspect, -(xy.y - lens.centre.y)};
    const double r = glm::length(p) / lens.radius;
    const double theta = fisheye_lens_theta(r);
    const double psi = std::atan2(p.y, p.x);
    return {std::sin(theta) * std::cos(psi), std::sin(theta) * std::sin(psi), -std::cos(theta)};
  }
  const double half = lens.fov_deg * kDeg / 2;
  const double u = 2 * xy.x - 1, v = (1 - 2 * xy.y) / aspect;
  const glm::dvec3 planar = glm::normalize(glm::dvec3(u * half, v * half, -1));
  const double azimuth = u * half;
  const glm::dvec3 cylindrical =
      glm::normalize(glm::dvec3(std::sin(azimuth), v * half, -std::cos(azimuth)));
  const double w = smoothstep((std::abs(u) - lens.planar) / lens.band);
  return glm::normalize((1 - w) * planar + w * cylindrical);
}

glm::dvec3 feature_direction(const TileFeature& feature, double global_zoom) {
  return zoomed(from_angles(feature.phi_deg, feature.theta_deg), feature.s * global_zoom);
}

TileScreen parse_tile_screen(const std::string& text, const std::string& source) {
  const Json json = json_fields::parse(text, source);
  Fields top(json, FieldPath(source));
  TileScreen screen;
  if (const Json* v = top.optional("name")) {
    screen.name = json_fields::to_string(*v, top.path("name"));
  }
  screen.size = json_fields::to_ivec2(top.required("size", "[W, H] in output pixels"),
                                      top.path("size"), "[W, H] in output pixels");
  check_image_size(screen.size, source, "size");
  if (const Json* v = top.optional("zoom")) {
    screen.zoom = json_fields::to_number(*v, top.path("zoom"));
    if (!(screen.zoom >= 1e-3 && screen.zoom <= 1e3)) {
      top.path("zoom").fail("a global zoom in [0.001, 1000]", *v);
    }
  }
  if (const Json* v = top.optional("off_axis")) {
    screen.off_axis = json_fields::to_dvec3(*v, top.path("off_axis"));
    if (!(glm::length(screen.off_axis) < 0.99)) {
      top.path("off_axis").fail("an off-axis vector O shorter than 0.99", *v);
    }
  }
  if (const Json* v = top.optional("lens")) screen.lens = read_lens(*v, top.path("lens"));
  const Json* rpts = top.optional("rpts");
  const Json* tpts = top.optional("tpts");
  if ((rpts == nullptr) == (tpts == nullptr)) {
    top.path("rpts").fail("exactly one of \"rpts\" (a regular grid) and \"tpts\" (triangles)");
  }
  const double aspect = double(screen.size.x) / screen.size.y;
  if (rpts) {
    screen.kind = TileScreen::Kind::rpts;
    Fields fields(*rpts, top.path("rpts"));
    screen.grid = json_fields::to_ivec2(fields.required("grid", "[Gx, Gy] feature counts"),
                                        fields.path("grid"), "[Gx, Gy] feature counts");
    if (screen.grid.x < 2 || screen.grid.y < 2 || screen.grid.x > kMaxGridSide ||
        screen.grid.y > kMaxGridSide) {
      fields.path("grid").fail("[Gx, Gy] with each count in [2, 1025]", *fields.optional("grid"));
    }
    const std::size_t count = std::size_t(screen.grid.x) * screen.grid.y;
    if (const Json* features = fields.optional("features")) {
      const FieldPath at = fields.path("features");
      if (!features->is_array() || features->size() != count) {
        at.fail("a list of Gx·Gy = " + std::to_string(count) + " features, row by row", *features);
      }
      for (std::size_t k = 0; k < count; ++k) {
        screen.features.push_back(read_feature((*features)[k], at[k]));
      }
      // A regular grid: feature (i, j) at (i / (Gx − 1), j / (Gy − 1)).
      for (int j = 0; j < screen.grid.y; ++j) {
        for (int i = 0; i < screen.grid.x; ++i) {
          const std::size_t k = std::size_t(j) * screen.grid.x + i;
          const TileFeature& f = screen.features[k];
          if (!(std::abs(f.x - double(i) / (screen.grid.x - 1)) <= 1e-6 &&
                std::abs(f.y - double(j) / (screen.grid.y - 1)) <= 1e-6)) {
            at[k].fail(
                "feature (i, j) = (" + std::to_string(i) + ", " + std::to_string(j) +
                    ") of the regular grid at x = i / (Gx − 1), y = j / (Gy − 1) within 1e-6",
                (*features)[k]);
          }
        }
      }
    } else if (screen.lens) {
      for (int j = 0; j < screen.grid.y; ++j) {
        for (int i = 0; i < screen.grid.x; ++i) {
          const glm::dvec2 xy{double(i) / (screen.grid.x - 1), double(j) / (screen.grid.y - 1)};
          const glm::dvec3 d = lens_direction(*screen.lens, xy, aspect);
          TileFeature f;
          f.x = xy.x;
          f.y = xy.y;
          f.theta_deg = std::acos(std::clamp(d.y, -1.0, 1.0)) / kDeg;
          f.phi_deg = std::atan2(d.x, -d.z) / kDeg;
          screen.features.push_back(f);
        }
      }
    } else {
      fields.path("features").fail("features, or a \"lens\" to sample them from");
    }
    fields.finish();
  } else {
    screen.kind = TileScreen::Kind::tpts;
    Fields fields(*tpts, top.path("tpts"));
    const FieldPath vat = fields.path("vertices");
    const Json& vertices = fields.required("vertices", "a list of features [x, y, φ, θ, s, f]");
    if (!vertices.is_array() || vertices.size() < 3 || vertices.size() > kMaxVertices) {
      vat.fail("a list of 3 to 2^20 features [x, y, φ, θ, s, f]", vertices);
    }
    for (std::size_t k = 0; k < vertices.size(); ++k) {
      screen.features.push_back(read_feature(vertices[k], vat[k]));
    }
    const FieldPath tat = fields.path("triangles");
    const Json& triangles = fields.required("triangles", "a list of [a, b, c] vertex indices");
    if (!triangles.is_array() || triangles.empty() || triangles.size() > kMaxTriangles) {
      tat.fail("a list of 1 to 2^21 triangles [a, b, c]", triangles);
    }
    for (std::size_t k = 0; k < triangles.size(); ++k) {
      const std::vector<double> t =
          json_fields::to_numbers(triangles[k], tat[k], 3, 3, "[a, b, c] vertex indices");
      std::array<int, 3> tri{};
      for (int c = 0; c < 3; ++c) {
        if (!(t[std::size_t(c)] >= 0 && t[std::size_t(c)] < double(vertices.size()) &&
              t[std::size_t(c)] == std::floor(t[std::size_t(c)]))) {
          tat[k].fail("vertex indices in [0, " + std::to_string(vertices.size() - 1) + "]",
                      triangles[k]);
        }
        tri[std::size_t(c)] = int(t[std::size_t(c)]);
      }
      const auto pos = [&](int c) {
        const TileFeature& f = screen.features[std::size_t(tri[std::size_t(c)])];
        return glm::dvec2(f.x * aspect, f.y);
      };
      if (!(std::abs(cross2(pos(1) - pos(0), pos(2) - pos(0))) > 1e-12)) {
        tat[k].fail("a triangle of non-zero area on the output", triangles[k]);
      }
      screen.triangles.push_back(tri);
    }
    fields.finish();
  }
  top.finish();
  // Zoomed directions stay short of the axis's far end, and tiles within a hemisphere.
  std::vector<glm::dvec3> d;
  d.reserve(screen.features.size());
  const FieldPath fat = screen.kind == TileScreen::Kind::rpts ? top.path("rpts")["features"]
                                                              : top.path("tpts")["vertices"];
  for (std::size_t k = 0; k < screen.features.size(); ++k) {
    const TileFeature& f = screen.features[k];
    const double alpha = std::acos(std::clamp(-from_angles(f.phi_deg, f.theta_deg).z, -1.0, 1.0));
    if (f.s * screen.zoom < 1 && !(alpha / (f.s * screen.zoom) <= 179 * kDeg)) {
      fat[k].fail("a zoomed angle from the view axis of at most 179° (angle / (s × zoom))");
    }
    d.push_back(feature_direction(f, screen.zoom));
  }
  if (screen.kind == TileScreen::Kind::rpts) {
    for (int j = 0; j + 1 < screen.grid.y; ++j) {
      for (int i = 0; i + 1 < screen.grid.x; ++i) {
        const int k = j * screen.grid.x + i;
        std::vector<glm::dvec3> corners{d[std::size_t(k)], d[std::size_t(k + 1)],
                                        d[std::size_t(k + screen.grid.x)],
                                        d[std::size_t(k + screen.grid.x + 1)]};
        check_tile(corners, {0, 1, 2, 3}, fat[std::size_t(k)]);
      }
    }
  } else {
    for (std::size_t k = 0; k < screen.triangles.size(); ++k) {
      const auto& t = screen.triangles[k];
      check_tile({d[std::size_t(t[0])], d[std::size_t(t[1])], d[std::size_t(t[2])]}, {0, 1, 2},
                 top.path("tpts")["triangles"][k]);
    }
  }
  return screen;
}

TileScreen read_tile_screen(const std::filesystem::path& path) {
  const Json json = json_fields::parse_file(path);
  return parse_tile_screen(json.dump(), path.string());
}

std::vector<std::vector<int>> tile_pieces(const TileScreen& screen) {
  if (screen.kind == TileScreen::Kind::rpts) return {{}};
  // Identical vertices are one.
  std::map<std::tuple<double, double, double, double, double, double>, int> first;
  std::vector<int> canonical(screen.features.size());
  for (std::size_t k = 0; k < screen.features.size(); ++k) {
    const TileFeature& f = screen.features[k];
    canonical[k] =
        first.try_emplace({f.x, f.y, f.phi_deg, f.theta_deg, f.s, f.f}, int(k)).first->second;
  }
  const std::size_t n = screen.triangles.size();
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int a) {
    while (parent[std::size_t(a)] != a) {
      a = parent[std::size_t(a)] = parent[std::size_t(parent[std::size_t(a)])];
    }
    return a;
  };
  std::map<std::pair<int, int>, int> edge_owner;
  for (std::size_t t = 0; t < n; ++t) {
    for (int e = 0; e < 3; ++e) {
      int a = canonical[std::size_t(screen.triangles[t][std::size_t(e)])];
      int b = canonical[std::size_t(screen.triangles[t][std::size_t((e + 1) % 3)])];
      if (a > b) std::swap(a, b);
      const auto [it, inserted] = edge_owner.try_emplace({a, b}, int(t));
      if (!inserted) parent[std::size_t(find(int(t)))] = find(it->second);
    }
  }
  std::map<int, std::size_t> piece_of_root;
  std::vector<std::vector<int>> pieces;
  for (std::size_t t = 0; t < n; ++t) {
    const auto [it, inserted] = piece_of_root.try_emplace(find(int(t)), pieces.size());
    if (inserted) pieces.emplace_back();
    pieces[it->second].push_back(int(t));
  }
  return pieces;
}

namespace {

// tile_direction with `dir(k)` giving feature k's direction (feature_direction).
template <class Direction>
std::optional<glm::dvec3> field_direction(const TileScreen& screen,
                                          const std::vector<std::vector<int>>& pieces, int piece,
                                          glm::dvec2 xy, bool continue_past, const Direction& dir) {
  if (screen.kind == TileScreen::Kind::rpts) {
    const int gx = screen.grid.x, gy = screen.grid.y;
    if (!continue_past && (xy.x < 0 || xy.x > 1 || xy.y < 0 || xy.y > 1)) return std::nullopt;
    const auto value = [&](glm::dvec2 p) {
      const double px = p.x * (gx - 1);
      const double py = p.y * (gy - 1);
      const int i = std::clamp(int(std::floor(px)), 0, gx - 2);
      const int j = std::clamp(int(std::floor(py)), 0, gy - 2);
      const glm::dvec4 wx = catmull_rom(px - i), wy = catmull_rom(py - j);
      // A feature's direction; past the grid's edge, continued linearly from the last two.
      const auto at = [&](int a, int b) {
        const auto clamped = [&](int u, int v) {
          return dir(std::size_t(std::clamp(v, 0, gy - 1)) * gx +
                     std::size_t(std::clamp(u, 0, gx - 1)));
        };
        glm::dvec3 d = clamped(a, b);
        if (a < 0) d = 2.0 * clamped(0, b) - clamped(1, b);
        if (a >= gx) d = 2.0 * clamped(gx - 1, b) - clamped(gx - 2, b);
        if (b < 0) d += 2.0 * clamped(a, 0) - clamped(a, 1) - clamped(a, b);
        if (b >= gy) d += 2.0 * clamped(a, gy - 1) - clamped(a, gy - 2) - clamped(a, b);
        return d;
      };
      glm::dvec3 d[16];
      double w[16];
      for (int b = 0; b < 4; ++b) {
        for (int a = 0; a < 4; ++a) {
          const int u = i - 1 + a, v = j - 1 + b;
          d[b * 4 + a] = at(u, v);
          w[b * 4 + a] = wx[a] * wy[b] *
                         screen
                             .features[std::size_t(std::clamp(v, 0, gy - 1)) * gx +
                                       std::size_t(std::clamp(u, 0, gx - 1))]
                             .f;
        }
      }
      return blend(d, w, 16, screen.off_axis);
    };
    const glm::dvec2 c = glm::clamp(xy, glm::dvec2(0.0), glm::dvec2(1.0));
    if (c == xy) return value(xy);
    // Past the grid's edge: the field at the nearest edge point continued to first order (a
    // tile's cubic, continued, may turn back and fold).
    const std::optional<glm::dvec3> at_c = value(c);
    if (!at_c) return std::nullopt;
    glm::dvec3 v = *at_c;
    constexpr double h = 1e-4;
    for (int axis = 0; axis < 2; ++axis) {
      const double out = xy[axis] - c[axis];
      if (out == 0) continue;
      glm::dvec2 inner = c;
      inner[axis] -= std::copysign(h, out);
      const std::optional<glm::dvec3> at_inner = value(inner);
      if (!at_inner) return std::nullopt;
      v += (*at_c - *at_inner) / h * std::abs(out);
    }
    const double length = glm::length(v);
    if (!(length > 1e-9)) return std::nullopt;
    return v / length;
  }
  const double aspect = double(screen.size.x) / screen.size.y;
  const glm::dvec2 scale{aspect, 1.0};
  const auto corner = [&](int t, int c) {
    const TileFeature& f =
        screen.features[std::size_t(screen.triangles[std::size_t(t)][std::size_t(c)])];
    return glm::dvec2(f.x, f.y);
  };
  int best = -1;
  double best_distance = 0;
  for (int t : pieces[std::size_t(piece)]) {
    const double distance =
        distance_to_triangle(xy, corner(t, 0), corner(t, 1), corner(t, 2), scale);
    if (best < 0 || distance < best_distance) {
      best = t;
      best_distance = distance;
      if (distance == 0) break;
    }
  }
  if (best < 0 || (best_distance > 0 && !continue_past)) return std::nullopt;
  const glm::dvec3 bw = barycentric(xy, corner(best, 0), corner(best, 1), corner(best, 2));
  glm::dvec3 d[3];
  double w[3];
  for (int c = 0; c < 3; ++c) {
    const std::size_t k = std::size_t(screen.triangles[std::size_t(best)][std::size_t(c)]);
    d[c] = dir(k);
    w[c] = bw[c] * screen.features[k].f;
  }
  return blend(d, w, 3, screen.off_axis);
}

// The screen's field with every feature's direction computed once, for the warp build, which
// asks for directions millions of times.
class TileField {
 public:
  TileField(const TileScreen& screen, const std::vector<std::vector<int>>& pieces)
      : screen_(screen), pieces_(pieces) {
    directions_.reserve(screen.features.size());
    for (const TileFeature& f : screen.features) {
      directions_.push_back(feature_direction(f, screen.zoom));
    }
  }
  std::optional<glm::dvec3> operator()(int piece, glm::dvec2 xy, bool continue_past) const {
    return field_direction(screen_, pieces_, piece, xy, continue_past,
                           [this](std::size_t k) { return directions_[k]; });
  }

 private:
  const TileScreen& screen_;
  const std::vector<std::vector<int>>& pieces_;
  std::vector<glm::dvec3> directions_;
};

// The normalised output position near `guess` at which the piece shows direction d (unit), by
// Newton's method on the direction's components across d; nullopt where it does not converge.
std::optional<glm::dvec2> solve_position(const TileField& field, int piece, glm::dvec3 d,
                                         glm::dvec2 guess) {
  const glm::dvec3 a = std::abs(d.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 e1 = glm::normalize(glm::cross(d, a));
  const glm::dvec3 e2 = glm::cross(d, e1);
  const auto residual = [&](glm::dvec2 xy) -> std::optional<glm::dvec2> {
    const auto v = field(piece, xy, true);
    if (!v || !(glm::dot(*v, d) > 0)) return std::nullopt;
    return glm::dvec2(glm::dot(*v, e1), glm::dot(*v, e2));
  };
  glm::dvec2 xy = guess;
  constexpr double h = 1e-7;
  for (int iteration = 0; iteration < 40; ++iteration) {
    const auto r = residual(xy);
    if (!r) return std::nullopt;
    if (glm::length(*r) < 1e-14) return xy;
    const auto rx = residual(xy + glm::dvec2(h, 0));
    const auto ry = residual(xy + glm::dvec2(0, h));
    if (!rx || !ry) return std::nullopt;
    const glm::dmat2 J((*rx - *r) / h, (*ry - *r) / h);
    const double det = glm::determinant(J);
    if (!(std::abs(det) > 1e-300)) return std::nullopt;
    glm::dvec2 step = -(glm::inverse(J) * *r);
    const double length = glm::length(step);
    if (length > 0.05) step *= 0.05 / length;
    xy += step;
    if (length < 1e-15) return xy;
  }
  const auto r = residual(xy);
  if (r && glm::length(*r) < 1e-11) return xy;
  return std::nullopt;
}

}  // namespace

std::optional<glm::dvec3> tile_direction(const TileScreen& screen,
                                         const std::vector<std::vector<int>>& pieces, int piece,
                                         glm::dvec2 xy, bool continue_past) {
  return field_direction(screen, pieces, piece, xy, continue_past, [&](std::size_t k) {
    return feature_direction(screen.features[k], screen.zoom);
  });
}

TileDisplay build_tile_display(const TileScreen& screen, glm::ivec2 size,
                               const std::string& source) {
  check_image_size(size, source, "size");
  const double aspect = double(size.x) / size.y;
  if (std::abs(aspect / (double(screen.size.x) / screen.size.y) - 1) > 0.01) {
    throw InputError(source, "size",
                     "an output size with the screen's aspect (" + std::to_string(screen.size.x) +
                         "×" + std::to_string(screen.size.y) + ") within 1%, got " +
                         std::to_string(size.x) + "×" + std::to_string(size.y));
  }
  const std::vector<std::vector<int>> pieces = tile_pieces(screen);
  const TileField field(screen, pieces);
  const bool several = pieces.size() > 1;
  const glm::ivec2 nodes = glm::min(size + 1, glm::ivec2(kMaxLatticeNodes));
  TileDisplay result;
  result.display.name = screen.name.empty() ? "tiles" : screen.name;
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const int piece = int(p);
    const auto node_xy = [&](int i, int j) {
      return glm::dvec2(double(i) / (nodes.x - 1), double(j) / (nodes.y - 1));
    };
    // Directions at the lattice's nodes: inside the piece, and continued two nodes past it.
    const std::size_t count = std::size_t(nodes.x) * nodes.y;
    std::vector<std::optional<glm::dvec3>> v(count);
    std::vector<bool> inside(count, false);
    for (int j = 0; j < nodes.y; ++j) {
      for (int i = 0; i < nodes.x; ++i) {
        const std::size_t k = std::size_t(j) * nodes.x + i;
        v[k] = field(piece, node_xy(i, j), false);
        inside[k] = v[k].has_value();
      }
    }
    if (several) {
      constexpr int kRing = 2;
      for (int j = 0; j < nodes.y; ++j) {
        for (int i = 0; i < nodes.x; ++i) {
          const std::size_t k = std::size_t(j) * nodes.x + i;
          if (inside[k]) continue;
          bool near = false;
          for (int dj = -kRing; dj <= kRing && !near; ++dj) {
            for (int di = -kRing; di <= kRing && !near; ++di) {
              const int a = i + di, b = j + dj;
              near = a >= 0 && b >= 0 && a < nodes.x && b < nodes.y &&
                     inside[std::size_t(b) * nodes.x + a];
            }
          }
          if (near) v[k] = field(piece, node_xy(i, j), true);
        }
      }
    }
    const std::string name =
        sanitize_name(result.display.name) + (several ? "_piece" + std::to_string(p) : "");
    // The base: a fisheye about the mean direction where its reach is under 150°, else an
    // equirectangular base over the directions' azimuths and elevations.
    glm::dvec3 sum(0.0);
    for (const auto& d : v) {
      if (d) sum += *d;
    }
    if (!(glm::length(sum) > 0)) {
      throw InputError(source, "tpts.triangles",
                       "triangles that cover at least one output position (piece " +
                           std::to_string(p) + " covers none at " + std::to_string(size.x) + "×" +
                           std::to_string(size.y) + ")");
    }
    const glm::dvec3 mean = glm::normalize(sum);
    double reach = 0;
    for (const auto& d : v) {
      if (d) reach = std::max(reach, std::acos(std::clamp(glm::dot(*d, mean), -1.0, 1.0)));
    }
    BaseProjection base;
    glm::dmat3 R_eye_base(1.0);
    if (reach < 150 * kDeg) {
      base = BaseProjection::fisheye(std::min(360.0, 2 * (reach / kDeg + 5)));
      const glm::dvec3 z = -mean;
      const glm::dvec3 up = std::abs(mean.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, -1);
      const glm::dvec3 x = glm::normalize(glm::cross(up, z));
      R_eye_base = glm::dmat3(x, glm::cross(z, x), z);
    } else {
      double el_min = 90, el_max = -90;
      const double mean_az = std::atan2(mean.x, -mean.z);
      double rel_min = 180, rel_max = -180;
      for (const auto& d : v) {
        if (!d) continue;
        const double el = std::asin(std::clamp(d->y, -1.0, 1.0)) / kDeg;
        el_min = std::min(el_min, el);
        el_max = std::max(el_max, el);
        if (std::abs(d->y) < 0.999999) {
          double rel = (std::atan2(d->x, -d->z) - mean_az) / kDeg;
          rel = std::remainder(rel, 360.0);
          rel_min = std::min(rel_min, rel);
          rel_max = std::max(rel_max, rel);
        }
      }
      double a0 = 0, a1 = 0;
      if (rel_max - rel_min + 10 < 360) {
        a0 = mean_az / kDeg + rel_min - 5;
        a1 = mean_az / kDeg + rel_max + 5;
      } else {
        // All the way round: the base's seam on the output's left edge.
        const std::optional<glm::dvec3> left = v[std::size_t(nodes.y / 2) * nodes.x];
        const glm::dvec3 l = left ? *left : -mean;
        a0 = std::atan2(l.x, -l.z) / kDeg;
        a1 = a0 + 360;
      }
      base = BaseProjection::equirectangular(a0, a1, std::min(90.0, el_max + 5),
                                             std::max(-90.0, el_min - 5));
    }
    // Initial guesses: the directions on a coarse lattice over the output and past its edges.
    std::vector<std::pair<glm::dvec2, glm::dvec3>> lattice;
    for (int j = 0; j <= 64; ++j) {
      for (int i = 0; i <= 64; ++i) {
        const glm::dvec2 xy{-0.25 + 1.5 * i / 64, -0.25 + 1.5 * j / 64};
        if (auto d = field(piece, xy, true)) lattice.emplace_back(xy, *d);
      }
    }
    const auto inside_piece = [&](glm::dvec2 xy) { return field(piece, xy, false).has_value(); };
    // The solved output positions of a grid's nodes: a finer grid takes the nodes it shares
    // with it as they are and starts its others from them.
    struct Solution {
      glm::ivec2 grid{0, 0};
      std::vector<glm::dvec2> xy;
      std::vector<bool> solved;
    };
    Solution coarse;
    const auto make_warp = [&](glm::ivec2 warp_grid) {
      Warp warp;
      warp.base = base;
      warp.R_eye_base = R_eye_base;
      warp.output_size = size;
      warp.grid_size = warp_grid;
      const std::size_t n = std::size_t(warp_grid.x) * warp_grid.y;
      std::vector<glm::dvec2> xy(n, glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
      std::vector<bool> solved(n, false);
      // Fine nodes per coarse cell, when the coarse grid's nodes are nodes of this one.
      glm::ivec2 ratio{0, 0};
      if (coarse.grid.x > 1 && (warp_grid.x - 1) % (coarse.grid.x - 1) == 0 &&
          (warp_grid.y - 1) % (coarse.grid.y - 1) == 0) {
        ratio = (warp_grid - 1) / (coarse.grid - 1);
      }
      const auto coarse_at = [&](int a, int b) {
        return std::size_t(b) * std::size_t(coarse.grid.x) + std::size_t(a);
      };
      for (int j = 0; j < warp_grid.y; ++j) {
        for (int i = 0; i < warp_grid.x; ++i) {
          const std::size_t k = warp.node_index(i, j);
          if (ratio.x > 0 && i % ratio.x == 0 && j % ratio.y == 0) {
            const std::size_t c = coarse_at(i / ratio.x, j / ratio.y);
            xy[k] = coarse.xy[c];
            solved[k] = coarse.solved[c];
            continue;
          }
          const glm::dvec2 st{double(i) / (warp_grid.x - 1), double(j) / (warp_grid.y - 1)};
          const glm::dvec3 d = R_eye_base * base.direction(st);
          // From the coarse grid's bilinear guess, else a neighbour's solution, else the best
          // lattice point (ties, as on a 360° seam, go to the one nearest st); a solution far
          // from its guess is another branch.
          const auto near = [&](glm::dvec2 guess, double within) -> std::optional<glm::dvec2> {
            const auto found = solve_position(field, piece, d, guess);
            if (found && glm::length(*found - guess) < within) return found;
            return std::nullopt;
          };
          std::optional<glm::dvec2> found;
          // Inside a coarse cell none of whose corners the lattice found, the lattice is not
          // searched again.
          bool search_lattice = true;
          if (ratio.x > 0) {
            const int a = std::min(i / ratio.x, coarse.grid.x - 2);
            const int b = std::min(j / ratio.y, coarse.grid.y - 2);
            const std::size_t c00 = coarse_at(a, b), c10 = coarse_at(a + 1, b),
                              c01 = coarse_at(a, b + 1), c11 = coarse_at(a + 1, b + 1);
            search_lattice = coarse.solved[c00] || coarse.solved[c10] || coarse.solved[c01] ||
                             coarse.solved[c11];
            if (coarse.solved[c00] && coarse.solved[c10] && coarse.solved[c01] &&
                coarse.solved[c11]) {
              const double fx = double(i - a * ratio.x) / ratio.x;
              const double fy = double(j - b * ratio.y) / ratio.y;
              const glm::dvec2 guess =
                  (coarse.xy[c00] * (1 - fx) + coarse.xy[c10] * fx) * (1 - fy) +
                  (coarse.xy[c01] * (1 - fx) + coarse.xy[c11] * fx) * fy;
              found = near(guess, 0.1);
            }
          }
          if (!found && i > 0 && solved[k - 1]) found = near(xy[k - 1], 0.1);
          if (!found && j > 0 && solved[k - std::size_t(warp_grid.x)]) {
            found = near(xy[k - std::size_t(warp_grid.x)], 0.1);
          }
          if (!found && search_lattice) {
            double best = -2;
            glm::dvec2 guess(0.5);
            for (const auto& [g, dg] : lattice) {
              const double score = glm::dot(dg, d) - 1e-4 * glm::dot(g - st, g - st);
              if (score > best) best = score, guess = g;
            }
            if (best > 0.9) found = near(guess, 0.1);
          }
          if (found && glm::all(glm::greaterThan(*found, glm::dvec2(-0.25))) &&
              glm::all(glm::lessThan(*found, glm::dvec2(1.25)))) {
            xy[k] = *found;
            solved[k] = true;
          }
        }
      }
      std::vector<glm::dvec2> offsets(n, glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
      for (int j = 0; j < warp_grid.y; ++j) {
        for (int i = 0; i < warp_grid.x; ++i) {
          const std::size_t k = warp.node_index(i, j);
          const glm::dvec2 st{double(i) / (warp_grid.x - 1), double(j) / (warp_grid.y - 1)};
          if (solved[k]) offsets[k] = (xy[k] - st) * glm::dvec2(size);
        }
      }
      fill_missing(offsets, warp_grid, source);
      // Covered: a node inside the piece, or next to one (its cell reaches into the piece).
      std::vector<bool> in(n, false);
      for (std::size_t k = 0; k < n; ++k) in[k] = solved[k] && inside_piece(xy[k]);
      warp.offset_px.resize(n);
      warp.coverage.resize(n);
      for (int j = 0; j < warp_grid.y; ++j) {
        for (int i = 0; i < warp_grid.x; ++i) {
          const std::size_t k = warp.node_index(i, j);
          bool covered = in[k];
          for (int dj = -1; dj <= 1 && !covered && solved[k]; ++dj) {
            for (int di = -1; di <= 1 && !covered; ++di) {
              const int a = i + di, b = j + dj;
              covered = a >= 0 && b >= 0 && a < warp_grid.x && b < warp_grid.y &&
                        in[warp.node_index(a, b)];
            }
          }
          warp.offset_px[k] = glm::vec2(offsets[k]);
          warp.coverage[k] = covered ? 1.0f : 0.0f;
        }
      }
      warp.validate(source);
      coarse = {warp_grid, std::move(xy), std::move(solved)};
      return warp;
    };
    // Samples at pixel centres inside the piece, about 160 a side.
    const int step = std::max(1, std::max(size.x, size.y) / 160);
    std::vector<std::pair<glm::dvec2, glm::dvec3>> samples;
    for (int y = 0; y < size.y; y += step) {
      for (int x = 0; x < size.x; x += step) {
        const glm::dvec2 q{x + 0.5, y + 0.5};
        if (auto d = field(piece, q / glm::dvec2(size), false)) {
          samples.emplace_back(q, *d);
        }
      }
    }
    const auto worst_of = [&](const Warp& warp) {
      double worst = 0;
      for (const auto& [q, d] : samples) {
        const auto projected = warp.project(d, q.x / size.x);
        worst = std::max(worst, projected ? glm::length(projected->q - q)
                                          : std::numeric_limits<double>::infinity());
      }
      return worst;
    };
    ImportedProjector projector;
    projector.name = name;
    glm::ivec2 warp_grid{129, 129};
    double worst = 0;
    for (;;) {
      projector.warp = make_warp(warp_grid);
      worst = worst_of(projector.warp);
      // A bilinear cell's error goes with the square of its side where the field is smooth: the
      // grid is made 2, 4 or 8 times finer, as that predicts the bound needs (a kink of a TPTS
      // converges more slowly, and takes another step).
      int factor = 2;
      while (factor < 8 && worst / (factor * factor) > kCheckBoundPx) factor *= 2;
      const glm::ivec2 finer = glm::min(factor * (warp_grid - 1) + 1, glm::ivec2(kMaxWarpGrid));
      if (worst <= kCheckBoundPx || finer == warp_grid) break;
      warp_grid = finer;
    }
    char note[200];
    std::snprintf(note, sizeof note,
                  "%s: %s base, warp grid %d×%d; the screen's directions at %zu pixel centres "
                  "land within %.4f px of them",
                  name.c_str(), to_string(base.kind).c_str(), warp_grid.x, warp_grid.y,
                  samples.size(), worst);
    projector.notes.push_back(note);
    if (several) {
      projection_io::BlendMap alpha = projection_io::BlendMap::constant(size, 0.0f);
      for (int y = 0; y < size.y; ++y) {
        for (int x = 0; x < size.x; ++x) {
          const glm::dvec2 xy{(x + 0.5) / size.x, (y + 0.5) / size.y};
          if (field(piece, xy, false)) alpha.at(x, y) = 1.0f;
        }
      }
      projector.blend = std::move(alpha);
    }
    projector.output.kind = projection_io::DisplayOutput::Kind::window;
    projector.output.window = {0, 0, size.x, size.y};
    result.worst_check_px.push_back(worst);
    result.checked_samples.push_back(int(samples.size()));
    result.display.projectors.push_back(std::move(projector));
  }
  return result;
}

}  // namespace facet::interop
