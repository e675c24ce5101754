#include "facet/driver/depth_image.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

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

namespace {

// The grid nodes of one axis inside a block from node `from` to node `to`: every step-th one
// and the last.
std::vector<int> block_nodes(int from, int to, int step) {
  std::vector<int> nodes;
  for (int k = from; k < to; k += step) nodes.push_back(k);
  nodes.push_back(to);
  return nodes;
}

// The nodes of `nodes` strictly between a and b (a < b), in order.
std::vector<int> nodes_between(const std::vector<int>& nodes, int a, int b) {
  std::vector<int> inside;
  for (int n : nodes)
    if (n > a && n < b) inside.push_back(n);
  return inside;
}

void check_mesh_options(const DepthMeshOptions& options) {
  if (options.step < 1 || options.step > 64)
    throw InputError(
        "command line", OptionName{"step"},
        "expected a depth image grid step in 1..64; got " + std::to_string(options.step));
  if (!std::isfinite(options.lod_angle_rad) || options.lod_angle_rad < 0 ||
      options.lod_angle_rad > 1)
    throw InputError("command line", OptionName{"lod"},
                     "expected a level-of-detail angle in [0, 1] rad; got " +
                         std::to_string(options.lod_angle_rad));
  if (options.lod_angle_rad > 0 && options.step != 1)
    throw InputError("command line", OptionName{"lod"},
                     "expected grid step 1 with level of detail (it chooses the steps); got " +
                         std::to_string(options.step));
}

// The grid of one part: nodes x in [0, last_x] (x = W, the cylinder's seam, is pixel column 0
// again), y in [0, last_y]; blocks of `block` nodes a side (one for the whole part without level
// of detail).
struct PartGrid {
  int W = 0, H = 0, last_x = 0, last_y = 0, block = 1, blocks_x = 0, blocks_y = 0;
  bool wraps = false;
  PartGrid(const DepthImagePart& part, bool lod)
      : W(part.size.x), H(part.size.y), wraps(part.base.wraps_horizontally()) {
    last_x = wraps ? W : W - 1;
    last_y = H - 1;
    block = lod ? kDepthLodBlock : std::max(last_x, last_y) + 1;
    blocks_x = last_x > 0 ? (last_x + block - 1) / block : 0;
    blocks_y = last_y > 0 ? (last_y + block - 1) / block : 0;
  }
};

constexpr int kLodLevels = std::countr_zero(unsigned(kDepthLodBlock)) + 1;

}  // namespace

DepthLodChooser::DepthLodChooser(const DepthImage& image, const DepthMeshOptions& options) {
  check_mesh_options(options);
  if (!(options.lod_angle_rad > 0))
    throw InputError("command line", OptionName{"lod"},
                     "expected a level-of-detail angle in (0, 1] rad; got " +
                         std::to_string(options.lod_angle_rad));
  image.validate();
  T_image_world_ = glm::inverse(image.T_world_image);
  angle_rad_ = options.lod_angle_rad;
  const double tangent_sin = std::sin(glm::radians(options.edge_tangent_deg));
  for (const DepthImagePart& part : image.parts) {
    const PartGrid grid(part, true);
    Part& out = parts_.emplace_back();
    out.blocks_x = grid.blocks_x;
    out.blocks_y = grid.blocks_y;
    out.wraps = grid.wraps;
    out.p_image.assign(part.distance_m.size(), glm::dvec3(0.0));
    const auto seen = [&](int i, int j) {
      return !std::isinf(part.distance_m[part.pixel_index(i, j)]);
    };
    for (int j = 0; j < grid.H; ++j)
      for (int i = 0; i < grid.W; ++i)
        if (seen(i, j))
          out.p_image[part.pixel_index(i, j)] =
              double(part.distance_m[part.pixel_index(i, j)]) * part.v_image(i, j);
    if (grid.blocks_x <= 0 || grid.blocks_y <= 0) continue;
    for (int j = 0; j < grid.H; ++j) {
      for (int i = 0; i < grid.W; ++i) {
        if (!seen(i, j)) continue;
        const std::size_t k = part.pixel_index(i, j);
        const glm::dvec3 n(part.normal[k]);
        const int bx = std::min(i / grid.block, grid.blocks_x - 1),
                  by = std::min(j / grid.block, grid.blocks_y - 1);
        for (const glm::ivec2 next : {glm::ivec2(i + 1, j), glm::ivec2(i, j + 1)}) {
          int ni = next.x;
          if (ni == grid.W) {
            if (!grid.wraps) continue;
            ni = 0;
          }
          if (next.y >= grid.H || !seen(ni, next.y)) continue;
          const std::size_t m = part.pixel_index(ni, next.y);
          if (!joins_one_surface(out.p_image[k], n, out.p_image[m], glm::dvec3(part.normal[m]),
                                 options.edge_footprints, tangent_sin))
            continue;
          out.pairs.push_back(
              {std::uint32_t(k), std::uint32_t(m), std::uint32_t(by * grid.blocks_x + bx)});
        }
      }
    }
  }
}

