// MPCDI containers: zip members, import into facet warps and blend maps, export.
#include "facet/interop/mpcdi.hpp"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <zip.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "facet/interop/inverse_grid.hpp"
#include "facet/interop/pfm.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/footprint.hpp"
#include "facet/projection/input_file.hpp"
#include "facet/projection/screen.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "image_map.hpp"
#include "json_fields.hpp"

namespace facet::interop {
namespace {

constexpr std::uint64_t kMaxMemberBytes = std::uint64_t(256) << 20;

struct ZipCloser {
  void operator()(zip_t* archive) const { zip_discard(archive); }
};

// ---- reading -----------------------------------------------------------------------------------

const std::string& member(const MpcdiFiles& files, const std::string& name,
                          const std::string& source, const std::string& field) {
  if (auto found = files.find(name); found != files.end()) return found->second;
  // Some writers store members in a folder but name them without it (or the other way round).
  const std::string base = std::filesystem::path(name).filename().string();
  for (const auto& [path, bytes] : files) {
    if (std::filesystem::path(path).filename().string() == base) return bytes;
  }
  throw InputError(source, field, "expected a member named \"" + name + "\" in the container");
}

// Fraction of complete cells of a node grid whose image keeps the grid's orientation with a
// non-negligible area: 1 for a good map, near 0 for a mirrored or collapsed one.
double orientation_score(const std::vector<glm::dvec2>& positions, glm::ivec2 size) {
  int good = 0, complete = 0;
  const double min_area = 1e-3 / (double(size.x - 1) * double(size.y - 1));
  for (int j = 0; j + 1 < size.y; ++j) {
    for (int i = 0; i + 1 < size.x; ++i) {
      const glm::dvec2 a = positions[std::size_t(j) * size.x + i];
      const glm::dvec2 b = positions[std::size_t(j) * size.x + i + 1];
      const glm::dvec2 c = positions[std::size_t(j + 1) * size.x + i];
      const glm::dvec2 d = positions[std::size_t(j + 1) * size.x + i + 1];
      if (!std::isfinite(a.x + a.y + b.x + b.y + c.x + c.y + d.x + d.y)) continue;
      ++complete;
      const auto cross = [](glm::dvec2 u, glm::dvec2 v) { return u.x * v.y - u.y * v.x; };
      if (cross(b - a, c - a) > min_area && cross(c - d, b - d) > min_area) ++good;
    }
  }
  return complete ? double(good) / complete : 0.0;
}

// facet's export continues each warp one PFM node past its coverage (node_directions) and lists
// those nodes in facet.json, so that the import can pin the forward cells across the coverage's
// edge without taking them as shown. Empty when the hint has no valid list.
constexpr int kContinuedRings = 1;
std::vector<bool> shown_from_hint(const nlohmann::json* hint, glm::ivec2 size) {
  if (!hint || !hint->contains("continued_nodes") || !(*hint)["continued_nodes"].is_array()) {
    return {};
  }
  std::vector<bool> shown(std::size_t(size.x) * size.y, true);
  for (const nlohmann::json& k : (*hint)["continued_nodes"]) {
    if (!k.is_number_unsigned() || k.get<std::uint64_t>() >= shown.size()) return {};
    shown[k.get<std::size_t>()] = false;
  }
  return shown;
}

struct RegionWarpInput {
  const PfmImage* pfm;
  std::vector<bool> shown;  // InverseGrid::shown
  BaseProjection base;
  glm::dmat3 R{1.0};
  glm::ivec2 output_size;
  glm::ivec2 warp_grid;
};

Warp region_warp(const RegionWarpInput& in, MpcdiWarpValues values, const std::string& source) {
  const PfmImage& pfm = *in.pfm;
  const glm::ivec2 size{pfm.width, pfm.height};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<glm::dvec2> absolute(std::size_t(size.x) * size.y), offset_output(absolute.size());
  for (int j = 0; j < size.y; ++j) {
    for (int i = 0; i < size.x; ++i) {
      const std::size_t k = std::size_t(j) * size.x + i;
      const double x = pfm.at(i, j, 0), y = pfm.at(i, j, 1);
      const bool ok = std::isfinite(x) && std::isfinite(y);
      const glm::dvec2 node{double(i) / (size.x - 1), double(j) / (size.y - 1)};
      absolute[k] = ok ? glm::dvec2(x, y) : glm::dvec2(nan);
      // The offset form adds (dx, dy) to the node's position with y up.
      offset_output[k] = ok ? node + glm::dvec2(x, -y) : glm::dvec2(nan);
    }
  }
  if (values == MpcdiWarpValues::automatic) {
    const double absolute_score = orientation_score(absolute, size);
    const double offset_score = orientation_score(offset_output, size);
    // A clean map keeps the orientation of (nearly) every cell under one reading only; when
    // both readings pass, the clearly better one wins.
    const bool absolute_ok =
        absolute_score >= 0.9 && absolute_score > offset_score + 0.05 - (offset_score < 0.9);
    const bool offset_ok =
        offset_score >= 0.9 && offset_score > absolute_score + 0.05 - (absolute_score < 0.9);
    if (absolute_ok == offset_ok) {
      throw InputError(source, OptionName{"values"},
                       "expected a warp that reads as either absolute positions or offsets "
                       "(cells keeping their orientation: absolute " +
                           std::to_string(absolute_score) + ", offset " +
                           std::to_string(offset_score) + "); say which it is");
    }
    values = absolute_ok ? MpcdiWarpValues::absolute : MpcdiWarpValues::offset;
  }
  if (values == MpcdiWarpValues::absolute) {
    InverseGrid grid;
    grid.grid_size = size;
    grid.st = std::move(absolute);
    grid.shown = in.shown;
    return warp_from_inverse_grid(grid, in.base, in.R, in.output_size, in.warp_grid, source);
  }
  // Offset form: the PFM grid is already a forward map over the base image.
  std::vector<glm::dvec2> offsets(offset_output.size());
  for (int j = 0; j < size.y; ++j) {
    for (int i = 0; i < size.x; ++i) {
      const std::size_t k = std::size_t(j) * size.x + i;
      const glm::dvec2 node{double(i) / (size.x - 1), double(j) / (size.y - 1)};
      offsets[k] = (offset_output[k] - node) * glm::dvec2(in.output_size);
    }
  }
  const std::vector<bool> covered = fill_missing(offsets, size, source);
  Warp warp;
  warp.base = in.base;
  warp.R_eye_base = in.R;
  warp.output_size = in.output_size;
  warp.grid_size = size;
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    warp.offset_px.push_back(glm::vec2(offsets[k]));
    warp.coverage.push_back(covered[k] ? 1.0f : 0.0f);
  }
  warp.validate(source);
  return warp;
}

// ---- writing -----------------------------------------------------------------------------------

// ---- profile a3
// ----------------------------------------------------------------------------------

// facet.json's record of a warp's base and rotation (rows, as in every facet file), so that an a3
// round trip lands on the same base image (the a3 PFM itself only holds screen points).
nlohmann::json base_hint(const BaseProjection& base, const glm::dmat3& R_eye_base) {
  nlohmann::json hint = {{"kind", to_string(base.kind)}};
  json_fields::put_base_parameters(base, hint);
  hint["rotation"] = json_fields::from_dmat3(R_eye_base);
  return hint;
}

// The base a facet.json hint records, or nullopt when it is missing or not usable (the import then
// chooses its own base; facet.json is advisory and never an error).
std::optional<BaseCover> base_from_hint(const nlohmann::json* hint) {
  if (!hint || !hint->contains("base") || !(*hint)["base"].is_object()) return std::nullopt;
  const nlohmann::json& json = (*hint)["base"];
  try {
    BaseCover cover;
    cover.base = json_fields::to_base_parameters(
        json, base_kind_from_string(json.at("kind").get<std::string>()),
        json_fields::FieldPath("facet.json", "base"));
    cover.base.validate();
    if (json.contains("rotation")) {
      cover.R_eye_base =
          json_fields::to_dmat3(json["rotation"], json_fields::FieldPath("facet.json"));
    } else {
      // Containers written before the rows convention stored the columns.
      cover.R_eye_base = glm::transpose(
          json_fields::to_dmat3(json.at("rotation_columns"), json_fields::FieldPath("facet.json")));
    }
    // Only a proper rotation is worth trusting.
    const glm::dmat3 should_be_identity = glm::transpose(cover.R_eye_base) * cover.R_eye_base;
    for (int c = 0; c < 3; ++c) {
      if (!(glm::length(should_be_identity[c] - glm::dmat3(1.0)[c]) < 1e-6)) return std::nullopt;
    }
    if (!(glm::determinant(cover.R_eye_base) > 0)) return std::nullopt;
    return cover;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// An a3 region's warp: every node's direction from the eye, expressed in a base covering them.
Warp region_warp_a3(const PfmImage& pfm, glm::dvec3 eye_file, glm::ivec2 output_size,
                    glm::ivec2 warp_grid, const nlohmann::json* hint, const std::string& source) {
  const glm::ivec2 size{pfm.width, pfm.height};
  const glm::dmat3 R_eye_file = R_eye_mpcdi3d();
  std::vector<glm::dvec3> v_eye(std::size_t(size.x) * size.y, glm::dvec3(0.0));
  std::vector<glm::dvec3> valid_directions;
  double longest = 0;
  for (int j = 0; j < size.y; ++j) {
    for (int i = 0; i < size.x; ++i) {
      const glm::dvec3 p{pfm.at(i, j, 0), pfm.at(i, j, 1), pfm.at(i, j, 2)};
      if (!std::isfinite(p.x + p.y + p.z) || p == glm::dvec3(0.0)) continue;
      const glm::dvec3 v = R_eye_file * (p - eye_file);
      longest = std::max(longest, glm::length(v));
      v_eye[std::size_t(j) * size.x + i] = v;
    }
  }
  // A point at the eye has no direction; "at" is relative to the size of the screen.
  for (glm::dvec3& v : v_eye) {
    if (!(glm::length(v) > 1e-9 * longest)) {
      v = glm::dvec3(0.0);
    } else {
      v = glm::normalize(v);
      valid_directions.push_back(v);
    }
  }
  if (valid_directions.empty()) {
    throw InputError(source, "nodes",
                     "expected at least one 3D point that is not NaN, (0, 0, 0) or the eye point");
  }
  std::optional<BaseCover> cover = base_from_hint(hint);
  if (!cover) {
    // Keep the projector's up (its image's top edge) towards t = 0, so that offsets stay small.
    glm::dvec3 up{0.0};
    for (int i = 0; i < size.x; ++i) {
      const glm::dvec3 top = v_eye[std::size_t(i)];
      const glm::dvec3 bottom = v_eye[std::size_t(size.y - 1) * size.x + i];
      if (top != glm::dvec3(0.0) && bottom != glm::dvec3(0.0)) up += top - bottom;
    }
    CoverOptions options;
    if (glm::length(up) > 1e-9) options.up_eye = glm::normalize(up);
    cover = cover_directions(valid_directions, options);
  }
  const glm::dmat3 R_base_eye = glm::transpose(cover->R_eye_base);
  InverseGrid grid;
  grid.grid_size = size;
  grid.shown = shown_from_hint(hint, size);
  grid.st.assign(v_eye.size(), glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  for (int j = 0; j < size.y; ++j) {
    // Wrapping bases pick the branch next to the row's previous node, so that rows stay
    // continuous across the seam.
    double s_hint = std::numeric_limits<double>::quiet_NaN();
    for (int i = 0; i < size.x; ++i) {
      const std::size_t k = std::size_t(j) * size.x + i;
      if (v_eye[k] == glm::dvec3(0.0)) continue;
      if (auto st = cover->base.st_from_direction(R_base_eye * v_eye[k], s_hint)) {
        grid.st[k] = *st;
        s_hint = st->x;
      }
    }
  }
  return warp_from_inverse_grid(grid, cover->base, cover->R_eye_base, output_size, warp_grid,
                                source);
}

}  // namespace

MpcdiFiles read_zip(std::string_view bytes, const std::string& source) {
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* zip_source = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
  if (!zip_source) {
    zip_error_fini(&error);
    throw InputError(source, "", "cannot read the container");
  }
  std::unique_ptr<zip_t, ZipCloser> archive(zip_open_from_source(zip_source, ZIP_RDONLY, &error));
  if (!archive) {
    zip_source_free(zip_source);
    const std::string reason = zip_error_strerror(&error);
    zip_error_fini(&error);
    throw InputError(source, "", "expected a zip container (MPCDI): " + reason);
  }
  zip_error_fini(&error);
  MpcdiFiles files;
  const zip_int64_t count = zip_get_num_entries(archive.get(), 0);
  for (zip_int64_t index = 0; index < count; ++index) {
    zip_stat_t stat;
    if (zip_stat_index(archive.get(), zip_uint64_t(index), 0, &stat) != 0 ||
        !(stat.valid & ZIP_STAT_NAME) || !(stat.valid & ZIP_STAT_SIZE)) {
      throw InputError(source, "member " + std::to_string(index), "expected a readable zip entry");
    }
    const std::string name = stat.name;
    if (!name.empty() && name.back() == '/') continue;  // a folder
    if (stat.size > kMaxMemberBytes) {
      throw InputError(source, name, "expected a member of at most 256 MiB");
    }
    zip_file_t* file = zip_fopen_index(archive.get(), zip_uint64_t(index), 0);
    if (!file)
      throw InputError(
          source, name,
          "expected a member that can be opened (unsupported compression or encryption?)");
    std::string data(std::size_t(stat.size), '\0');
    const zip_int64_t read = zip_fread(file, data.data(), stat.size);
    zip_fclose(file);
    if (read < 0 || zip_uint64_t(read) != stat.size) {
      throw InputError(source, name, "expected a member that decompresses to its recorded size");
    }
    files[name] = std::move(data);
  }
  return files;
}

MpcdiFiles read_zip_file(const std::filesystem::path& path) {
  const Activity activity("reading the MPCDI container " + path.string());
  require_regular_file(path);
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw InputError(path.string(), "", "cannot open the file");
  std::ostringstream bytes;
  bytes << stream.rdbuf();
  return read_zip(bytes.str(), path.string());
}

void write_zip_file(const std::filesystem::path& path, const MpcdiFiles& files) {
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    int code = 0;
    zip_t* archive = zip_open(temporary.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &code);
    if (!archive) throw InputError(path.string(), "", "cannot create the file");
    for (const auto& [name, bytes] : files) {
      zip_source_t* data = zip_source_buffer(archive, bytes.data(), bytes.size(), 0);
      if (!data ||
          zip_file_add(archive, name.c_str(), data, ZIP_FL_OVERWRITE | ZIP_FL_ENC_UTF_8) < 0) {
        if (data) zip_source_free(data);
        zip_discard(archive);
        throw InputError(path.string(), name, "cannot add this member");
      }
    }
    if (zip_close(archive) != 0) {
      const std::string reason = zip_strerror(archive);
      zip_discard(archive);
      throw InputError(path.string(), "", "cannot write the file: " + reason);
    }
  });
}

ImportedDisplay import_mpcdi(const MpcdiFiles& files, const std::string& source,
                             const MpcdiImportOptions& options) {
  // The description: mpcdi.xml, else the only .xml member.
  std::string xml_name;
  if (files.count("mpcdi.xml")) {
    xml_name = "mpcdi.xml";
  } else {
    for (const auto& [name, bytes] : files) {
      if (name.size() > 4 && name.compare(name.size() - 4, 4, ".xml") == 0) {
        if (!xml_name.empty()) {
          throw InputError(source, "mpcdi.xml",
                           "expected mpcdi.xml, or a single .xml member (found several)");
        }
        xml_name = name;
      }
    }
  }
  if (xml_name.empty()) throw InputError(source, "mpcdi.xml", "expected this member");
  const std::string xml_source = source + ":" + xml_name;
  const MpcdiDocument document = parse_mpcdi_xml(files.at(xml_name), xml_source);
  // The sampling facet's own export recorded, if this container came from facet.
  nlohmann::json hints;
  if (auto found = files.find("facet.json"); found != files.end()) {
    hints = nlohmann::json::parse(found->second, nullptr, false);
    if (hints.is_discarded() || !hints.is_object()) hints = nlohmann::json::object();
  }

  ImportedDisplay display;
  display.name = std::filesystem::path(source).stem().string();
  if (document.profile == MpcdiProfile::advanced_3d) {
    const MpcdiRegion& first = document.regions.front();
    const glm::dvec3 eye_file = options.eye.value_or(glm::dvec3(0.0));
    const std::optional<double> metres = metres_per_unit(first.unit);
    display.eye = R_eye_mpcdi3d() * eye_file * metres.value_or(1.0);
    if (!options.eye && first.origin != MpcdiOrigin::ideal_eye_point) {
      display.notes.push_back(std::string("profile a3 with originOf3DData ") +
                              to_string(first.origin) +
                              ": the eye is taken at the origin of the file's frame; give the "
                              "real eye point as the import's eye (x,y,z in the file's frame "
                              "and geometricUnit)");
    }
    if (!metres && eye_file != glm::dvec3(0.0)) {
      display.notes.push_back(
          "geometricUnit unknown: display.json's eye is the given eye point read as metres");
    }
    for (const MpcdiRegion& region : document.regions) {
      if (region.unit != first.unit) {
        throw InputError(
            xml_source, "files/fileset[region=" + region.id + "]/geometryWarpFile/geometricUnit",
            std::string("expected the same unit in every region (") + to_string(first.unit) + ")");
      }
      if (region.origin != first.origin) {
        throw InputError(xml_source,
                         "files/fileset[region=" + region.id + "]/geometryWarpFile/originOf3DData",
                         std::string("expected the same origin in every region (") +
                             to_string(first.origin) + ")");
      }
    }
  }
  for (const MpcdiRegion& region : document.regions) {
    const std::string field = "files/fileset[region=" + region.id + "]";
    const std::string& pfm_bytes =
        member(files, region.warp_path, xml_source, field + "/geometryWarpFile/path");
    const std::string pfm_source = source + ":" + region.warp_path;
    const PfmImage pfm = parse_pfm(pfm_bytes, pfm_source);
    if (pfm.channels != 3 || pfm.width < 2 || pfm.height < 2) {
      throw InputError(pfm_source, "header", "expected a three-channel PFM of at least 2×2 nodes");
    }
    RegionWarpInput in;
    in.pfm = &pfm;
    in.output_size = region.resolution;
    if (document.profile == MpcdiProfile::three_d) {
      in.base = frustum_base(*region.frustum);
      in.R = R_eye_frustum(*region.frustum);
    } else {
      const double aspect = double(region.buffer_resolution.x) / region.buffer_resolution.y;
      in.base = BaseProjection::perspective(-aspect, aspect, 1, -1);
    }
    in.warp_grid = {pfm.width, pfm.height};
    const nlohmann::json* hint = nullptr;
    if (hints.contains("regions") && hints["regions"].is_object() &&
        hints["regions"].contains(region.id)) {
      hint = &hints["regions"][region.id];
    }
    if (options.warp_grid) {
      in.warp_grid = *options.warp_grid;
    } else if (hint && hint->contains("warp_grid") && (*hint)["warp_grid"].is_array() &&
               (*hint)["warp_grid"].size() == 2 && (*hint)["warp_grid"][0].is_number_integer() &&
               (*hint)["warp_grid"][1].is_number_integer()) {
      const int gx = (*hint)["warp_grid"][0], gy = (*hint)["warp_grid"][1];
      if (gx >= 2 && gy >= 2 && gx <= 4096 && gy <= 4096) in.warp_grid = {gx, gy};
    }

    MpcdiWarpValues values = options.values;
    if (values == MpcdiWarpValues::automatic && hint && hint->contains("warp_values") &&
        (*hint)["warp_values"] == "absolute") {
      values = MpcdiWarpValues::absolute;
    }
    in.shown = shown_from_hint(hint, {pfm.width, pfm.height});
    ImportedProjector projector;
    projector.name = sanitize_name(region.id);
    if (document.profile == MpcdiProfile::advanced_3d) {
      projector.warp = region_warp_a3(pfm, options.eye.value_or(glm::dvec3(0.0)), region.resolution,
                                      in.warp_grid, hint, pfm_source);
      if (display.eye != glm::dvec3(0.0)) projector.warp.eye = display.eye;
    } else {
      projector.warp = region_warp(in, values, pfm_source);
    }
    if (region.alpha) {
      projector.blend =
          decode_image_map(member(files, region.alpha->path, xml_source, field + "/alphaMap/path"),
                           region.alpha->path, region.alpha->gamma_embedded, region.resolution,
                           source + ":" + region.alpha->path);
    }
    if (region.beta) {
      projector.black = decode_image_map(
          member(files, region.beta->path, xml_source, field + "/betaMap/path"), region.beta->path,
          region.beta->gamma_embedded, region.resolution, source + ":" + region.beta->path);
    }
    // Buffers sit left to right on the desktop, regions inside them by their extents.
    int x0 = 0;
    std::vector<int> widths;
    for (const MpcdiRegion& other : document.regions) {
      if (int(widths.size()) <= other.buffer_index) widths.resize(other.buffer_index + 1, 0);
      widths[other.buffer_index] = other.buffer_resolution.x;
    }
    for (int b = 0; b < region.buffer_index; ++b) x0 += widths[b];
    projector.output.kind = projection_io::DisplayOutput::Kind::window;
    projector.output.window = {x0 + int(std::lround(region.extent.x * region.buffer_resolution.x)),
                               int(std::lround(region.extent.y * region.buffer_resolution.y)),
                               region.resolution.x, region.resolution.y};
    display.projectors.push_back(std::move(projector));
  }
  return display;
}

MpcdiFrustum covering_frustum(const Warp& warp, const std::string& source) {
  if (warp.base.kind == BaseKind::perspective) return frustum_from_base(warp.base, warp.R_eye_base);
  // Directions of the output image's border and interior, found by exact inversion.
  const WarpInverse inverse(warp);
  std::vector<glm::dvec3> directions;
  const int n = 64;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const glm::dvec2 q{double(i) / n * warp.output_size.x, double(j) / n * warp.output_size.y};
      if (auto inverted = inverse.invert(q)) directions.push_back(inverted->v_eye);
    }
  }
  if (directions.empty()) {
    throw InputError(source, "coverage", "expected a warp that covers some output pixels");
  }
  CoverOptions cover;
  cover.max_perspective_half_angle_rad = glm::radians(80.0);
  cover.up_eye = warp.R_eye_base * glm::dvec3(0, 1, 0);
  const BaseCover covered = cover_directions(directions, cover);
  if (covered.base.kind != BaseKind::perspective) {
    throw InputError(source, "base",
                     "expected a projector footprint within 80° of its centre, so that one "
                     "perspective frustum holds it");
  }
  return frustum_from_base(covered.base, covered.R_eye_base);
}

