#include "facet/driver/depth_image.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "facet/driver/scene_view.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "json_fields.hpp"

namespace facet::driver {
namespace {

using nlohmann::json;
constexpr const char* kFormat = "facet-depth-image/1";
constexpr const char* kAttribute = "facet:depth_image";
constexpr std::array<const char*, 7> kFloatChannels{"R", "G", "B", "Z", "N.x", "N.y", "N.z"};

std::string pixel_text(const DepthImagePart& part, std::size_t k) {
  return part.name + " pixel (" + std::to_string(k % std::size_t(part.size.x)) + ", " +
         std::to_string(k / std::size_t(part.size.x)) + ")";
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Rotation: orthonormal columns and determinant +1, within rounding of stored decimals.
bool is_rotation(const glm::dmat3& R) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (!std::isfinite(R[c][r])) return false;
  const glm::dmat3 should_be_identity = glm::transpose(R) * R;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (std::abs(should_be_identity[c][r] - (c == r ? 1.0 : 0.0)) > 1e-6) return false;
  return glm::determinant(R) > 0;
}

json part_to_json(const DepthImage& image, const DepthImagePart& part) {
  json meta = {{"format", kFormat},
               {"kind", to_string(image.kind)},
               {"part", part.name},
               {"base", to_string(part.base.kind)}};
  json_fields::put_base_parameters(part.base, meta);
  json pose = json::array();
  for (int r = 0; r < 4; ++r)
    pose.push_back({image.T_world_image[0][r], image.T_world_image[1][r], image.T_world_image[2][r],
                    image.T_world_image[3][r]});
  meta["rotation"] = json_fields::from_dmat3(part.R_image_part);
  meta["T_world_image"] = pose;
  return meta;
}

template <int R, int C>
glm::mat<C, R, double> matrix(const json& meta, const char* field, const std::string& source) {
  const std::string name = std::string(kAttribute) + "." + field;
  const std::string expected =
      "expected " + std::to_string(R) + " rows of " + std::to_string(C) + " numbers";
  const auto it = meta.find(field);
  if (it == meta.end() || !it->is_array() || it->size() != std::size_t(R))
    throw InputError(source, name, expected);
  glm::mat<C, R, double> m(1.0);
  for (int r = 0; r < R; ++r) {
    const json& row = (*it)[std::size_t(r)];
    if (!row.is_array() || row.size() != std::size_t(C)) throw InputError(source, name, expected);
    for (int c = 0; c < C; ++c) {
      if (!row[std::size_t(c)].is_number()) throw InputError(source, name, expected);
      m[c][r] = row[std::size_t(c)].get<double>();
    }
  }
  return m;
}

std::string subimage_source(const std::string& path, int subimage) {
  return path + " (part " + std::to_string(subimage) + ")";
}

}  // namespace

std::string to_string(DepthImageKind kind) {
  return kind == DepthImageKind::planar ? "planar" : "dpci";
}

glm::dvec3 DepthImagePart::v_image(int i, int j) const {
  const glm::dvec2 st((i + 0.5) / size.x, (j + 0.5) / size.y);
  return R_image_part * base.direction(st);
}

Warp DepthImagePart::warp() const { return Warp::analytic(base, size, {2, 2}, R_image_part); }

DepthImage make_dpci(glm::ivec2 cylinder_size, double tan_top, double tan_bottom) {
  DepthImage image;
  image.kind = DepthImageKind::dpci;
  DepthImagePart cylinder;
  cylinder.name = "cylinder";
  cylinder.base = BaseProjection::cylindrical(-180.0, 180.0, tan_top, tan_bottom);
  cylinder.size = cylinder_size;
  DepthImagePart cap;
  cap.name = "cap";
  cap.base = BaseProjection::perspective(-kDpciCapTan, kDpciCapTan, kDpciCapTan, -kDpciCapTan);
  // Base -z (the cap's view) to image +y, base +y (its top row) to image +z.
  cap.R_image_part = glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0));
  cap.size = {cylinder_size.y, cylinder_size.y};
  image.parts = {cylinder, cap};
  for (DepthImagePart& part : image.parts) {
    const std::size_t n = std::size_t(part.size.x) * std::size_t(std::max(part.size.y, 0));
    part.colour.assign(n, glm::vec3(0));
    part.distance_m.assign(n, std::numeric_limits<float>::infinity());
    part.normal.assign(n, glm::vec3(0));
  }
  return image;
}