DepthLodLevels DepthLodChooser::levels(const glm::dvec3& eye_world) const {
  const glm::dvec3 eye(T_image_world_ * glm::dvec4(eye_world, 1.0));
  DepthLodLevels levels;
  for (const Part& part : parts_) {
    const int blocks_x = part.blocks_x, blocks_y = part.blocks_y;
    std::vector<std::uint8_t>& level = levels.emplace_back(
        std::size_t(std::max(blocks_x, 0)) * std::size_t(std::max(blocks_y, 0)), std::uint8_t(0));
    // The largest angle, seen from the eye, between neighbouring pixels that join one surface,
    // found as the largest chord |u_a - u_b| between their unit directions from the eye (2
    // sin(angle / 2), which grows with the angle over [0, pi]): each pixel's direction is
    // normalised once, not once per pair, and no pair takes an arctangent.
    std::vector<glm::dvec3> u(part.p_image.size());
    for (const Part::Pair& pair : part.pairs)
      for (const std::uint32_t k : {pair.a, pair.b})
        if (u[k] == glm::dvec3(0.0)) u[k] = glm::normalize(part.p_image[k] - eye);
    std::vector<double> chord_squared(level.size(), 0.0);
    for (const Part::Pair& pair : part.pairs) {
      const glm::dvec3 d = u[pair.a] - u[pair.b];
      double& worst = chord_squared[pair.block];
      worst = std::max(worst, glm::dot(d, d));
    }
    std::vector<double> angle(level.size(), 0.0);
    for (std::size_t b = 0; b < level.size(); ++b)
      angle[b] = 2.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(chord_squared[b])));
    for (std::size_t b = 0; b < level.size(); ++b) {
      int l = 0;
      while (l + 1 < kLodLevels && angle[b] * double(1 << (l + 1)) <= angle_rad_) ++l;
      level[b] = std::uint8_t(l);
    }
    // Neighbours differ by one level at most: lower the coarser until none is two above.
    const auto level_at = [&](int bx, int by) -> std::uint8_t& {
      return level[std::size_t(by) * std::size_t(blocks_x) + std::size_t(bx)];
    };
    for (bool changed = true; changed;) {
      changed = false;
      for (int by = 0; by < blocks_y; ++by)
        for (int bx = 0; bx < blocks_x; ++bx) {
          std::uint8_t& l = level_at(bx, by);
          const auto limit = [&](int nx, int ny) {
            if (nx < 0 || nx >= blocks_x) {
              if (!part.wraps) return;
              nx = (nx + blocks_x) % blocks_x;
            }
            if (ny < 0 || ny >= blocks_y) return;
            if (l > level_at(nx, ny) + 1) {
              l = std::uint8_t(level_at(nx, ny) + 1);
              changed = true;
            }
          };
          limit(bx - 1, by);
          limit(bx + 1, by);
          limit(bx, by - 1);
          limit(bx, by + 1);
        }
    }
  }
  return levels;
}

