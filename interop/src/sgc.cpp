// SCISS .sgc warp meshes: parse, and import as a facet warp.
#include "facet/interop/sgc.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <pugixml.hpp>
#include <sstream>

#include "facet/interop/inverse_grid.hpp"
#include "facet/projection/errors.hpp"
#include "xml_document.hpp"

namespace facet::interop {
namespace {

constexpr std::uint32_t kMaxCount = 1u << 24;
constexpr int kMaxAutoGrid = 1025;

class Reader {
 public:
  Reader(std::string_view bytes, const std::string& source) : bytes_(bytes), source_(source) {}

  template <typename T>
  T read(const char* field) {
    T value;
    if (bytes_.size() - offset_ < sizeof(T)) {
      throw InputError(source_, field,
                       "expected " + std::to_string(sizeof(T)) + " more bytes at offset " +
                           std::to_string(offset_) + " (the file is truncated)");
    }
    std::memcpy(&value, bytes_.data() + offset_, sizeof(T));  // the files are little-endian
    offset_ += sizeof(T);
    return value;
  }
  std::size_t remaining() const { return bytes_.size() - offset_; }

 private:
  std::string_view bytes_;
  const std::string& source_;
  std::size_t offset_ = 0;
};

double cross(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

// Point location among the mesh's triangles in one of its two spaces (output or texture).
class TriangleLocator {
 public:
  TriangleLocator(const SgcMesh& mesh, const std::vector<bool>& proper, bool in_output)
      : mesh_(mesh), in_output_(in_output) {
    lo_ = glm::dvec2(std::numeric_limits<double>::max());
    hi_ = -lo_;
    for (const SgcVertex& v : mesh.vertices) lo_ = glm::min(lo_, at(v)), hi_ = glm::max(hi_, at(v));
    const int n = std::clamp(int(std::sqrt(double(mesh.triangles.size()) / 2)), 1, 512);
    buckets_ = {n, n};
    cells_.resize(std::size_t(n) * n);
    for (std::uint32_t k = 0; k < mesh.triangles.size(); ++k) {
      if (!proper[k]) continue;
      const glm::uvec3 t = mesh.triangles[k];
      const glm::dvec2 a = point(t.x), b = point(t.y), c = point(t.z);
      const glm::ivec2 b0 = bucket(glm::min(a, glm::min(b, c)));
      const glm::ivec2 b1 = bucket(glm::max(a, glm::max(b, c)));
      for (int j = b0.y; j <= b1.y; ++j) {
        for (int i = b0.x; i <= b1.x; ++i) cells_[std::size_t(j) * n + i].push_back(k);
      }
    }
  }

  // The other space's position at p, interpolated in the triangle holding p (its edges
  // included, with a relative slack of 1e-9); nullopt outside every triangle.
  std::optional<glm::dvec2> map(glm::dvec2 p) const {
    if (p.x < lo_.x || p.y < lo_.y || p.x > hi_.x || p.y > hi_.y) return std::nullopt;
    const glm::ivec2 b = bucket(p);
    for (std::uint32_t k : cells_[std::size_t(b.y) * buckets_.x + b.x]) {
      const glm::dvec3 w = barycentric(k, p);
      constexpr double slack = -1e-9;
      if (w.x < slack || w.y < slack || w.z < slack) continue;
      return interpolate(k, w);
    }
    return std::nullopt;
  }

  // Outside every triangle: the affine map of the triangle whose centroid is nearest p, among
  // those in the nearest ring of buckets that holds any (and the ring after it); nullopt for a
  // mesh without proper triangles.
  std::optional<glm::dvec2> extrapolate(glm::dvec2 p) const {
    const glm::ivec2 b = bucket(p);
    std::optional<std::uint32_t> nearest;
    double nearest_d2 = std::numeric_limits<double>::max();
    int last_ring = std::max(buckets_.x, buckets_.y);
    for (int ring = 0; ring <= last_ring; ++ring) {
      for (int j = b.y - ring; j <= b.y + ring; ++j) {
        for (int i = b.x - ring; i <= b.x + ring; ++i) {
          if (std::max(std::abs(i - b.x), std::abs(j - b.y)) != ring) continue;
          if (i < 0 || j < 0 || i >= buckets_.x || j >= buckets_.y) continue;
          for (std::uint32_t k : cells_[std::size_t(j) * buckets_.x + i]) {
            const glm::uvec3 t = mesh_.triangles[k];
            const glm::dvec2 d = (point(t.x) + point(t.y) + point(t.z)) / 3.0 - p;
            if (glm::dot(d, d) < nearest_d2) nearest_d2 = glm::dot(d, d), nearest = k;
          }
        }
      }
      if (nearest && last_ring > ring + 1) last_ring = ring + 1;
    }
    if (!nearest) return std::nullopt;
    return interpolate(*nearest, barycentric(*nearest, p));
  }

 private:
  // Barycentric coordinates of p in triangle k of this space (any sign: outside it too).
  glm::dvec3 barycentric(std::uint32_t k, glm::dvec2 p) const {
    const glm::uvec3 t = mesh_.triangles[k];
    const glm::dvec2 a = point(t.x), e1 = point(t.y) - a, e2 = point(t.z) - a;
    const double area = cross(e1, e2);
    const double w1 = cross(p - a, e2) / area, w2 = cross(e1, p - a) / area;
    return {1 - w1 - w2, w1, w2};
  }
  // The other space's position at barycentric coordinates w of triangle k.
  glm::dvec2 interpolate(std::uint32_t k, glm::dvec3 w) const {
    const glm::uvec3 t = mesh_.triangles[k];
    return w.x * other(t.x) + w.y * other(t.y) + w.z * other(t.z);
  }
  glm::dvec2 at(const SgcVertex& v) const { return in_output_ ? v.q_norm : v.st; }
  glm::dvec2 point(std::uint32_t i) const { return at(mesh_.vertices[i]); }
  glm::dvec2 other(std::uint32_t i) const {
    return in_output_ ? mesh_.vertices[i].st : mesh_.vertices[i].q_norm;
  }
  glm::ivec2 bucket(glm::dvec2 p) const {
    const glm::dvec2 extent = glm::max(hi_ - lo_, glm::dvec2(1e-300));
    const glm::dvec2 f = glm::clamp((p - lo_) / extent * glm::dvec2(buckets_), glm::dvec2(0.0),
                                    glm::dvec2(buckets_ - 1));
    return glm::ivec2(f);
  }

  const SgcMesh& mesh_;
  bool in_output_;
  glm::dvec2 lo_, hi_;
  glm::ivec2 buckets_;
  std::vector<std::vector<std::uint32_t>> cells_;
};

// The node counts of a regular grid over [0,1]² that the vertices' positions in one space form,
// each node taken exactly once; nullopt when they form none.
std::optional<glm::ivec2> regular_grid(const SgcMesh& mesh, bool in_output) {
  const auto at = [&](const SgcVertex& v) { return in_output ? v.q_norm : v.st; };
  std::map<long long, int> xs, ys;
  for (const SgcVertex& v : mesh.vertices) {
    ++xs[std::llround(at(v).x * 1e6)];
    ++ys[std::llround(at(v).y * 1e6)];
  }
  const int nx = int(xs.size()), ny = int(ys.size());
  if (nx < 2 || ny < 2 || std::size_t(nx) * ny != mesh.vertices.size()) return std::nullopt;
  std::vector<bool> taken(mesh.vertices.size(), false);
  for (const SgcVertex& v : mesh.vertices) {
    const glm::dvec2 g = at(v) * glm::dvec2(nx - 1, ny - 1);
    const glm::ivec2 node(glm::round(g));
    if (node.x < 0 || node.y < 0 || node.x >= nx || node.y >= ny ||
        glm::length(g - glm::dvec2(node)) > 1e-3) {
      return std::nullopt;
    }
    const std::size_t k = std::size_t(node.y) * nx + node.x;
    if (taken[k]) return std::nullopt;
    taken[k] = true;
  }
  return glm::ivec2(nx, ny);
}

// Triangles with area in both spaces: at least a millionth of the median in each. The others
// are the joins and turns of triangle strips (zero area in one space), which draw nothing or
// a sliver along the mesh's edge.
std::vector<bool> proper_triangles(const SgcMesh& mesh) {
  std::vector<double> q_areas, st_areas;
  for (const glm::uvec3& t : mesh.triangles) {
    const SgcVertex &a = mesh.vertices[t.x], &b = mesh.vertices[t.y], &c = mesh.vertices[t.z];
    q_areas.push_back(std::abs(cross(b.q_norm - a.q_norm, c.q_norm - a.q_norm)));
    st_areas.push_back(std::abs(cross(b.st - a.st, c.st - a.st)));
  }
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const double q_min = 1e-6 * median(q_areas), st_min = 1e-6 * median(st_areas);
  std::vector<bool> proper(mesh.triangles.size());
  for (std::size_t k = 0; k < proper.size(); ++k) {
    proper[k] = q_areas[k] > q_min && st_areas[k] > st_min;
  }
  return proper;
}

// The first proper triangle whose map from texture to output turns the other way from the
// majority's.
std::optional<std::uint32_t> first_folded_triangle(const SgcMesh& mesh,
                                                   const std::vector<bool>& proper) {
  int positive = 0, negative = 0;
  std::vector<int> sign(mesh.triangles.size(), 0);
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    if (!proper[k]) continue;
    const glm::uvec3 t = mesh.triangles[k];
    const SgcVertex &a = mesh.vertices[t.x], &b = mesh.vertices[t.y], &c = mesh.vertices[t.z];
    const double map_orientation =
        cross(b.q_norm - a.q_norm, c.q_norm - a.q_norm) * cross(b.st - a.st, c.st - a.st);
    sign[k] = map_orientation > 0 ? 1 : -1;
    (sign[k] > 0 ? positive : negative)++;
  }
  const int majority = positive >= negative ? 1 : -1;
  for (std::size_t k = 0; k < sign.size(); ++k) {
    if (sign[k] == -majority) return std::uint32_t(k);
  }
  return std::nullopt;
}

double worst_follow_px(const SgcMesh& mesh, const std::vector<bool>& proper, const Warp& warp) {
  const glm::dvec2 size(warp.output_size);
  double worst = 0;
  const auto check = [&](glm::dvec2 st, glm::dvec2 q_norm) {
    if (st.x < 0 || st.y < 0 || st.x > 1 || st.y > 1) return;
    worst = std::max(worst, glm::length(warp.q_from_st(st) - q_norm * size));
  };
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    if (!proper[k]) continue;
    const glm::uvec3 t = mesh.triangles[k];
    const SgcVertex &a = mesh.vertices[t.x], &b = mesh.vertices[t.y], &c = mesh.vertices[t.z];
    // A barycentric lattice of sevenths: none of its points but the corners falls on a node of
    // a grid refined by doubling, where the warp would agree by construction.
    for (int i = 0; i <= 7; ++i) {
      for (int j = 0; i + j <= 7; ++j) {
        const double u = i / 7.0, v = j / 7.0, w = 1 - u - v;
        check(w * a.st + u * b.st + v * c.st, w * a.q_norm + u * b.q_norm + v * c.q_norm);
      }
    }
  }
  return worst;
}

// A forward warp sampled from the triangulation at the nodes of `grid`. Nodes outside every
// triangle are uncovered and continue the nearest triangle's affine map, so that a bilinear cell
// that is partly inside the mesh still follows it there.
Warp forward_warp(const SgcMesh& mesh, const TriangleLocator& in_texture, glm::ivec2 grid,
                  glm::ivec2 output_size, const std::string& source) {
  Warp warp = Warp::analytic(sgc_frustum_base(mesh), output_size, grid, sgc_R_eye_frustum(mesh));
  const glm::dvec2 size(output_size);
  for (int j = 0; j < grid.y; ++j) {
    for (int i = 0; i < grid.x; ++i) {
      const glm::dvec2 st{double(i) / (grid.x - 1), double(j) / (grid.y - 1)};
      std::optional<glm::dvec2> q_norm = in_texture.map(st);
      warp.coverage[warp.node_index(i, j)] = q_norm ? 1.0f : 0.0f;
      if (!q_norm) q_norm = in_texture.extrapolate(st);
      if (!q_norm) throw InputError(source, "mesh", "expected triangles with area");
      warp.offset_px[warp.node_index(i, j)] = glm::vec2((*q_norm - st) * size);
    }
  }
  return warp;
}

Warp warp_through_inverse(const SgcMesh& mesh, const TriangleLocator& in_output, glm::ivec2 grid,
                          glm::ivec2 output_size, const std::string& source) {
  InverseGrid inverse;
  inverse.grid_size = grid;
  inverse.st.resize(std::size_t(grid.x) * grid.y);
  for (int j = 0; j < grid.y; ++j) {
    for (int i = 0; i < grid.x; ++i) {
      const std::optional<glm::dvec2> st =
          in_output.map({double(i) / (grid.x - 1), double(j) / (grid.y - 1)});
      inverse.st[std::size_t(j) * grid.x + i] =
          st ? *st : glm::dvec2(std::numeric_limits<double>::quiet_NaN());
    }
  }
  return warp_from_inverse_grid(inverse, sgc_frustum_base(mesh), sgc_R_eye_frustum(mesh),
                                output_size, grid, source);
}

}  // namespace