DepthImage make_planar(glm::ivec2 size, double fov_x_deg) {
  DepthImage image;
  image.kind = DepthImageKind::planar;
  DepthImagePart part;
  part.name = "planar";
  const double tan_x = std::tan(glm::radians(fov_x_deg) / 2);
  const double tan_y = tan_x * size.y / std::max(size.x, 1);
  part.base = BaseProjection::perspective(-tan_x, tan_x, tan_y, -tan_y);
  part.size = size;
  const std::size_t n = std::size_t(std::max(size.x, 0)) * std::size_t(std::max(size.y, 0));
  part.colour.assign(n, glm::vec3(0));
  part.distance_m.assign(n, std::numeric_limits<float>::infinity());
  part.normal.assign(n, glm::vec3(0));
  image.parts = {part};
  return image;
}

void DepthImage::validate(const std::string& source) const {
  const std::vector<std::pair<std::string, BaseKind>> expected_parts =
      kind == DepthImageKind::planar
          ? std::vector<std::pair<std::string, BaseKind>>{{"planar", BaseKind::perspective}}
          : std::vector<std::pair<std::string, BaseKind>>{{"cylinder", BaseKind::cylindrical},
                                                          {"cap", BaseKind::perspective}};
  if (parts.size() != expected_parts.size())
    throw InputError(source, "parts",
                     "expected " + std::to_string(expected_parts.size()) + " part(s) for a " +
                         to_string(kind) + " depth image; got " + std::to_string(parts.size()));
  const glm::dmat3 R_world_image(T_world_image);
  bool pose_ok = is_rotation(R_world_image) && T_world_image[0][3] == 0 &&
                 T_world_image[1][3] == 0 && T_world_image[2][3] == 0 && T_world_image[3][3] == 1;
  for (int r = 0; r < 3; ++r) pose_ok = pose_ok && std::isfinite(T_world_image[3][r]);
  if (!pose_ok)
    throw InputError(source, "T_world_image", "expected a rigid transform (rotation, translation)");
  std::int64_t total = 0;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const DepthImagePart& part = parts[p];
    if (part.name != expected_parts[p].first || part.base.kind != expected_parts[p].second)
      throw InputError(source, "parts[" + std::to_string(p) + "]",
                       "expected part '" + expected_parts[p].first + "' with a " +
                           to_string(expected_parts[p].second) + " base; got '" + part.name +
                           "' with a " + to_string(part.base.kind) + " base");
    check_image_size(part.size, source, part.name + ".size");
    total += std::int64_t(part.size.x) * part.size.y;
    if (total > kMaxDepthImagePixels)
      throw InputError(source, part.name + ".size",
                       "expected at most " + std::to_string(kMaxDepthImagePixels) +
                           " pixels in all parts together");
    part.base.validate(source);
    if (!is_rotation(part.R_image_part))
      throw InputError(source, part.name + ".rotation", "expected a rotation matrix");
    const std::size_t n = std::size_t(part.size.x) * part.size.y;
    if (part.colour.size() != n || part.distance_m.size() != n || part.normal.size() != n ||
        (!part.source_id.empty() && part.source_id.size() != n))
      throw InputError(source, part.name + ".pixels",
                       "expected " + std::to_string(n) + " values in every channel");
    for (std::size_t k = 0; k < n; ++k) {
      const float d = part.distance_m[k];
      if (std::isnan(d) || d <= 0)
        throw InputError(source, "Z",
                         "expected a distance > 0 m or +inf (nothing seen) at " +
                             pixel_text(part, k) + "; got " + std::to_string(d));
      if (std::isinf(d)) continue;
      if (!finite(part.colour[k]))
        throw InputError(source, "R,G,B", "expected finite colour at " + pixel_text(part, k));
      const float length = finite(part.normal[k]) ? glm::length(part.normal[k]) : -1.0f;
      if (!(std::abs(length - 1.0f) <= 0.01f))
        throw InputError(source, "N.x,N.y,N.z",
                         "expected a unit normal at " + pixel_text(part, k) + "; its length is " +
                             std::to_string(length));
    }
  }
}

