// MPCDI XML: parsing and writing the container's description, and the frustum conventions.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <pugixml.hpp>
#include <sstream>

#include "facet/interop/mpcdi.hpp"
#include "facet/projection/errors.hpp"
#include "xml_document.hpp"

namespace facet::interop {
namespace {

glm::dmat3 rotation_about(glm::dvec3 axis, double degrees) {
  return glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(degrees), axis));
}

double attribute_number(const pugi::xml_node& node, const char* name, const std::string& source,
                        const std::string& path) {
  const pugi::xml_attribute attribute = node.attribute(name);
  if (!attribute) throw InputError(source, path + "@" + name, "expected this attribute");
  return parse_number(attribute.value(), source, path + "@" + name);
}

int attribute_resolution(const pugi::xml_node& node, const char* name, const std::string& source,
                         const std::string& path) {
  const double value = attribute_number(node, name, source, path);
  if (value < 1 || value > 65536 || value != std::floor(value)) {
    throw InputError(source, path + "@" + name, "expected a whole number of pixels in [1, 65536]");
  }
  return int(value);
}

double child_number(const pugi::xml_node& node, const char* name, const std::string& source,
                    const std::string& path) {
  const pugi::xml_node child = node.child(name);
  if (!child) throw InputError(source, path + "/" + name, "expected this element");
  return parse_number(child.text().get(), source, path + "/" + name);
}

std::optional<MpcdiMap> read_map(const pugi::xml_node& fileset, const char* name,
                                 const std::string& source, const std::string& path) {
  const pugi::xml_node node = fileset.child(name);
  if (!node) return std::nullopt;
  const std::string file = node.child("path").text().get();
  // Files from some tools carry an empty <alphaMap/>: no map.
  if (file.empty()) return std::nullopt;
  MpcdiMap map;
  map.path = file;
  if (node.child("gammaEmbedded")) {
    map.gamma_embedded = child_number(node, "gammaEmbedded", source, path + "/" + name);
    if (map.gamma_embedded <= 0 || map.gamma_embedded > 10) {
      throw InputError(source, path + "/" + name + "/gammaEmbedded", "expected a gamma in (0, 10]");
    }
  }
  return map;
}

std::string format_number(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// The standard's names. The reference MPCDI library writes "unkown"; it reads as unknown too.
constexpr std::pair<const char*, MpcdiUnit> kUnits[] = {
    {"mm", MpcdiUnit::mm}, {"cm", MpcdiUnit::cm},          {"dm", MpcdiUnit::dm},
    {"m", MpcdiUnit::m},   {"in", MpcdiUnit::in},          {"ft", MpcdiUnit::ft},
    {"yd", MpcdiUnit::yd}, {"unknown", MpcdiUnit::unknown}};
constexpr std::pair<const char*, MpcdiOrigin> kOrigins[] = {
    {"centerOfMass", MpcdiOrigin::center_of_mass},
    {"idealEyePoint", MpcdiOrigin::ideal_eye_point},
    {"floorCenter", MpcdiOrigin::floor_center},
    {"unknown", MpcdiOrigin::unknown}};

template <typename Enum, std::size_t N>
Enum enum_child(const pugi::xml_node& node, const char* name,
                const std::pair<const char*, Enum> (&names)[N], Enum unknown,
                const std::string& source, const std::string& path) {
  const pugi::xml_node child = node.child(name);
  if (!child) return unknown;
  std::string text = child.text().get();
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!text.empty() && blank(text.back())) text.pop_back();
  while (!text.empty() && blank(text.front())) text.erase(text.begin());
  if (text == "unkown") return unknown;
  std::string expected;
  for (const auto& [word, value] : names) {
    if (text == word) return value;
    expected += std::string(expected.empty() ? "" : ", ") + word;
  }
  throw InputError(source, path + "/" + name,
                   "expected one of " + expected + ", found \"" + text.substr(0, 40) + "\"");
}

template <typename Enum, std::size_t N>
const char* enum_name(Enum value, const std::pair<const char*, Enum> (&names)[N]) {
  for (const auto& [word, entry] : names) {
    if (entry == value) return word;
  }
  return "unknown";
}

}  // namespace