SgcMesh parse_sgc(std::string_view bytes, const std::string& source) {
  Reader in(bytes, source);
  char magic[3];
  for (char& c : magic) c = in.read<char>("magic");
  if (std::string_view(magic, 3) != "SGC") {
    throw InputError(source, "magic", "expected the file to start with \"SGC\"");
  }
  SgcMesh mesh;
  mesh.version = in.read<std::uint8_t>("version");
  if (mesh.version != 1 && mesh.version != 2) {
    throw InputError(source, "version",
                     "expected version 1 or 2, got " + std::to_string(mesh.version));
  }
  const auto mapping = in.read<std::uint32_t>("mapping type");
  if (mapping != 0) {
    throw InputError(source, "mapping type",
                     "expected 0 (planar); got " + std::to_string(mapping) +
                         (mapping == 1 ? " (cube), which facet does not read" : ""));
  }
  float view[11];
  const char* view_fields[11] = {"quaternion x", "quaternion y", "quaternion z", "quaternion w",
                                 "position x",   "position y",   "position z",   "fov up",
                                 "fov down",     "fov left",     "fov right"};
  for (int k = 0; k < 11; ++k) {
    view[k] = in.read<float>(view_fields[k]);
    if (!std::isfinite(view[k])) throw InputError(source, view_fields[k], "expected a number");
  }
  const glm::dquat q(view[3], view[0], view[1], view[2]);
  const double q_length = glm::length(q);
  if (!(q_length > 0.5 && q_length < 2)) {
    throw InputError(source, "quaternion", "expected a unit rotation quaternion (x, y, z, w)");
  }
  mesh.q_world_frustum = q / q_length;
  mesh.position = {view[4], view[5], view[6]};
  mesh.up_deg = view[7], mesh.down_deg = view[8], mesh.left_deg = view[9],
  mesh.right_deg = view[10];
  for (auto [angle, field] : {std::pair{mesh.up_deg, "fov up"},
                              {mesh.down_deg, "fov down"},
                              {mesh.left_deg, "fov left"},
                              {mesh.right_deg, "fov right"}}) {
    if (!(std::abs(angle) < 89)) {
      throw InputError(source, field, "expected an edge angle within (−89°, 89°)");
    }
  }
  if (!(mesh.down_deg < mesh.up_deg)) {
    throw InputError(source, "fov down", "expected the bottom edge below the top edge (fov up)");
  }
  if (!(mesh.left_deg < mesh.right_deg)) {
    throw InputError(source, "fov left", "expected the left edge left of the right edge");
  }
  const auto size0 = in.read<std::uint32_t>("size"), size1 = in.read<std::uint32_t>("size");
  std::uint64_t vertex_count = mesh.version == 2 ? size1 : std::uint64_t(size0) * size1;
  if (vertex_count < 3 || vertex_count > kMaxCount) {
    throw InputError(source, mesh.version == 2 ? "vertex count" : "nx ny",
                     "expected between 3 and 2^24 vertices, got " + std::to_string(vertex_count));
  }
  if (in.remaining() < vertex_count * 24) {
    throw InputError(source, "vertices",
                     "expected " + std::to_string(vertex_count) +
                         " vertices of 24 bytes (the file is truncated)");
  }
  mesh.vertices.resize(vertex_count);
  for (std::uint64_t k = 0; k < vertex_count; ++k) {
    float v[6];
    for (float& f : v) f = in.read<float>("vertices");
    // Real meshes stay within a few percent of [0,1]; the bound keeps areas finite.
    if (!(std::abs(v[0]) <= 100 && std::abs(v[1]) <= 100 && std::abs(v[3]) <= 100 &&
          std::abs(v[4]) <= 100)) {
      throw InputError(source, "vertex " + std::to_string(k),
                       "expected finite x y tx ty within ±100 (normalised positions)");
    }
    mesh.vertices[k].q_norm = {v[0], v[1]};
    mesh.vertices[k].st = {v[3], 1.0 - double(v[4])};
  }
  const auto index_count = in.read<std::uint32_t>("index count");
  if (index_count > kMaxCount || in.remaining() != std::size_t(index_count) * 4) {
    throw InputError(source, "index count",
                     std::to_string(index_count) + " indices, but " +
                         std::to_string(in.remaining()) +
                         " bytes follow; expected the file to end with the indices");
  }
  std::vector<std::uint32_t> indices(index_count);
  for (std::uint32_t& index : indices) {
    index = in.read<std::uint32_t>("indices");
    if (index >= vertex_count) {
      throw InputError(source, "indices",
                       "expected indices below the vertex count " + std::to_string(vertex_count) +
                           ", got " + std::to_string(index));
    }
  }
  const bool triangle_list = mesh.version == 2 && size0 == 4;
  const auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (a != b && b != c && a != c) mesh.triangles.emplace_back(a, b, c);
  };
  if (triangle_list) {
    if (index_count % 3 != 0) {
      throw InputError(source, "index count", "expected a multiple of 3 for a triangle list");
    }
    for (std::uint32_t k = 0; k < index_count; k += 3)
      add(indices[k], indices[k + 1], indices[k + 2]);
  } else {
    for (std::uint32_t k = 0; k + 2 < index_count; ++k) {
      add(indices[k], indices[k + 1], indices[k + 2]);
    }
  }
  if (mesh.triangles.empty()) {
    throw InputError(source, "indices", "expected at least one non-degenerate triangle");
  }
  return mesh;
}