// One part of the image as DepthMeshBuilder keeps it.
struct DepthMeshBuilder::Part {
  Part(const DepthImagePart& source, bool lod) : name(source.name), grid(source, lod) {}
  std::string name;
  PartGrid grid;
  // Per pixel, row-major: the point in the image frame (unused where nothing is seen), the stored
  // normal and the source ID.
  std::vector<glm::dvec3> p_image;
  std::vector<bool> seen;
  std::vector<glm::vec3> normal;
  std::vector<std::uint32_t> id;
  Image texture;
  // A block's triangles as grid nodes (y · (W + 1) + x), counter-clockwise seen from the eye, in
  // the order depth_image_mesh emits them; the seen nodes its triangles looked at, in the order
  // they were first looked at (vertices are numbered in that order across blocks); and what they
  // were made for: the block's level and each side's finer neighbour's (kNoNeighbour if none).
  struct Block {
    static constexpr std::uint8_t kNoNeighbour = 0xff;
    bool made = false;
    std::array<std::uint8_t, 5> key{};
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<std::uint32_t> source_id;
    std::vector<std::uint32_t> looked_at;
    std::size_t dropped = 0;
  };
  std::vector<Block> blocks;

  std::size_t node(int x, int y) const {
    return std::size_t(y) * std::size_t(grid.W + 1) + std::size_t(x);
  }
  std::size_t pixel_of_node(std::size_t n) const {
    const int x = int(n % std::size_t(grid.W + 1)), y = int(n / std::size_t(grid.W + 1));
    return std::size_t(y) * std::size_t(grid.W) + std::size_t(x == grid.W ? 0 : x);
  }
};

DepthMeshBuilder::~DepthMeshBuilder() = default;
DepthMeshBuilder::DepthMeshBuilder(DepthMeshBuilder&&) noexcept = default;
DepthMeshBuilder& DepthMeshBuilder::operator=(DepthMeshBuilder&&) noexcept = default;

std::size_t DepthMeshBuilder::block_count() const {
  std::size_t count = 0;
  for (const Part& part : parts_) count += part.blocks.size();
  return count;
}

DepthMeshBuilder::DepthMeshBuilder(const DepthImage& image, const DepthMeshOptions& options)
    : T_world_image_(image.T_world_image), options_(options), lod_(options.lod_angle_rad > 0) {
  check_mesh_options(options);
  image.validate();
  options_.lod_levels.reset();
  options_.lod_eye_world.reset();
  for (const DepthImagePart& source : image.parts) {
    Part& part = parts_.emplace_back(source, lod_);
    const PartGrid& grid = part.grid;
    const std::size_t pixels = source.distance_m.size();
    part.p_image.assign(pixels, glm::dvec3(0.0));
    part.seen.assign(pixels, false);
    part.normal = source.normal;
    part.id = source.source_id.empty() ? std::vector<std::uint32_t>(pixels, 0u) : source.source_id;
    for (int j = 0; j < grid.H; ++j)
      for (int i = 0; i < grid.W; ++i) {
        const std::size_t k = source.pixel_index(i, j);
        if (std::isinf(source.distance_m[k])) continue;
        part.seen[k] = true;
        part.p_image[k] = double(source.distance_m[k]) * source.v_image(i, j);
      }
    // The colour as an sRGB texture, texel centres at the vertices' uvs.
    part.texture.name = source.name;
    part.texture.width = source.size.x;
    part.texture.height = source.size.y;
    part.texture.rgba.resize(std::size_t(source.size.x) * source.size.y * 4);
    for (std::size_t k = 0; k < source.colour.size(); ++k) {
      for (int c = 0; c < 3; ++c)
        part.texture.rgba[4 * k + std::size_t(c)] = srgb_encode(source.colour[k][c]);
      part.texture.rgba[4 * k + 3] = 255;
    }
    part.blocks.resize(std::size_t(std::max(grid.blocks_x, 0)) *
                       std::size_t(std::max(grid.blocks_y, 0)));
  }
}

