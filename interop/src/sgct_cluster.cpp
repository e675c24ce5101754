// SGCT cluster configurations with SCISS or SimCAD meshes and masks: import into a display, and
// a display exported as one.
#include "facet/interop/sgct_cluster.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <pugixml.hpp>
#include <set>
#include <sstream>

#include "facet/interop/inverse_grid.hpp"
#include "facet/interop/mpcdi.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "image_map.hpp"
#include "xml_document.hpp"

namespace facet::interop {
namespace {

std::string read_file(const std::filesystem::path& path, const std::string& source,
                      const std::string& field) {
  require_regular_file(path);
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw InputError(source, field, "cannot open \"" + path.string() + "\"");
  std::ostringstream bytes;
  bytes << stream.rdbuf();
  return bytes.str();
}

double number_attribute(const pugi::xml_node& node, const char* name, double fallback,
                        const std::string& source, const std::string& path) {
  const pugi::xml_attribute attribute = node.attribute(name);
  return attribute ? parse_number(attribute.value(), source, path + "@" + name) : fallback;
}

// The first of `names` the element has, or "".
std::string attribute_of(const pugi::xml_node& node, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    if (const pugi::xml_attribute a = node.attribute(name)) return a.value();
  }
  return {};
}

// A path as written, else relative to the configuration's folder, else its file name there
// (Windows separators included).
std::filesystem::path resolve(const std::string& written, const std::filesystem::path& folder,
                              const std::string& source, const std::string& field,
                              std::vector<std::string>& notes) {
  const std::filesystem::path as_written(written);
  if (as_written.is_absolute() && std::filesystem::is_regular_file(as_written)) return as_written;
  if (std::filesystem::is_regular_file(folder / as_written)) return folder / as_written;
  const std::size_t slash = written.find_last_of("/\\");
  const std::string name = slash == std::string::npos ? written : written.substr(slash + 1);
  if (!name.empty() && std::filesystem::is_regular_file(folder / name)) {
    notes.push_back(field + " \"" + written + "\" not found; took \"" + name +
                    "\" next to the configuration");
    return folder / name;
  }
  throw InputError(source, field,
                   "expected an existing file; neither \"" + written + "\" nor \"" + name +
                       "\" next to the configuration exists");
}

// A mesh header (no vertices) holding `frustum`: its edge angles, and its rotation as the
// quaternion of R_eye_frustum.
SgcMesh sgc_header(const MpcdiFrustum& frustum) {
  SgcMesh header;
  header.q_world_frustum = glm::normalize(glm::quat_cast(R_eye_frustum(frustum)));
  header.up_deg = frustum.up_deg, header.down_deg = frustum.down_deg;
  header.left_deg = frustum.left_deg, header.right_deg = frustum.right_deg;
  return header;
}

// The frustum of a viewport's <PlanarProjection>: <FOV left right up down> (degrees, each positive
// outwards from the axis, so down="-7.7" puts the bottom edge above it) and <Orientation> as
// heading, pitch, roll (degrees, R = Ry(−heading)·Rx(pitch)·Rz(−roll), as facet reads MPCDI
// frusta) or as a quaternion x, y, z, w.
SgcMesh planar_projection(const pugi::xml_node& viewport, const std::string& source,
                          const std::string& path) {
  const pugi::xml_node projection = viewport.child("PlanarProjection");
  const std::string projection_path = path + "/PlanarProjection";
  if (!projection) {
    throw InputError(source, projection_path,
                     "expected this element: a .simcad mesh holds no frustum");
  }
  const pugi::xml_node fov = projection.child("FOV");
  const std::string fov_path = projection_path + "/FOV";
  if (!fov) throw InputError(source, fov_path, "expected this element");
  const auto required = [&](const pugi::xml_node& node, const char* name, const std::string& at) {
    if (!node.attribute(name)) throw InputError(source, at + "@" + name, "expected this attribute");
    return number_attribute(node, name, 0, source, at);
  };
  MpcdiFrustum frustum;
  frustum.left_deg = -required(fov, "left", fov_path);
  frustum.right_deg = required(fov, "right", fov_path);
  frustum.up_deg = required(fov, "up", fov_path);
  frustum.down_deg = -required(fov, "down", fov_path);
  if (!(std::abs(frustum.left_deg) < 89 && std::abs(frustum.right_deg) < 89 &&
        std::abs(frustum.up_deg) < 89 && std::abs(frustum.down_deg) < 89 &&
        frustum.left_deg < frustum.right_deg && frustum.down_deg < frustum.up_deg)) {
    throw InputError(source, fov_path,
                     "expected left, right, up and down within (−89°, 89°) with the left edge "
                     "left of the right one and the bottom edge below the top one");
  }
  const pugi::xml_node orientation = projection.child("Orientation");
  const std::string orientation_path = projection_path + "/Orientation";
  if (orientation && orientation.attribute("w")) {
    const glm::dquat q(
        required(orientation, "w", orientation_path), required(orientation, "x", orientation_path),
        required(orientation, "y", orientation_path), required(orientation, "z", orientation_path));
    if (!(glm::length(q) > 0.5 && glm::length(q) < 2)) {
      throw InputError(source, orientation_path, "expected a unit quaternion x, y, z, w");
    }
    SgcMesh header = sgc_header(frustum);
    header.q_world_frustum = glm::normalize(q);
    return header;
  }
  frustum.yaw_deg = number_attribute(orientation, "heading", 0, source, orientation_path);
  frustum.pitch_deg = number_attribute(orientation, "pitch", 0, source, orientation_path);
  frustum.roll_deg = number_attribute(orientation, "roll", 0, source, orientation_path);
  return sgc_header(frustum);
}

bool has_extension(const std::string& path, const std::string& extension) {
  if (path.size() < extension.size()) return false;
  std::string tail = path.substr(path.size() - extension.size());
  std::transform(tail.begin(), tail.end(), tail.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return tail == extension;
}

}  // namespace

ImportedDisplay import_sgct_cluster(const std::filesystem::path& config,
                                    const SgctImportOptions& options) {
  const std::string source = config.string();
  const std::string xml = read_file(config, source, "");
  pugi::xml_document document;
  load_xml(document, xml, source);
  const pugi::xml_node cluster = document.child("Cluster");
  if (!cluster) throw InputError(source, "Cluster", "expected the root element <Cluster>");
  const std::filesystem::path folder = config.parent_path();

  ImportedDisplay display;
  display.name = config.stem().string();
  if (const pugi::xml_node user_pos = cluster.child("User").child("Pos")) {
    for (int c = 0; c < 3; ++c) {
      const char* axis[3] = {"x", "y", "z"};
      display.eye[c] = number_attribute(user_pos, axis[c], 0, source, "User/Pos");
    }
  }
  std::set<std::string> names;
  int desktop_x = 0;
  int node_index = 0;
  for (const pugi::xml_node& node : cluster.children("Node")) {
    const std::string node_path = "Node[" + std::to_string(node_index++) + "]";
    int node_right = desktop_x;
    int window_index = 0;
    for (const pugi::xml_node& window : node.children("Window")) {
      const std::string window_path = node_path + "/Window[" + std::to_string(window_index++) + "]";
      const pugi::xml_node size_node = window.child("Size");
      const double width = number_attribute(size_node, "x", 0, source, window_path + "/Size");
      const double height = number_attribute(size_node, "y", 0, source, window_path + "/Size");
      if (!(width >= 1 && height >= 1 && width <= 65536 && height <= 65536)) {
        throw InputError(source, window_path + "/Size",
                         "expected x and y, whole pixels in [1, 65536]");
      }
      const pugi::xml_node pos_node = window.child("Pos");
      const glm::ivec2 window_pos{
          int(number_attribute(pos_node, "x", 0, source, window_path + "/Pos")),
          int(number_attribute(pos_node, "y", 0, source, window_path + "/Pos"))};
      const glm::dvec2 window_size{std::floor(width), std::floor(height)};
      int viewport_index = 0;
      for (const pugi::xml_node& viewport : window.children("Viewport")) {
        const std::string path =
            window_path + "/Viewport[" + std::to_string(viewport_index++) + "]";
        const std::string mesh_written = attribute_of(viewport, {"mesh", "correctionMesh"});
        const std::string viewport_name = viewport.attribute("name").value();
        if (mesh_written.empty()) {
          display.notes.push_back(path + (viewport_name.empty() ? "" : " (" + viewport_name + ")") +
                                  " has no correction mesh: not a projector, left out");
          continue;
        }
        const bool simcad = has_extension(mesh_written, ".simcad");
        if (!simcad && !has_extension(mesh_written, ".sgc")) {
          throw InputError(source, path + "@mesh",
                           "expected a SCISS .sgc or SimCAD .simcad mesh, found \"" + mesh_written +
                               "\" (MPCDI and Paul Bourke meshes have their own import commands)");
        }
        const pugi::xml_node vp_pos = viewport.child("Pos"), vp_size = viewport.child("Size");
        const glm::dvec2 fraction_pos{number_attribute(vp_pos, "x", 0, source, path + "/Pos"),
                                      number_attribute(vp_pos, "y", 0, source, path + "/Pos")};
        const glm::dvec2 fraction_size{number_attribute(vp_size, "x", 1, source, path + "/Size"),
                                       number_attribute(vp_size, "y", 1, source, path + "/Size")};
        if (!(fraction_pos.x >= 0 && fraction_pos.y >= 0 && fraction_size.x > 0 &&
              fraction_size.y > 0 && fraction_pos.x + fraction_size.x <= 1 + 1e-9 &&
              fraction_pos.y + fraction_size.y <= 1 + 1e-9)) {
          throw InputError(source, path + "/Pos",
                           "expected the viewport's Pos and Size as fractions of the window "
                           "within [0,1]");
        }
        const glm::ivec2 output_size =
            glm::max(glm::ivec2(glm::round(fraction_size * window_size)), glm::ivec2(1));
        const glm::ivec2 output_pos =
            window_pos + glm::ivec2(glm::round(fraction_pos * window_size));

        std::vector<std::string> notes;
        const std::filesystem::path mesh_path =
            resolve(mesh_written, folder, source, path + "@mesh", notes);
        const std::string mesh_source = mesh_path.string();
        const std::string mesh_bytes = read_file(mesh_path, mesh_source, "");
        const SgcMesh mesh =
            simcad
                ? parse_simcad(mesh_bytes, planar_projection(viewport, source, path), mesh_source)
                : parse_sgc(mesh_bytes, mesh_source);
        SgcImportOptions import;
        import.output_size = output_size;
        import.warp_grid = options.warp_grid;
        std::string name =
            sanitize_name(viewport_name.empty() ? mesh_path.stem().string() : viewport_name);
        for (std::string base = name; !names.insert(name).second;) {
          name = base + "-" + std::to_string(names.size());
        }
        ImportedProjector projector = import_sgc(mesh, import, mesh_source, name).projector;
        const std::string mask_written = attribute_of(viewport, {"mask", "blendMask"});
        if (!mask_written.empty()) {
          const std::filesystem::path mask_path =
              resolve(mask_written, folder, source, path + "@mask", notes);
          projection_io::BlendMap mask =
              decode_image_map(read_file(mask_path, mask_path.string(), ""), mask_path.string(),
                               options.mask_gamma, output_size, mask_path.string());
          collapse_equal_channels(mask);
          projector.blend = std::move(mask);
        }
        projector.output.kind = projection_io::DisplayOutput::Kind::window;
        projector.output.window = {desktop_x + output_pos.x, output_pos.y, output_size.x,
                                   output_size.y};
        node_right = std::max(node_right, projector.output.window.x + output_size.x);
        projector.notes.insert(projector.notes.begin(), notes.begin(), notes.end());
        display.projectors.push_back(std::move(projector));
      }
    }
    desktop_x = node_right;
  }
  if (display.projectors.empty()) {
    throw InputError(source, "Node/Window/Viewport@mesh",
                     "expected at least one viewport with a .sgc or .simcad correction mesh");
  }
  if (node_index > 1) {
    display.notes.push_back(
        "the cluster's nodes are separate machines; their windows are placed "
        "left to right on one desktop");
  }
  return display;
}

ImportedDisplay import_sgc_files(const std::vector<std::filesystem::path>& meshes,
                                 glm::ivec2 output_size, glm::ivec2 warp_grid) {
  FACET_ASSERT(!meshes.empty());
  ImportedDisplay display;
  display.name = meshes.front().stem().string();
  SgcImportOptions import;
  import.output_size = output_size;
  import.warp_grid = warp_grid;
  int x = 0;
  for (const std::filesystem::path& path : meshes) {
    const std::string source = path.string();
    ImportedProjector projector = import_sgc(parse_sgc(read_file(path, source, ""), source), import,
                                             source, sanitize_name(path.stem().string()))
                                      .projector;
    for (const ImportedProjector& other : display.projectors) {
      if (other.name == projector.name) {
        throw InputError(source, "",
                         "expected file names that differ: two are \"" + projector.name + "\"");
      }
    }
    projector.output.window = {x, 0, output_size.x, output_size.y};
    x += output_size.x;
    display.projectors.push_back(std::move(projector));
  }
  return display;
}

std::map<std::string, std::string> export_sgct(const projection_io::DisplayConfig& display,
                                               const SgctExportOptions& options) {
  FACET_ASSERT(options.node_spacing_px >= 1 && options.node_spacing_px <= 1024);
  FACET_ASSERT(options.mask_gamma > 0);
  std::map<std::string, std::string> files;
  pugi::xml_document document;
  pugi::xml_node cluster = document.append_child("Cluster");
  cluster.append_attribute("masterAddress") = "127.0.0.1";
  int port = 20401;
  for (const projection_io::DisplayProjector& projector : display.projectors) {
    const std::string warp_path = display.resolve(projector.warp).string();
    const Warp warp = read_warp(warp_path);
    const MpcdiFrustum frustum = covering_frustum(warp, warp_path);
    const BaseProjection base = frustum_base(frustum);
    const glm::dmat3 R_frustum_eye = glm::transpose(R_eye_frustum(frustum));
    const glm::ivec2 nodes{int(std::ceil(warp.output_size.x / options.node_spacing_px)) + 1,
                           int(std::ceil(warp.output_size.y / options.node_spacing_px)) + 1};
    // Every vertex, covered or not: rings as wide as the grid continue the map everywhere it
    // reaches, and neighbours fill in the rest.
    InverseGrid grid = inverse_grid_from_warp(
        warp, nodes,
        [&](const glm::dvec3& v_eye) { return base.st_from_direction(R_frustum_eye * v_eye); },
        std::max(nodes.x, nodes.y));
    std::vector<glm::dvec2>& st = grid.st;
    fill_missing(st, nodes, warp_path);
    SgcMesh mesh = sgc_header(frustum);
    mesh.vertices.resize(st.size());
    for (int j = 0; j < nodes.y; ++j) {
      for (int i = 0; i < nodes.x; ++i) {
        const std::size_t k = std::size_t(j) * nodes.x + i;
        mesh.vertices[k].q_norm = {double(i) / (nodes.x - 1), double(j) / (nodes.y - 1)};
        mesh.vertices[k].st = st[k];
      }
    }
    files[projector.name + ".sgc"] = format_sgc(mesh, nodes);

    projection_io::BlendMap mask =
        projector.blend ? projection_io::read_blend_map(display.resolve(*projector.blend).string(),
                                                        warp.output_size)
                        : projection_io::BlendMap::constant(warp.output_size, 1.0f);
    const std::vector<glm::dvec2> st_at_pixels = WarpInverse(warp).st_at_pixel_centres();
    for (int y = 0; y < mask.size.y; ++y) {
      for (int x = 0; x < mask.size.x; ++x) {
        const bool covered = std::isfinite(st_at_pixels[std::size_t(y) * mask.size.x + x].x);
        for (int c = 0; c < mask.channels; ++c) {
          mask.at(x, y, c) = covered
                                 ? float(std::pow(std::clamp(double(mask.at(x, y, c)), 0.0, 1.0),
                                                  1 / options.mask_gamma))
                                 : 0.0f;
        }
      }
    }
    files[projector.name + "_mask.png"] = encode_png(mask, 8);

    pugi::xml_node node = cluster.append_child("Node");
    node.append_attribute("address") = "127.0.0.1";
    node.append_attribute("port") = port++;
    pugi::xml_node window = node.append_child("Window");
    window.append_attribute("fullScreen") = "true";
    pugi::xml_node size = window.append_child("Size");
    size.append_attribute("x") = warp.output_size.x;
    size.append_attribute("y") = warp.output_size.y;
    pugi::xml_node viewport = window.append_child("Viewport");
    viewport.append_attribute("name") = projector.name.c_str();
    viewport.append_attribute("mesh") = (projector.name + ".sgc").c_str();
    viewport.append_attribute("mask") = (projector.name + "_mask.png").c_str();
  }
  pugi::xml_node user_pos = cluster.append_child("User").append_child("Pos");
  user_pos.append_attribute("x") = display.eye.x;
  user_pos.append_attribute("y") = display.eye.y;
  user_pos.append_attribute("z") = display.eye.z;
  std::ostringstream xml;
  document.save(xml, "  ");
  files["cluster.xml"] = xml.str();
  return files;
}

}  // namespace facet::interop