SgcMesh parse_simcad(std::string_view xml, const SgcMesh& frustum, const std::string& source) {
  pugi::xml_document document;
  load_xml(document, xml, source);
  const pugi::xml_node definition = document.child("GeometryFile").child("GeometryDefinition");
  if (!definition) {
    throw InputError(source, "GeometryFile/GeometryDefinition", "expected this element");
  }
  struct Axis {
    double range = 0;
    std::vector<double> values;
  };
  const auto read_axis = [&](const char* name) {
    const std::string field = std::string("GeometryFile/GeometryDefinition/") + name;
    const pugi::xml_node node = definition.child(name);
    if (!node) throw InputError(source, field, "expected this element");
    Axis axis;
    axis.range = node.attribute("range").as_double(0);
    if (!(axis.range > 0 && std::isfinite(axis.range))) {
      throw InputError(source, field + "@range", "expected a positive number of pixels");
    }
    std::istringstream numbers(node.text().get());
    std::string token;
    while (numbers >> token) {
      const double value = parse_number(token, source, field);
      if (std::abs(value) > 100 * axis.range) {
        throw InputError(source, field,
                         "expected pixel offsets within 100 ranges, found " + token.substr(0, 40));
      }
      axis.values.push_back(value);
      if (axis.values.size() > kMaxCount) {
        throw InputError(source, field, "expected at most 2^24 numbers");
      }
    }
    return axis;
  };
  const Axis x = read_axis("X-FlatParameters"), y = read_axis("Y-FlatParameters");
  const int n = int(std::lround(std::sqrt(double(x.values.size()))));
  if (x.values.size() != y.values.size() || n < 2 || std::size_t(n) * n != x.values.size()) {
    throw InputError(source, "GeometryFile/GeometryDefinition",
                     "expected the same square count n² (n >= 2) of X and Y offsets; got " +
                         std::to_string(x.values.size()) + " and " +
                         std::to_string(y.values.size()));
  }
  SgcMesh mesh = frustum;
  mesh.version = 0;
  mesh.bilinear_grid = true;
  mesh.vertices.assign(x.values.size(), {});
  mesh.triangles.clear();
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      const std::size_t k = std::size_t(r) * n + c;
      const glm::dvec2 st{double(c) / (n - 1), double(r) / (n - 1)};
      mesh.vertices[k].st = st;
      mesh.vertices[k].q_norm = st + glm::dvec2(x.values[k] / x.range, y.values[k] / y.range);
      if (r + 1 < n && c + 1 < n) {
        const auto at = [&](int dc, int dr) { return std::uint32_t((r + dr) * n + c + dc); };
        mesh.triangles.emplace_back(at(0, 0), at(1, 0), at(0, 1));
        mesh.triangles.emplace_back(at(1, 0), at(1, 1), at(0, 1));
      }
    }
  }
  return mesh;
}