std::optional<double> metres_per_unit(MpcdiUnit unit) {
  switch (unit) {
    case MpcdiUnit::mm:
      return 0.001;
    case MpcdiUnit::cm:
      return 0.01;
    case MpcdiUnit::dm:
      return 0.1;
    case MpcdiUnit::m:
      return 1.0;
    case MpcdiUnit::in:
      return 0.0254;
    case MpcdiUnit::ft:
      return 0.3048;
    case MpcdiUnit::yd:
      return 0.9144;
    case MpcdiUnit::unknown:
      break;
  }
  return std::nullopt;
}

const char* to_string(MpcdiUnit unit) { return enum_name(unit, kUnits); }
const char* to_string(MpcdiOrigin origin) { return enum_name(origin, kOrigins); }

glm::dmat3 R_eye_mpcdi3d() { return glm::dmat3(-1, 0, 0, 0, 1, 0, 0, 0, -1); }

glm::dmat3 R_eye_frustum(const MpcdiFrustum& f) {
  return rotation_about({0, 1, 0}, -f.yaw_deg) * rotation_about({1, 0, 0}, f.pitch_deg) *
         rotation_about({0, 0, 1}, -f.roll_deg);
}

BaseProjection frustum_base(const MpcdiFrustum& f) {
  return BaseProjection::perspective(
      std::tan(glm::radians(f.left_deg)), std::tan(glm::radians(f.right_deg)),
      std::tan(glm::radians(f.up_deg)), std::tan(glm::radians(f.down_deg)));
}

MpcdiFrustum frustum_from_base(const BaseProjection& perspective, const glm::dmat3& R) {
  FACET_ASSERT(perspective.kind == BaseKind::perspective);
  MpcdiFrustum f;
  const glm::dvec3 forward = R * glm::dvec3(0, 0, -1);
  f.pitch_deg = glm::degrees(std::asin(std::clamp(forward.y, -1.0, 1.0)));
  f.yaw_deg = glm::degrees(std::atan2(forward.x, -forward.z));
  // What is left after yaw and pitch is the roll about the view axis.
  const glm::dmat3 rest = glm::transpose(rotation_about({0, 1, 0}, -f.yaw_deg) *
                                         rotation_about({1, 0, 0}, f.pitch_deg)) *
                          R;
  f.roll_deg = -glm::degrees(std::atan2(rest[0][1], rest[0][0]));
  f.left_deg = glm::degrees(std::atan(perspective.tan_extent[0]));
  f.right_deg = glm::degrees(std::atan(perspective.tan_extent[1]));
  f.up_deg = glm::degrees(std::atan(perspective.tan_extent[2]));
  f.down_deg = glm::degrees(std::atan(perspective.tan_extent[3]));
  return f;
}