void write_depth_image(const std::filesystem::path& path, const DepthImage& image) {
  image.validate(path.string());
  const std::size_t parts = image.parts.size();
  std::vector<OIIO::ImageSpec> specs;
  std::vector<std::vector<unsigned char>> pixels(parts);
  for (std::size_t p = 0; p < parts; ++p) {
    const DepthImagePart& part = image.parts[p];
    const bool with_id = !part.source_id.empty();
    const int channels = int(kFloatChannels.size()) + (with_id ? 1 : 0);
    OIIO::ImageSpec spec(part.size.x, part.size.y, channels, OIIO::TypeDesc::FLOAT);
    spec.channelnames.assign(kFloatChannels.begin(), kFloatChannels.end());
    spec.channelformats.assign(kFloatChannels.size(), OIIO::TypeDesc::FLOAT);
    if (with_id) {
      spec.channelnames.push_back("id");
      spec.channelformats.push_back(OIIO::TypeDesc::UINT32);
    }
    spec.alpha_channel = -1;
    spec.z_channel = 3;
    spec.attribute("compression", "zip");
    spec.attribute("name", part.name);
    spec.attribute(kAttribute, part_to_json(image, part).dump());
    specs.push_back(spec);
    // Native layout: each pixel's channels in their own formats, 4 bytes each.
    const std::size_t n = std::size_t(part.size.x) * part.size.y;
    std::vector<unsigned char>& bytes = pixels[p];
    bytes.resize(n * std::size_t(channels) * 4);
    for (std::size_t k = 0; k < n; ++k) {
      const float values[7] = {part.colour[k].x,   part.colour[k].y, part.colour[k].z,
                               part.distance_m[k], part.normal[k].x, part.normal[k].y,
                               part.normal[k].z};
      unsigned char* out = &bytes[k * std::size_t(channels) * 4];
      std::memcpy(out, values, sizeof values);
      if (with_id) std::memcpy(out + sizeof values, &part.source_id[k], 4);
    }
  }
  // The parts of a multi-part OpenEXR file share one display window: the largest part's.
  int full_width = 0, full_height = 0;
  for (const OIIO::ImageSpec& spec : specs) {
    full_width = std::max(full_width, spec.width);
    full_height = std::max(full_height, spec.height);
  }
  for (OIIO::ImageSpec& spec : specs) {
    spec.full_width = full_width;
    spec.full_height = full_height;
  }
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    auto output = OIIO::ImageOutput::create("openexr");
    if (!output || !output->open(temporary.string(), int(parts), specs.data()))
      throw InputError(
          path.string(), "",
          "cannot create the file: " + (output ? output->geterror() : OIIO::geterror()));
    for (std::size_t p = 0; p < parts; ++p) {
      if (p > 0 && !output->open(temporary.string(), specs[p], OIIO::ImageOutput::AppendSubimage))
        throw InputError(path.string(), "",
                         "cannot add part " + image.parts[p].name + ": " + output->geterror());
      if (!output->write_image(OIIO::TypeDesc::UNKNOWN, pixels[p].data()))
        throw InputError(path.string(), "", "cannot write the file: " + output->geterror());
    }
    if (!output->close())
      throw InputError(path.string(), "", "cannot write the file: " + output->geterror());
  });
}