std::string format_sgc(const SgcMesh& mesh, glm::ivec2 grid) {
  FACET_ASSERT(grid.x >= 2 && grid.y >= 2);
  FACET_ASSERT(mesh.vertices.size() == std::size_t(grid.x) * grid.y);
  std::string bytes = "SGC";
  const auto put = [&](auto value) {
    char raw[sizeof value];
    std::memcpy(raw, &value, sizeof value);
    bytes.append(raw, sizeof value);
  };
  put(std::uint8_t(1));
  put(std::uint32_t(0));
  const glm::dquat& q = mesh.q_world_frustum;
  for (double v : {q.x, q.y, q.z, q.w, mesh.position.x, mesh.position.y, mesh.position.z,
                   mesh.up_deg, mesh.down_deg, mesh.left_deg, mesh.right_deg}) {
    put(float(v));
  }
  put(std::uint32_t(grid.x));
  put(std::uint32_t(grid.y));
  for (const SgcVertex& v : mesh.vertices) {
    for (double f : {v.q_norm.x, v.q_norm.y, 0.0, v.st.x, 1 - v.st.y, 0.0}) put(float(f));
  }
  // Row pairs alternately rightwards and leftwards: each row starts with the index the previous
  // one ended with, which joins them by degenerate triangles.
  std::vector<std::uint32_t> strip;
  for (int r = 0; r + 1 < grid.y; ++r) {
    const bool rightwards = r % 2 == 0;
    for (int k = 0; k < grid.x; ++k) {
      const int c = rightwards ? k : grid.x - 1 - k;
      strip.push_back(std::uint32_t(r * grid.x + c));
      strip.push_back(std::uint32_t((r + 1) * grid.x + c));
    }
  }
  put(std::uint32_t(strip.size()));
  for (std::uint32_t index : strip) put(index);
  return bytes;
}