MpcdiDocument parse_mpcdi_xml(std::string_view xml, const std::string& source) {
  pugi::xml_document document;
  load_xml(document, xml, source);
  const pugi::xml_node root = document.child("MPCDI");
  if (!root) throw InputError(source, "MPCDI", "expected the root element <MPCDI>");
  MpcdiDocument result;
  const std::string profile = root.attribute("profile").value();
  if (profile == "2d") {
    result.profile = MpcdiProfile::two_d;
  } else if (profile == "3d") {
    result.profile = MpcdiProfile::three_d;
  } else if (profile == "a3") {
    result.profile = MpcdiProfile::advanced_3d;
  } else {
    throw InputError(source, "MPCDI@profile",
                     "expected \"2d\", \"3d\" or \"a3\", found \"" + profile.substr(0, 40) + "\"");
  }
  result.version = root.attribute("version").value();

  std::map<std::string, std::size_t> region_index;
  int buffer_index = 0;
  const pugi::xml_node display = root.child("display");
  if (!display) throw InputError(source, "MPCDI/display", "expected this element");
  for (const pugi::xml_node& buffer : display.children("buffer")) {
    const std::string buffer_path = "display/buffer[" + std::to_string(buffer_index) + "]";
    const glm::ivec2 buffer_resolution{
        attribute_resolution(buffer, "xResolution", source, buffer_path),
        attribute_resolution(buffer, "yResolution", source, buffer_path)};
    int index = 0;
    for (const pugi::xml_node& node : buffer.children("region")) {
      const std::string path = buffer_path + "/region[" + std::to_string(index++) + "]";
      MpcdiRegion region;
      region.id = node.attribute("id").value();
      if (region.id.empty()) throw InputError(source, path + "@id", "expected a non-empty id");
      if (region_index.count(region.id)) {
        throw InputError(source, path + "@id",
                         "expected a unique id, \"" + region.id + "\" repeats");
      }
      region.buffer_index = buffer_index;
      region.buffer_resolution = buffer_resolution;
      region.extent = {attribute_number(node, "x", source, path),
                       attribute_number(node, "y", source, path),
                       attribute_number(node, "xSize", source, path),
                       attribute_number(node, "ySize", source, path)};
      const auto& e = region.extent;
      if (e.x < 0 || e.y < 0 || e.z <= 0 || e.w <= 0 || e.x + e.z > 1 + 1e-6 ||
          e.y + e.w > 1 + 1e-6) {
        throw InputError(source, path + "@x,y,xSize,ySize",
                         "expected normalised extents inside the buffer: x, y >= 0, sizes > 0, "
                         "x + xSize <= 1, y + ySize <= 1");
      }
      region.resolution = {attribute_resolution(node, "xResolution", source, path),
                           attribute_resolution(node, "yResolution", source, path)};
      if (const pugi::xml_node frustum = node.child("frustum")) {
        const std::string fpath = path + "/frustum";
        MpcdiFrustum f;
        f.yaw_deg = child_number(frustum, "yaw", source, fpath);
        f.pitch_deg = child_number(frustum, "pitch", source, fpath);
        f.roll_deg = child_number(frustum, "roll", source, fpath);
        f.left_deg = child_number(frustum, "leftAngle", source, fpath);
        f.right_deg = child_number(frustum, "rightAngle", source, fpath);
        f.up_deg = child_number(frustum, "upAngle", source, fpath);
        f.down_deg = child_number(frustum, "downAngle", source, fpath);
        for (double angle : {f.left_deg, f.right_deg, f.up_deg, f.down_deg}) {
          if (!(std::abs(angle) < 89.99)) {
            throw InputError(source, fpath, "expected edge angles inside (-90°, 90°)");
          }
        }
        // Any turn is within one either way; beyond, the degrees lose the digits a pose needs.
        for (const auto& [name, angle] :
             {std::pair{"yaw", f.yaw_deg}, std::pair{"pitch", f.pitch_deg},
              std::pair{"roll", f.roll_deg}}) {
          if (!(std::abs(angle) <= 360)) {
            throw InputError(source, fpath + "/" + name, "expected degrees within [-360, 360]");
          }
        }
        if (!(f.left_deg < f.right_deg) || !(f.down_deg < f.up_deg)) {
          throw InputError(source, fpath,
                           "expected leftAngle < rightAngle and downAngle < upAngle");
        }
        region.frustum = f;
      } else if (result.profile == MpcdiProfile::three_d) {
        throw InputError(source, path + "/frustum", "expected a frustum for profile 3d");
      }
      region_index[region.id] = result.regions.size();
      result.regions.push_back(region);
    }
    ++buffer_index;
  }
  if (result.regions.empty()) {
    throw InputError(source, "display/buffer/region", "expected at least one region");
  }

  const pugi::xml_node files = root.child("files");
  int fileset_index = 0;
  for (const pugi::xml_node& fileset : files.children("fileset")) {
    const std::string path = "files/fileset[" + std::to_string(fileset_index++) + "]";
    const std::string id = fileset.attribute("region").value();
    const auto found = region_index.find(id);
    if (found == region_index.end()) {
      throw InputError(source, path + "@region",
                       "expected the id of a region, found \"" + id.substr(0, 40) + "\"");
    }
    MpcdiRegion& region = result.regions[found->second];
    const pugi::xml_node warp_node = fileset.child("geometryWarpFile");
    const std::string warp = warp_node.child("path").text().get();
    if (!warp.empty()) region.warp_path = warp;
    if (result.profile == MpcdiProfile::advanced_3d) {
      const std::string warp_path = "files/fileset[region=" + id + "]/geometryWarpFile";
      region.unit =
          enum_child(warp_node, "geometricUnit", kUnits, MpcdiUnit::unknown, source, warp_path);
      region.origin = enum_child(warp_node, "originOf3DData", kOrigins, MpcdiOrigin::unknown,
                                 source, warp_path);
    }
    if (auto alpha = read_map(fileset, "alphaMap", source, path)) region.alpha = alpha;
    if (auto beta = read_map(fileset, "betaMap", source, path)) region.beta = beta;
  }
  for (const MpcdiRegion& region : result.regions) {
    if (region.warp_path.empty()) {
      throw InputError(source, "files/fileset[region=" + region.id + "]/geometryWarpFile/path",
                       "expected a geometry warp file for every region");
    }
  }
  return result;
}