DepthImage read_depth_image(const std::filesystem::path& path) {
  const std::string file = path.string();
  require_regular_file(path);
  auto input = OIIO::ImageInput::open(file);
  if (!input) throw InputError(file, "", "cannot open as an image: " + OIIO::geterror());
  if (std::string(input->format_name()) != "openexr")
    throw InputError(file, "",
                     "expected an OpenEXR file; got " + std::string(input->format_name()));
  DepthImage image;
  std::int64_t total = 0;
  for (int subimage = 0; input->seek_subimage(subimage, 0); ++subimage) {
    const std::string source = subimage_source(file, subimage);
    if (subimage >= 2)
      throw InputError(file, "parts", "expected at most 2 parts (a DPCI's cylinder and cap)");
    const OIIO::ImageSpec spec = input->spec();
    const std::string meta_text = spec.get_string_attribute(kAttribute);
    if (meta_text.empty())
      throw InputError(source, kAttribute, "expected the header attribute holding the JSON");
    json meta;
    try {
      meta = json::parse(meta_text);
    } catch (const json::exception& e) {
      throw InputError(source, kAttribute, std::string("expected valid JSON: ") + e.what());
    }
    if (!meta.is_object() || meta.value("format", std::string()) != kFormat)
      throw InputError(source, std::string(kAttribute) + ".format",
                       std::string("expected \"") + kFormat + "\"");
    const auto string_field = [&](const char* field) {
      const auto it = meta.find(field);
      if (it == meta.end() || !it->is_string())
        throw InputError(source, std::string(kAttribute) + "." + field, "expected a string");
      return it->get<std::string>();
    };
    const std::string kind = string_field("kind");
    if (kind != "planar" && kind != "dpci")
      throw InputError(source, std::string(kAttribute) + ".kind",
                       "expected \"planar\" or \"dpci\"; got \"" + kind + "\"");
    const DepthImageKind this_kind =
        kind == "planar" ? DepthImageKind::planar : DepthImageKind::dpci;
    const glm::dmat4 pose = matrix<4, 4>(meta, "T_world_image", source);
    if (subimage == 0) {
      image.kind = this_kind;
      image.T_world_image = pose;
    } else if (this_kind != image.kind || pose != image.T_world_image) {
      throw InputError(source, kAttribute,
                       "expected the same kind and T_world_image in every part");
    }
    DepthImagePart part;
    part.name = string_field("part");
    part.base.kind =
        base_kind_from_string(string_field("base"), source, std::string(kAttribute) + ".base");
    if (part.base.kind != BaseKind::perspective && part.base.kind != BaseKind::cylindrical)
      throw InputError(source, std::string(kAttribute) + ".base",
                       "expected perspective or cylindrical");
    const json_fields::FieldPath at(source, kAttribute);
    part.base = json_fields::to_base_parameters(meta, part.base.kind, at);
    if (!meta.contains("rotation")) at["rotation"].fail("a 3x3 matrix (the field is missing)");
    part.R_image_part = json_fields::to_dmat3(meta["rotation"], at["rotation"]);
    // Sizes before any pixel is allocated.
    part.size = {spec.width, spec.height};
    check_image_size(part.size, source, "size");
    total += std::int64_t(spec.width) * spec.height;
    if (total > kMaxDepthImagePixels)
      throw InputError(file, "size",
                       "expected at most " + std::to_string(kMaxDepthImagePixels) +
                           " pixels in all parts together");
    std::array<int, 7> channel{};
    std::string missing;
    for (std::size_t c = 0; c < kFloatChannels.size(); ++c) {
      channel[c] = spec.channelindex(kFloatChannels[c]);
      if (channel[c] < 0) missing += (missing.empty() ? "" : ", ") + std::string(kFloatChannels[c]);
    }
    if (!missing.empty())
      throw InputError(
          source, "channels",
          "expected channels R, G, B, Z, N.x, N.y, N.z (id optional); missing " + missing);
    const std::size_t n = std::size_t(spec.width) * spec.height;
    std::vector<float> values(n * std::size_t(spec.nchannels));
    if (!input->read_image(subimage, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, values.data()))
      throw InputError(source, "pixels", "cannot read the image data: " + input->geterror());
    part.colour.resize(n);
    part.distance_m.resize(n);
    part.normal.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const float* v = &values[k * std::size_t(spec.nchannels)];
      part.colour[k] = {v[channel[0]], v[channel[1]], v[channel[2]]};
      part.distance_m[k] = v[channel[3]];
      part.normal[k] = {v[channel[4]], v[channel[5]], v[channel[6]]};
    }
    const int id_channel = spec.channelindex("id");
    if (id_channel >= 0) {
      part.source_id.resize(n);
      if (!input->read_image(subimage, 0, id_channel, id_channel + 1, OIIO::TypeDesc::UINT32,
                             part.source_id.data()))
        throw InputError(source, "id", "cannot read the image data: " + input->geterror());
    }
    image.parts.push_back(std::move(part));
  }
  if (image.parts.empty()) throw InputError(file, "parts", "expected at least one part");
  image.validate(file);
  return image;
}