MpcdiFiles export_mpcdi(const projection_io::DisplayConfig& display,
                        const MpcdiExportOptions& options) {
  FACET_ASSERT(options.node_spacing_px > 0);
  FACET_ASSERT(options.profile != MpcdiProfile::two_d);
  const bool a3 = options.profile == MpcdiProfile::advanced_3d;
  MpcdiDocument document;
  document.profile = options.profile;
  MpcdiFiles files;
  nlohmann::json hints = {{"format", "facet-mpcdi/1"}, {"regions", nlohmann::json::object()}};
  int buffer = 0;
  for (const projection_io::DisplayProjector& projector : display.projectors) {
    const std::string warp_path = display.resolve(projector.warp).string();
    const Warp warp = read_warp(warp_path);
    MpcdiRegion region;
    region.id = projector.name;
    region.buffer_index = buffer++;
    region.buffer_resolution = warp.output_size;
    region.resolution = warp.output_size;
    const glm::ivec2 nodes{int(std::ceil(warp.output_size.x / options.node_spacing_px)) + 1,
                           int(std::ceil(warp.output_size.y / options.node_spacing_px)) + 1};
    PfmImage pfm;
    pfm.width = nodes.x;
    pfm.height = nodes.y;
    pfm.channels = 3;
    nlohmann::json& hint = hints["regions"][projector.name];
    hint = {{"warp_grid", {warp.grid_size.x, warp.grid_size.y}}, {"pfm_nodes", {nodes.x, nodes.y}}};
    std::vector<std::size_t> continued;  // PFM nodes past the coverage, row-major
    if (a3) {
      region.unit = MpcdiUnit::m;
      region.origin = MpcdiOrigin::ideal_eye_point;
      const NodeDirections directions = node_directions(warp, nodes, kContinuedRings);
      const glm::dmat3 R_file_eye = glm::transpose(R_eye_mpcdi3d());
      const float nan = std::numeric_limits<float>::quiet_NaN();
      for (std::size_t k = 0; k < directions.v_eye.size(); ++k) {
        std::optional<glm::dvec3> p_eye;
        if (const auto& v_eye = directions.v_eye[k]) {
          if (!display.screen) {
            p_eye = *v_eye;
          } else if (auto hit = screen_hit(*display.screen, display.eye, *v_eye)) {
            p_eye = *hit - display.eye;
          }
        }
        const glm::dvec3 p = p_eye ? R_file_eye * *p_eye : glm::dvec3(nan);
        pfm.values.insert(pfm.values.end(), {float(p.x), float(p.y), float(p.z)});
        if (p_eye && !directions.shown[k]) continued.push_back(k);
      }
      hint["base"] = base_hint(warp.base, warp.R_eye_base);
    }
    const MpcdiFrustum frustum = a3 ? MpcdiFrustum{} : covering_frustum(warp, warp_path);
    if (!a3) {
      region.frustum = frustum;
      const BaseProjection base = frustum_base(frustum);
      const glm::dmat3 R_frustum_eye = glm::transpose(R_eye_frustum(frustum));
      const InverseGrid grid = inverse_grid_from_warp(
          warp, nodes,
          [&](const glm::dvec3& v_eye) { return base.st_from_direction(R_frustum_eye * v_eye); },
          kContinuedRings);
      for (std::size_t k = 0; k < grid.st.size(); ++k) {
        const glm::dvec2 st = grid.st[k];
        pfm.values.push_back(float(st.x));
        pfm.values.push_back(float(st.y));
        pfm.values.push_back(std::isfinite(st.x) ? 0.0f : std::numeric_limits<float>::quiet_NaN());
        if (std::isfinite(st.x) && !grid.shown[k]) continued.push_back(k);
      }
      hint["warp_values"] = "absolute";
    }
    hint["continued_nodes"] = continued;
    region.warp_path = projector.name + ".pfm";
    files[region.warp_path] = format_pfm(pfm);
    if (projector.blend) {
      const auto map = projection_io::read_blend_map(display.resolve(*projector.blend).string(),
                                                     warp.output_size);
      region.alpha = MpcdiMap{projector.name + "_alpha.png", 1.0, map.channels};
      files[region.alpha->path] = encode_png(map, 16);
    }
    if (projector.black) {
      const auto map = projection_io::read_blend_map(display.resolve(*projector.black).string(),
                                                     warp.output_size);
      region.beta = MpcdiMap{projector.name + "_beta.png", 1.0, map.channels};
      files[region.beta->path] = encode_png(map, 16);
    }
    document.regions.push_back(region);
  }
  files["mpcdi.xml"] = format_mpcdi_xml(document);
  files["facet.json"] = hints.dump(2);
  return files;
}

}  // namespace facet::interop