BaseProjection sgc_frustum_base(const SgcMesh& mesh) {
  const auto tan_deg = [](double a) { return std::tan(a * M_PI / 180); };
  return BaseProjection::perspective(tan_deg(mesh.left_deg), tan_deg(mesh.right_deg),
                                     tan_deg(mesh.up_deg), tan_deg(mesh.down_deg));
}

glm::dmat3 sgc_R_eye_frustum(const SgcMesh& mesh) { return glm::mat3_cast(mesh.q_world_frustum); }

SgcImport import_sgc(const SgcMesh& mesh, const SgcImportOptions& options,
                     const std::string& source, const std::string& name) {
  FACET_ASSERT(options.output_size.x > 0 && options.output_size.y > 0);
  const std::vector<bool> proper = proper_triangles(mesh);
  if (std::find(proper.begin(), proper.end(), true) == proper.end()) {
    throw InputError(source, "mesh", "expected triangles with area in the output and the image");
  }
  if (const auto folded = first_folded_triangle(mesh, proper)) {
    const glm::uvec3 t = mesh.triangles[*folded];
    const glm::dvec2 q = mesh.vertices[t.x].q_norm * glm::dvec2(options.output_size);
    char text[200];
    std::snprintf(text, sizeof text,
                  "expected a mesh without folds; triangle %u (vertices %u, %u, %u, near output "
                  "pixel (%.0f, %.0f)) is turned over relative to the others",
                  *folded, t.x, t.y, t.z, q.x, q.y);
    throw InputError(source, "mesh", text);
  }
  SgcImport result;
  std::optional<glm::ivec2> mesh_grid;
  if ((mesh_grid = regular_grid(mesh, false))) {
    result.side = SgcGridSide::texture;
  } else if ((mesh_grid = regular_grid(mesh, true))) {
    result.side = SgcGridSide::output;
  } else {
    result.side = SgcGridSide::neither;
    mesh_grid = options.output_size / 8 + 1;
  }
  const TriangleLocator locator(mesh, proper, result.side != SgcGridSide::texture);
  const auto build = [&](glm::ivec2 grid) {
    return result.side == SgcGridSide::texture
               ? forward_warp(mesh, locator, grid, options.output_size, source)
               : warp_through_inverse(mesh, locator, grid, options.output_size, source);
  };
  ImportedProjector& projector = result.projector;
  projector.name = name;
  projector.output.kind = projection_io::DisplayOutput::Kind::window;
  projector.output.window = {0, 0, options.output_size.x, options.output_size.y};
  char text[240];
  if (mesh.bilinear_grid && result.side == SgcGridSide::texture) {
    projector.warp = build(*mesh_grid);
    projector.warp.validate(source);
    std::snprintf(text, sizeof text, "a %d×%d node grid over the frustum image, taken as it is",
                  mesh_grid->x, mesh_grid->y);
    projector.notes.push_back(text);
    return result;
  }
  glm::ivec2 grid = options.warp_grid.x >= 2 ? options.warp_grid : *mesh_grid;
  for (;;) {
    projector.warp = build(grid);
    result.worst_follow_px = worst_follow_px(mesh, proper, projector.warp);
    const glm::ivec2 finer = glm::min(2 * (grid - 1) + 1, glm::ivec2(kMaxAutoGrid));
    if (options.warp_grid.x >= 2 || result.worst_follow_px <= options.follow_bound_px ||
        finer == grid) {
      break;
    }
    grid = finer;
  }
  projector.warp.validate(source);
  std::snprintf(text, sizeof text,
                "%zu vertices, regular over the %s; warp grid %d×%d follows the mesh within "
                "%.3f px (worst over a lattice of sevenths in every triangle)",
                mesh.vertices.size(),
                result.side == SgcGridSide::texture  ? "frustum image"
                : result.side == SgcGridSide::output ? "output"
                                                     : "neither (sampled every 8 px)",
                grid.x, grid.y, result.worst_follow_px);
  projector.notes.push_back(text);
  if (mesh.position != glm::dvec3(0.0)) {
    std::snprintf(text, sizeof text,
                  "the view position (%g, %g, %g) is not used: facet renders from the display's "
                  "eye",
                  mesh.position.x, mesh.position.y, mesh.position.z);
    projector.notes.push_back(text);
  }
  return result;
}

}  // namespace facet::interop