namespace {

// True when the grid edge from a to b (image-frame points of the two pixels, eye at the origin)
// stays on one surface (DepthMeshOptions): the plane through either end predicts the other end's
// distance within `footprints` of its pixel footprints, or the edge runs within `tangent_sin`
// (a sine) of either end's tangent plane.
bool joins_one_surface(const glm::dvec3& p_a, const glm::dvec3& n_a, const glm::dvec3& p_b,
                       const glm::dvec3& n_b, double footprints, double tangent_sin) {
  const double d_a = glm::length(p_a), d_b = glm::length(p_b);
  const glm::dvec3 v_a = p_a / d_a, v_b = p_b / d_b;
  const double angle = std::atan2(glm::length(glm::cross(v_a, v_b)), glm::dot(v_a, v_b));
  const auto predicts = [&](const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& v,
                            double d) {
    const double facing = glm::dot(n, v);
    if (std::abs(facing) < 1e-6) return false;
    const double t = glm::dot(n, p) / facing;
    return t > 0 && std::abs(t - d) <= footprints * angle * d;
  };
  if (predicts(p_a, n_a, v_b, d_b) || predicts(p_b, n_b, v_a, d_a)) return true;
  const glm::dvec3 edge = p_b - p_a;
  const double length = glm::length(edge);
  if (length == 0) return true;
  return std::abs(glm::dot(n_a, edge)) <= tangent_sin * length ||
         std::abs(glm::dot(n_b, edge)) <= tangent_sin * length;
}

std::uint8_t srgb_encode(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);
  const float e = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return std::uint8_t(std::lround(e * 255.0f));
}

}  // namespace