std::string format_mpcdi_xml(const MpcdiDocument& document) {
  pugi::xml_document xml;
  pugi::xml_node declaration = xml.append_child(pugi::node_declaration);
  declaration.append_attribute("version") = "1.0";
  declaration.append_attribute("encoding") = "utf-8";
  pugi::xml_node root = xml.append_child("MPCDI");
  root.append_attribute("profile") = document.profile == MpcdiProfile::two_d     ? "2d"
                                     : document.profile == MpcdiProfile::three_d ? "3d"
                                                                                 : "a3";
  root.append_attribute("geometry") = "1";
  root.append_attribute("color") = "1";
  root.append_attribute("version") = document.version.c_str();
  pugi::xml_node display = root.append_child("display");
  pugi::xml_node files = root.append_child("files");
  int current_buffer = -1;
  pugi::xml_node buffer;
  for (const MpcdiRegion& region : document.regions) {
    if (region.buffer_index != current_buffer) {
      current_buffer = region.buffer_index;
      buffer = display.append_child("buffer");
      buffer.append_attribute("id") = ("buffer" + std::to_string(current_buffer)).c_str();
      buffer.append_attribute("xResolution") = region.buffer_resolution.x;
      buffer.append_attribute("yResolution") = region.buffer_resolution.y;
    }
    pugi::xml_node node = buffer.append_child("region");
    node.append_attribute("id") = region.id.c_str();
    node.append_attribute("x") = format_number(region.extent.x).c_str();
    node.append_attribute("y") = format_number(region.extent.y).c_str();
    node.append_attribute("xSize") = format_number(region.extent.z).c_str();
    node.append_attribute("ySize") = format_number(region.extent.w).c_str();
    node.append_attribute("xResolution") = region.resolution.x;
    node.append_attribute("yResolution") = region.resolution.y;
    if (region.frustum) {
      pugi::xml_node f = node.append_child("frustum");
      const auto put = [&](const char* name, double value) {
        f.append_child(name).text().set(format_number(value).c_str());
      };
      put("yaw", region.frustum->yaw_deg);
      put("pitch", region.frustum->pitch_deg);
      put("roll", region.frustum->roll_deg);
      put("rightAngle", region.frustum->right_deg);
      put("leftAngle", region.frustum->left_deg);
      put("upAngle", region.frustum->up_deg);
      put("downAngle", region.frustum->down_deg);
    }
    pugi::xml_node fileset = files.append_child("fileset");
    fileset.append_attribute("region") = region.id.c_str();
    pugi::xml_node warp = fileset.append_child("geometryWarpFile");
    warp.append_child("path").text().set(region.warp_path.c_str());
    if (document.profile == MpcdiProfile::advanced_3d) {
      warp.append_child("geometricUnit").text().set(to_string(region.unit));
    }
    warp.append_child("interpolation").text().set("linear");
    if (document.profile == MpcdiProfile::advanced_3d) {
      warp.append_child("originOf3DData").text().set(to_string(region.origin));
    }
    const auto put_map = [&](const char* name, const std::optional<MpcdiMap>& map) {
      if (!map) return;
      pugi::xml_node node_map = fileset.append_child(name);
      node_map.append_child("path").text().set(map->path.c_str());
      node_map.append_child("componentDepth").text().set(map->components);
      node_map.append_child("bitDepth").text().set("16");
      if (std::string(name) == "alphaMap") {
        node_map.append_child("gammaEmbedded")
            .text()
            .set(format_number(map->gamma_embedded).c_str());
      }
    };
    put_map("alphaMap", region.alpha);
    put_map("betaMap", region.beta);
  }
  std::ostringstream out;
  xml.save(out, "  ");
  return out.str();
}

}  // namespace facet::interop