DepthMesh DepthMeshBuilder::build(const DepthLodLevels& given_levels) {
  const DepthMeshOptions& options = options_;
  const bool lod = lod_;
  DepthMesh mesh;
  Scene& scene = mesh.scene;
  scene.name = "depth image";
  const double tangent_sin = std::sin(glm::radians(options.edge_tangent_deg));
  DepthLodLevels levels;
  if (lod) {
    mesh.lod_blocks_by_level.assign(kLodLevels, 0);
    bool fits = given_levels.size() == parts_.size();
    for (std::size_t p = 0; fits && p < given_levels.size(); ++p) {
      fits = given_levels[p].size() == parts_[p].blocks.size();
      for (std::uint8_t l : given_levels[p]) fits = fits && l < kLodLevels;
    }
    if (!fits)
      throw InputError("command line", OptionName{"lod"},
                       "expected levels below " + std::to_string(kLodLevels) +
                           " for every block of every part of the depth image");
    levels = given_levels;
  }
  blocks_made_ = 0;
  for (std::size_t part_index = 0; part_index < parts_.size(); ++part_index) {
    Part& part = parts_[part_index];
    const PartGrid& grid = part.grid;
    const bool wraps = grid.wraps;
    const int W = grid.W, H = grid.H, last_x = grid.last_x, last_y = grid.last_y;
    const int block = grid.block, blocks_x = grid.blocks_x, blocks_y = grid.blocks_y;
    const auto block_from_x = [&](int bx) { return bx * block; };
    const auto block_to_x = [&](int bx) { return std::min((bx + 1) * block, last_x); };
    const auto block_from_y = [&](int by) { return by * block; };
    const auto block_to_y = [&](int by) { return std::min((by + 1) * block, last_y); };

    // Each block's level (step 2^level).
    const auto level_at = [&](int bx, int by) -> int {
      return levels[part_index][std::size_t(by) * std::size_t(blocks_x) + std::size_t(bx)];
    };
    if (lod)
      for (std::uint8_t l : levels[part_index]) ++mesh.lod_blocks_by_level[std::size_t(l)];
    // A block's nodes along x and y at its step. Without level of detail the cylinder keeps its
    // last column before the seam (every step-th pixel and the last, then the seam).
    const auto xs_of = [&](int bx, int by) {
      if (!lod) {
        std::vector<int> xs = block_nodes(0, W - 1, options.step);
        if (wraps) xs.push_back(W);
        return xs;
      }
      return block_nodes(block_from_x(bx), block_to_x(bx), 1 << level_at(bx, by));
    };
    const auto ys_of = [&](int bx, int by) {
      if (!lod) return block_nodes(0, last_y, options.step);
      return block_nodes(block_from_y(by), block_to_y(by), 1 << level_at(bx, by));
    };
    // The finer neighbour of block (bx, by) at block (nx, ny), if that is one.
    const auto finer_neighbour = [&](int bx, int by, int nx, int ny) -> std::optional<glm::ivec2> {
      if (!lod) return std::nullopt;
      if (nx < 0 || nx >= blocks_x) {
        if (!wraps) return std::nullopt;
        nx = (nx + blocks_x) % blocks_x;
      }
      if (ny < 0 || ny >= blocks_y) return std::nullopt;
      if (level_at(nx, ny) >= level_at(bx, by)) return std::nullopt;
      return glm::ivec2(nx, ny);
    };

    // Nodes a block looked at, marked with the block's number + 1 while it is made.
    std::vector<std::uint32_t> looked_by;
    std::uint32_t block_number = 0;
    const auto make_block = [&](int bx, int by, Part::Block& made) {
      made.triangles.clear();
      made.source_id.clear();
      made.looked_at.clear();
      made.dropped = 0;
      if (looked_by.empty()) looked_by.assign(std::size_t(W + 1) * std::size_t(std::max(H, 0)), 0u);
      ++block_number;
      using Node = glm::ivec2;
      // The seen node at (x, y), recorded as looked at; nullopt where the pixel sees nothing.
      const auto look_at = [&](Node n) -> std::optional<std::size_t> {
        const std::size_t k = part.pixel_of_node(part.node(n.x, n.y));
        if (!part.seen[k]) return std::nullopt;
        const std::size_t node = part.node(n.x, n.y);
        if (looked_by[node] != block_number) {
          looked_by[node] = block_number;
          made.looked_at.push_back(std::uint32_t(node));
        }
        return node;
      };
      // joins_one_surface (symmetric) of the cell's edges, each judged once: the four triangles
      // a plain cell tries share its four sides and two diagonals. Cleared for every cell.
      struct JudgedEdge {
        std::size_t u, w;
        bool joins;
      };
      std::vector<JudgedEdge> judged;
      const auto edge_joins = [&](std::size_t u, std::size_t w) {
        if (u > w) std::swap(u, w);
        for (const JudgedEdge& edge : judged)
          if (edge.u == u && edge.w == w) return edge.joins;
        const std::size_t ku = part.pixel_of_node(u), kw = part.pixel_of_node(w);
        const bool joins =
            joins_one_surface(part.p_image[ku], glm::dvec3(part.normal[ku]), part.p_image[kw],
                              glm::dvec3(part.normal[kw]), options.edge_footprints, tangent_sin);
        judged.push_back({u, w, joins});
        return joins;
      };
      // A triangle of grid nodes when all corners are seen and every edge joins one surface;
      // wound counter-clockwise seen from the eye.
      const auto triangle = [&](Node na, Node nb, Node nc, std::array<std::uint32_t, 3>& out,
                                std::uint32_t& id) {
        const std::optional<std::size_t> a = look_at(na), b = look_at(nb), c = look_at(nc);
        if (!a || !b || !c) return false;
        const std::array<std::size_t, 3> v{*a, *b, *c};
        for (int e = 0; e < 3; ++e) {
          const std::size_t u = v[std::size_t(e)], w = v[std::size_t((e + 1) % 3)];
          if (!edge_joins(u, w)) return false;
        }
        const std::array<std::size_t, 3> k{part.pixel_of_node(v[0]), part.pixel_of_node(v[1]),
                                           part.pixel_of_node(v[2])};
        const glm::dvec3 normal = glm::cross(part.p_image[k[1]] - part.p_image[k[0]],
                                             part.p_image[k[2]] - part.p_image[k[0]]);
        if (glm::dot(normal, normal) == 0) return false;
        const bool facing_eye = glm::dot(normal, part.p_image[k[0]]) < 0;
        out = {std::uint32_t(v[0]), std::uint32_t(facing_eye ? v[1] : v[2]),
               std::uint32_t(facing_eye ? v[2] : v[1])};
        const std::uint32_t ia = part.id[k[0]], ib = part.id[k[1]], ic = part.id[k[2]];
        id = ib == ic ? ib : ia;
        return true;
      };
      const auto emit = [&](const std::array<std::uint32_t, 3>& tri, std::uint32_t id) {
        made.triangles.push_back(tri);
        made.source_id.push_back(id);
      };
      const std::vector<int> xs = xs_of(bx, by), ys = ys_of(bx, by);
      // The finer neighbours' nodes along the shared edges (none without level of detail).
      const auto left = finer_neighbour(bx, by, bx - 1, by),
                 right = finer_neighbour(bx, by, bx + 1, by),
                 top = finer_neighbour(bx, by, bx, by - 1),
                 bottom = finer_neighbour(bx, by, bx, by + 1);
      const std::vector<int> left_ys = left ? ys_of(left->x, left->y) : std::vector<int>{},
                             right_ys = right ? ys_of(right->x, right->y) : std::vector<int>{},
                             top_xs = top ? xs_of(top->x, top->y) : std::vector<int>{},
                             bottom_xs = bottom ? xs_of(bottom->x, bottom->y) : std::vector<int>{};
      for (std::size_t gj = 0; gj + 1 < ys.size(); ++gj) {
        for (std::size_t gi = 0; gi + 1 < xs.size(); ++gi) {
          const int x0 = xs[gi], x1 = xs[gi + 1], y0 = ys[gj], y1 = ys[gj + 1];
          // Extra nodes on the cell's sides from finer neighbours.
          const std::vector<int> on_top =
              top && gj == 0 ? nodes_between(top_xs, x0, x1) : std::vector<int>{};
          const std::vector<int> on_bottom =
              bottom && gj + 2 == ys.size() ? nodes_between(bottom_xs, x0, x1) : std::vector<int>{};
          const std::vector<int> on_left =
              left && gi == 0 ? nodes_between(left_ys, y0, y1) : std::vector<int>{};
          const std::vector<int> on_right =
              right && gi + 2 == xs.size() ? nodes_between(right_ys, y0, y1) : std::vector<int>{};
          judged.clear();
          std::array<std::uint32_t, 3> tri{};
          std::uint32_t id = 0;
          if (on_top.empty() && on_bottom.empty() && on_left.empty() && on_right.empty()) {
            // The diagonal that keeps more triangles (across a discontinuity one may survive).
            const Node n00(x0, y0), n10(x1, y0), n01(x0, y1), n11(x1, y1);
            std::array<std::array<std::uint32_t, 3>, 4> tris{};
            std::array<std::uint32_t, 4> ids{};
            const std::array<std::array<Node, 3>, 4> corners{
                {{n00, n01, n11}, {n00, n11, n10}, {n00, n01, n10}, {n10, n01, n11}}};
            std::array<bool, 4> ok{};
            for (std::size_t t = 0; t < 4; ++t)
              ok[t] = triangle(corners[t][0], corners[t][1], corners[t][2], tris[t], ids[t]);
            const int first = int(ok[0]) + int(ok[1]), second = int(ok[2]) + int(ok[3]);
            const std::size_t from = second > first ? 2 : 0;
            made.dropped += std::size_t(2 - std::max(first, second));
            for (std::size_t t = from; t < from + 2; ++t)
              if (ok[t]) emit(tris[t], ids[t]);
            continue;
          }
          // The cell's outline, counter-clockwise in the grid (x right, y down): top left to
          // bottom left, bottom right, top right, with the finer neighbours' nodes.
          std::vector<Node> outline;
          outline.emplace_back(x0, y0);
          for (int y : on_left) outline.emplace_back(x0, y);
          outline.emplace_back(x0, y1);
          for (int x : on_bottom) outline.emplace_back(x, y1);
          outline.emplace_back(x1, y1);
          for (auto it = on_right.rbegin(); it != on_right.rend(); ++it)
            outline.emplace_back(x1, *it);
          outline.emplace_back(x1, y0);
          for (auto it = on_top.rbegin(); it != on_top.rend(); ++it) outline.emplace_back(*it, y0);
          const auto add = [&](Node a, Node b, Node c) {
            if (triangle(a, b, c, tri, id))
              emit(tri, id);
            else
              ++made.dropped;
          };
          if (x1 - x0 >= 2 && y1 - y0 >= 2) {
            // A fan about the cell's centre pixel.
            const Node centre((x0 + x1) / 2, (y0 + y1) / 2);
            for (std::size_t k = 0; k < outline.size(); ++k)
              add(centre, outline[k], outline[(k + 1) % outline.size()]);
          } else {
            // One pixel wide: the extra nodes lie on the two long sides; a strip between them.
            const bool tall = x1 - x0 == 1;
            std::vector<Node> a, b;  // the two long sides, in the same direction
            if (tall) {
              a.emplace_back(x0, y0);
              for (int y : on_left) a.emplace_back(x0, y);
              a.emplace_back(x0, y1);
              b.emplace_back(x1, y0);
              for (int y : on_right) b.emplace_back(x1, y);
              b.emplace_back(x1, y1);
            } else {
              a.emplace_back(x0, y0);
              for (int x : on_top) a.emplace_back(x, y0);
              a.emplace_back(x1, y0);
              b.emplace_back(x0, y1);
              for (int x : on_bottom) b.emplace_back(x, y1);
              b.emplace_back(x1, y1);
            }
            std::size_t ia = 0, ib = 0;
            while (ia + 1 < a.size() || ib + 1 < b.size()) {
              const int along_a = ia + 1 < a.size() ? (tall ? a[ia + 1].y : a[ia + 1].x) : 1 << 30;
              const int along_b = ib + 1 < b.size() ? (tall ? b[ib + 1].y : b[ib + 1].x) : 1 << 30;
              if (along_a <= along_b) {
                add(a[ia], a[ia + 1], b[ib]);
                ++ia;
              } else {
                add(a[ia], b[ib + 1], b[ib]);
                ++ib;
              }
            }
          }
        }
      }
    };

    // Make the blocks whose level or finer neighbours changed; number the vertices in the order
    // the blocks first looked at their nodes, as one pass over every block would.
    Primitive primitive;
    primitive.first_index = std::uint32_t(scene.indices.size());
    primitive.material = std::uint32_t(scene.materials.size());
    std::vector<std::uint32_t> vertex(std::size_t(W + 1) * std::size_t(std::max(H, 0)), ~0u);
    for (int by = 0; by < blocks_y; ++by) {
      for (int bx = 0; bx < blocks_x; ++bx) {
        Part::Block& made = part.blocks[std::size_t(by) * std::size_t(blocks_x) + std::size_t(bx)];
        std::array<std::uint8_t, 5> key{};
        if (lod) {
          const auto side = [&](int nx, int ny) {
            const std::optional<glm::ivec2> n = finer_neighbour(bx, by, nx, ny);
            return n ? std::uint8_t(level_at(n->x, n->y)) : Part::Block::kNoNeighbour;
          };
          key = {std::uint8_t(level_at(bx, by)), side(bx - 1, by), side(bx + 1, by),
                 side(bx, by - 1), side(bx, by + 1)};
        }
        if (!made.made || made.key != key) {
          make_block(bx, by, made);
          made.made = true;
          made.key = key;
          ++blocks_made_;
        }
        for (const std::uint32_t node : made.looked_at) {
          if (vertex[node] != ~0u) continue;
          vertex[node] = std::uint32_t(scene.positions.size());
          const std::size_t k = part.pixel_of_node(node);
          const int x = int(node % std::uint32_t(W + 1)), y = int(node / std::uint32_t(W + 1));
          scene.positions.push_back(glm::vec3(part.p_image[k]));
          scene.normals.push_back(glm::normalize(part.normal[k]));
          scene.uvs.push_back({float((x + 0.5) / W), float((y + 0.5) / H)});
        }
        for (const std::array<std::uint32_t, 3>& tri : made.triangles)
          for (const std::uint32_t node : tri) scene.indices.push_back(vertex[node]);
        mesh.source_id.insert(mesh.source_id.end(), made.source_id.begin(), made.source_id.end());
        mesh.dropped_triangles += made.dropped;
      }
    }
    primitive.index_count = std::uint32_t(scene.indices.size()) - primitive.first_index;
    Material material;
    material.name = "depth image " + part.name;
    material.texture = int(scene.images.size());
    material.repeat = wraps;
    scene.images.push_back(part.texture);
    scene.materials.push_back(material);
    Object object;
    object.name = part.name;
    object.T_world_object = glm::mat4(T_world_image_);
    object.first_primitive = std::uint32_t(scene.primitives.size());
    object.primitive_count = 1;
    scene.primitives.push_back(primitive);
    scene.objects.push_back(object);
  }
  SceneCamera eye;
  eye.name = kDepthImageEyeCamera;
  eye.T_world_camera = T_world_image_;
  scene.cameras.push_back(eye);
  scene.update_bounds();
  return mesh;
}

DepthMesh depth_image_mesh(const DepthImage& image, const DepthMeshOptions& options) {
  DepthMeshBuilder builder(image, options);
  DepthLodLevels levels;
  if (options.lod_angle_rad > 0)
    levels = options.lod_levels
                 ? *options.lod_levels
                 : DepthLodChooser(image, options)
                       .levels(options.lod_eye_world ? *options.lod_eye_world
                                                     : glm::dvec3(image.T_world_image[3]));
  return builder.build(levels);
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