DepthMesh depth_image_mesh(const DepthImage& image, const DepthMeshOptions& options) {
  if (options.step < 1 || options.step > 64)
    throw InputError(
        "command line", OptionName{"step"},
        "expected a depth image grid step in 1..64; got " + std::to_string(options.step));
  image.validate();
  DepthMesh mesh;
  Scene& scene = mesh.scene;
  scene.name = "depth image";
  const double tangent_sin = std::sin(glm::radians(options.edge_tangent_deg));
  for (const DepthImagePart& part : image.parts) {
    const bool wraps = part.base.wraps_horizontally();
    // Grid columns and rows: every step-th pixel and the last.
    const auto samples = [&](int n) {
      std::vector<int> s;
      for (int k = 0; k < n; k += options.step) s.push_back(k);
      if (s.back() != n - 1) s.push_back(n - 1);
      return s;
    };
    const std::vector<int> rows = samples(part.size.y);
    std::vector<int> columns = samples(part.size.x);
    const std::size_t grid_w = columns.size() + (wraps ? 1 : 0);
    // Vertex index per grid node, or -1 where the pixel sees nothing.
    std::vector<std::int64_t> vertex(grid_w * rows.size(), -1);
    std::vector<glm::dvec3> p_node(vertex.size()), n_node(vertex.size());
    for (std::size_t gj = 0; gj < rows.size(); ++gj) {
      for (std::size_t gi = 0; gi < grid_w; ++gi) {
        const bool seam = gi == columns.size();
        const int i = seam ? columns[0] : columns[gi], j = rows[gj];
        const std::size_t k = part.pixel_index(i, j);
        if (std::isinf(part.distance_m[k])) continue;
        const glm::dvec3 p = double(part.distance_m[k]) * part.v_image(i, j);
        const std::size_t node = gj * grid_w + gi;
        vertex[node] = std::int64_t(scene.positions.size());
        p_node[node] = p;
        n_node[node] = glm::dvec3(part.normal[k]);
        scene.positions.push_back(glm::vec3(p));
        scene.normals.push_back(glm::normalize(part.normal[k]));
        scene.uvs.push_back({float((i + (seam ? part.size.x : 0) + 0.5) / part.size.x),
                             float((j + 0.5) / part.size.y)});
      }
    }
    Primitive primitive;
    primitive.first_index = std::uint32_t(scene.indices.size());
    primitive.material = std::uint32_t(scene.materials.size());
    const auto id_at = [&](std::size_t node) -> std::uint32_t {
      if (part.source_id.empty()) return 0;
      const std::size_t gi = node % grid_w, gj = node / grid_w;
      const int i = gi == columns.size() ? columns[0] : columns[gi];
      return part.source_id[part.pixel_index(i, rows[gj])];
    };
    // A triangle of grid nodes when all corners are seen and every edge joins one surface; wound
    // counter-clockwise seen from the eye.
    const auto triangle = [&](std::size_t a, std::size_t b, std::size_t c,
                              std::array<std::uint32_t, 3>& out) {
      if (vertex[a] < 0 || vertex[b] < 0 || vertex[c] < 0) return false;
      const std::array<std::size_t, 3> nodes{a, b, c};
      for (int e = 0; e < 3; ++e) {
        const std::size_t u = nodes[std::size_t(e)], v = nodes[std::size_t((e + 1) % 3)];
        if (!joins_one_surface(p_node[u], n_node[u], p_node[v], n_node[v], options.edge_footprints,
                               tangent_sin))
          return false;
      }
      const glm::dvec3 normal = glm::cross(p_node[b] - p_node[a], p_node[c] - p_node[a]);
      if (glm::dot(normal, normal) == 0) return false;
      const bool facing_eye = glm::dot(normal, p_node[a]) < 0;
      out = {std::uint32_t(vertex[a]), std::uint32_t(vertex[facing_eye ? b : c]),
             std::uint32_t(vertex[facing_eye ? c : b])};
      return true;
    };
    for (std::size_t gj = 0; gj + 1 < rows.size(); ++gj) {
      for (std::size_t gi = 0; gi + 1 < grid_w; ++gi) {
        const std::size_t n00 = gj * grid_w + gi, n10 = n00 + 1, n01 = n00 + grid_w, n11 = n01 + 1;
        // The diagonal that keeps more triangles (across a discontinuity one may survive).
        std::array<std::array<std::uint32_t, 3>, 4> tri{};
        std::array<std::array<std::size_t, 3>, 4> corners{
            {{n00, n01, n11}, {n00, n11, n10}, {n00, n01, n10}, {n10, n01, n11}}};
        std::array<bool, 4> ok{};
        for (std::size_t t = 0; t < 4; ++t)
          ok[t] = triangle(corners[t][0], corners[t][1], corners[t][2], tri[t]);
        const int first = int(ok[0]) + int(ok[1]), second = int(ok[2]) + int(ok[3]);
        const std::size_t from = second > first ? 2 : 0;
        mesh.dropped_triangles += std::size_t(2 - std::max(first, second));
        for (std::size_t t = from; t < from + 2; ++t) {
          if (!ok[t]) continue;
          scene.indices.insert(scene.indices.end(), tri[t].begin(), tri[t].end());
          const std::uint32_t a = id_at(corners[t][0]), b = id_at(corners[t][1]),
                              c = id_at(corners[t][2]);
          mesh.source_id.push_back(b == c ? b : a);
        }
      }
    }
    primitive.index_count = std::uint32_t(scene.indices.size()) - primitive.first_index;
    // The colour as an sRGB texture, texel centres at the vertices' uvs.
    Image texture;
    texture.name = part.name;
    texture.width = part.size.x;
    texture.height = part.size.y;
    texture.rgba.resize(std::size_t(part.size.x) * part.size.y * 4);
    for (std::size_t k = 0; k < part.colour.size(); ++k) {
      for (int c = 0; c < 3; ++c)
        texture.rgba[4 * k + std::size_t(c)] = srgb_encode(part.colour[k][c]);
      texture.rgba[4 * k + 3] = 255;
    }
    Material material;
    material.name = "depth image " + part.name;
    material.texture = int(scene.images.size());
    material.repeat = wraps;
    scene.images.push_back(std::move(texture));
    scene.materials.push_back(material);
    Object object;
    object.name = part.name;
    object.T_world_object = glm::mat4(image.T_world_image);
    object.first_primitive = std::uint32_t(scene.primitives.size());
    object.primitive_count = 1;
    scene.primitives.push_back(primitive);
    scene.objects.push_back(object);
  }
  SceneCamera eye;
  eye.name = kDepthImageEyeCamera;
  eye.T_world_camera = image.T_world_image;
  scene.cameras.push_back(eye);
  scene.update_bounds();
  return mesh;
}

Scene merge_scenes(Scene a, const Scene& b) {
  const auto vertex_base = std::uint32_t(a.positions.size());
  const auto index_base = std::uint32_t(a.indices.size());
  const auto primitive_base = std::uint32_t(a.primitives.size());
  const auto material_base = std::uint32_t(a.materials.size());
  const int image_base = int(a.images.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
  a.uvs.insert(a.uvs.end(), b.uvs.begin(), b.uvs.end());
  for (std::uint32_t index : b.indices) a.indices.push_back(index + vertex_base);
  for (Primitive primitive : b.primitives) {
    primitive.first_index += index_base;
    primitive.material += material_base;
    a.primitives.push_back(primitive);
  }
  for (Object object : b.objects) {
    object.first_primitive += primitive_base;
    a.objects.push_back(object);
  }
  for (Material material : b.materials) {
    if (material.texture >= 0) material.texture += image_base;
    a.materials.push_back(material);
  }
  a.images.insert(a.images.end(), b.images.begin(), b.images.end());
  a.cameras.insert(a.cameras.end(), b.cameras.begin(), b.cameras.end());
  a.name = a.name + " + " + b.name;
  return a;
}

}  // namespace facet::driver
