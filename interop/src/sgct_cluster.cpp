// SGCT cluster configurations with SCISS or SimCAD meshes and masks: import into a display, and
// a display exported as one.
#include "facet/interop/sgct_cluster.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
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
  // A name the system cannot look up (too long, a loop of links) is no file either.
  auto is_file = [](const std::filesystem::path& path) {
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
  };
  const std::filesystem::path as_written(written);
  if (as_written.is_absolute() && is_file(as_written)) return as_written;
  if (is_file(folder / as_written)) return folder / as_written;
  const std::size_t slash = written.find_last_of("/\\");
  const std::string name = slash == std::string::npos ? written : written.substr(slash + 1);
  if (!name.empty() && is_file(folder / name)) {
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

// One row of a SimCAD `<stem>_frustum.csv` (`;`-separated, a header line then one of values):
// the frustum its `.simcad` mesh was made for, degrees, each FOV edge positive outwards.
struct SimcadFrustumTable {
  double heading = 0, pitch = 0, bank = 0, left = 0, right = 0, bottom = 0, top = 0;
};

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> items;
  std::stringstream stream(line);
  for (std::string item; std::getline(stream, item, separator);) {
    if (!item.empty() && item.back() == '\r') item.pop_back();
    items.push_back(item);
  }
  return items;
}

SimcadFrustumTable read_frustum_table(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::stringstream text(read_file(path, source, ""));
  std::string header, values;
  std::getline(text, header);
  std::getline(text, values);
  const std::vector<std::string> names = split(header, ';'), numbers = split(values, ';');
  const auto column = [&](const char* name) {
    const auto at = std::find(names.begin(), names.end(), name);
    if (at == names.end())
      throw InputError(source, "line 1", "expected a column " + std::string(name));
    const std::size_t index = std::size_t(at - names.begin());
    if (index >= numbers.size()) {
      throw InputError(source, "line 2", "expected a value for column " + std::string(name));
    }
    return parse_number(numbers[index], source, "line 2/" + std::string(name));
  };
  return {column("heading"), column("pitch"),  column("bank"), column("left"),
          column("right"),   column("bottom"), column("top")};
}

// Whether two angles in degrees agree within 0.001° (modulo 360°).
bool same_angle(double a, double b) {
  const double difference = std::remainder(a - b, 360.0);
  return std::abs(difference) < 1e-3;
}

// "channel2" before "channel10": digit runs compare as numbers.
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) &&
        std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t i_end = i, j_end = j;
      while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end]))) ++i_end;
      while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end]))) ++j_end;
      const std::string x = a.substr(i, i_end - i), y = b.substr(j, j_end - j);
      const std::string x_digits = x.substr(std::min(x.find_first_not_of('0'), x.size()));
      const std::string y_digits = y.substr(std::min(y.find_first_not_of('0'), y.size()));
      if (x_digits.size() != y_digits.size()) return x_digits.size() < y_digits.size();
      if (x_digits != y_digits) return x_digits < y_digits;
      i = i_end, j = j_end;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i, ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

// SimCAD's cluster files name no meshes: each projector's viewport has a <PlanarProjection> but
// no mesh attribute, and the channel's `.simcad` file lies next to the cluster file, with a
// `<stem>_frustum.csv` holding the frustum it was made for. Pairs such viewports (keyed by their
// XML node) with those files: by frustum where every `.simcad` file has its table (a viewport
// takes the one file whose table matches its FOV and heading, pitch, roll within 0.001°), else in
// order (the k-th such viewport in the file takes the k-th `.simcad` file by name) when the counts
// are equal. Notes say which file each took. Once one viewport has taken a file, every such
// viewport must: one left without (its file missing, unreadable or not matching) is an InputError
// naming it, since a cluster imported without one of its projectors would leave a dark wedge in the
// show.
std::map<const void*, std::string> pair_sibling_simcad(const pugi::xml_node& cluster,
                                                       const std::filesystem::path& folder,
                                                       const std::string& source,
                                                       std::vector<std::string>& notes) {
  std::vector<std::pair<pugi::xml_node, std::string>> viewports;  // and their paths
  int node_index = 0;
  for (const pugi::xml_node& node : cluster.children("Node")) {
    int window_index = 0;
    for (const pugi::xml_node& window : node.children("Window")) {
      int viewport_index = 0;
      for (const pugi::xml_node& viewport : window.children("Viewport")) {
        const std::string path = "Node[" + std::to_string(node_index) + "]/Window[" +
                                 std::to_string(window_index) + "]/Viewport[" +
                                 std::to_string(viewport_index++) + "]";
        if (attribute_of(viewport, {"mesh", "correctionMesh"}).empty() &&
            viewport.child("PlanarProjection")) {
          viewports.emplace_back(viewport, path);
        }
      }
      ++window_index;
    }
    ++node_index;
  }
  std::map<const void*, std::string> paired;
  if (viewports.empty()) return paired;
  std::vector<std::string> meshes;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(
           folder.empty() ? std::filesystem::path(".") : folder, error)) {
    const std::string name = entry.path().filename().string();
    if (has_extension(name, ".simcad") && entry.is_regular_file(error)) meshes.push_back(name);
  }
  std::sort(meshes.begin(), meshes.end(), natural_less);
  if (meshes.empty()) return paired;

  std::vector<std::optional<SimcadFrustumTable>> tables;
  std::vector<std::pair<std::string, std::string>> unpaired;  // viewport path, what it lacks
  bool every_table = true;
  for (const std::string& mesh : meshes) {
    const std::filesystem::path table =
        folder / (std::filesystem::path(mesh).stem().string() + "_frustum.csv");
    std::error_code error_table;
    tables.push_back(std::filesystem::is_regular_file(table, error_table)
                         ? std::optional(read_frustum_table(table))
                         : std::nullopt);
    every_table = every_table && tables.back().has_value();
  }
  if (every_table) {
    std::vector<bool> taken(meshes.size(), false);
    for (const auto& [viewport, path] : viewports) {
      const pugi::xml_node projection = viewport.child("PlanarProjection");
      const pugi::xml_node fov = projection.child("FOV");
      const pugi::xml_node orientation = projection.child("Orientation");
      if (!fov || orientation.attribute("w")) {
        notes.push_back(path +
                        " has no mesh attribute, and its <PlanarProjection> gives no FOV "
                        "and heading to find its .simcad file by");
        continue;
      }
      const std::string fov_path = path + "/PlanarProjection/FOV";
      const std::string orientation_path = path + "/PlanarProjection/Orientation";
      const double left = number_attribute(fov, "left", 0, source, fov_path);
      const double right = number_attribute(fov, "right", 0, source, fov_path);
      const double up = number_attribute(fov, "up", 0, source, fov_path);
      const double down = number_attribute(fov, "down", 0, source, fov_path);
      const double heading = number_attribute(orientation, "heading", 0, source, orientation_path);
      const double pitch = number_attribute(orientation, "pitch", 0, source, orientation_path);
      const double roll = number_attribute(orientation, "roll", 0, source, orientation_path);
      std::vector<std::size_t> matches;
      for (std::size_t m = 0; m < meshes.size(); ++m) {
        const SimcadFrustumTable& t = *tables[m];
        if (same_angle(t.left, left) && same_angle(t.right, right) && same_angle(t.top, up) &&
            same_angle(t.bottom, down) && same_angle(t.heading, heading) &&
            same_angle(t.pitch, pitch) && same_angle(t.bank, roll)) {
          matches.push_back(m);
        }
      }
      if (matches.size() != 1 || taken[matches[0]]) {
        unpaired.push_back(
            {path,
             "a .simcad mesh next to the configuration whose _frustum.csv holds this "
             "viewport's frustum (FOV and heading, pitch, roll within 0.001°); " +
                 (matches.empty() ? std::string("none of the ")
                                  : std::to_string(matches.size()) + " (or a taken one) of the ") +
                 std::to_string(meshes.size()) + " found does"});
        continue;
      }
      taken[matches[0]] = true;
      const std::string& mesh = meshes[matches[0]];
      paired[viewport.internal_object()] = mesh;
      notes.push_back(path + " has no mesh attribute: took \"" + mesh +
                      "\" next to the configuration, whose " +
                      std::filesystem::path(mesh).stem().string() +
                      "_frustum.csv holds this viewport's frustum");
    }
  } else if (meshes.size() == viewports.size()) {
    for (std::size_t k = 0; k < viewports.size(); ++k) {
      paired[viewports[k].first.internal_object()] = meshes[k];
      notes.push_back(viewports[k].second + " has no mesh attribute: took \"" + meshes[k] +
                      "\", the .simcad file next to the configuration in the same place in "
                      "name order as this viewport among those with a <PlanarProjection> and "
                      "no mesh");
    }
  } else {
    notes.push_back(std::to_string(viewports.size()) +
                    " viewports have a <PlanarProjection> but no mesh attribute, and " +
                    std::to_string(meshes.size()) +
                    " .simcad files without a _frustum.csv each lie next to the configuration: "
                    "not paired");
  }
  if (!paired.empty() && !unpaired.empty())
    throw InputError(source, unpaired.front().first, unpaired.front().second);
  return paired;
}

}  // namespace

ImportedDisplay import_sgct_cluster(const std::filesystem::path& config,
                                    const SgctImportOptions& options) {
  const std::string source = config.string();
  const Activity activity("importing the SGCT cluster " + source);
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
  const std::map<const void*, std::string> sibling_meshes =
      pair_sibling_simcad(cluster, folder, source, display.notes);
  std::set<std::string> names;
  int desktop_x = 0;
  int node_index = 0;
  // facet's own cluster: a node per SGCT node that drives a projector, at the node's address on
  // ports 7400 + 2k and 7401 + 2k (SGCT's own ports belong to SGCT's protocol).
  projection_io::DisplayCluster facet_cluster;
  const std::string master_address = cluster.attribute("masterAddress").value();
  for (const pugi::xml_node& node : cluster.children("Node")) {
    const int this_node = node_index;
    const std::size_t projectors_before = display.projectors.size();
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
        std::string mesh_written = attribute_of(viewport, {"mesh", "correctionMesh"});
        if (const auto sibling = sibling_meshes.find(viewport.internal_object());
            mesh_written.empty() && sibling != sibling_meshes.end()) {
          mesh_written = sibling->second;
        }
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
    if (display.projectors.size() > projectors_before) {
      std::string address = node.attribute("address").value();
      if (address.empty() || address == "localhost") address = "127.0.0.1";
      projection_io::ClusterNode facet_node;
      facet_node.name = "node" + std::to_string(this_node);
      facet_node.address = "tcp://" + address + ":" + std::to_string(7400 + 2 * this_node);
      for (std::size_t p = projectors_before; p < display.projectors.size(); ++p)
        facet_node.projectors.push_back(display.projectors[p].name);
      if (facet_cluster.master.empty() && node.attribute("address").value() == master_address)
        facet_cluster.master = facet_node.name;
      facet_cluster.nodes.push_back(std::move(facet_node));
    }
  }
  if (facet_cluster.nodes.size() > 1) {
    if (facet_cluster.master.empty()) {
      facet_cluster.master = facet_cluster.nodes.front().name;
      display.notes.push_back("the cluster's master (masterAddress \"" + master_address +
                              "\") drives no projector: " + facet_cluster.master +
                              " is facet's master");
    }
    // An address that is no node's own (a name SGCT resolves, a bad one) is left to the reader,
    // which names it; here only what facet's cluster section can hold is kept.
    bool addresses_ok = true;
    for (const projection_io::ClusterNode& node : facet_cluster.nodes)
      addresses_ok = addresses_ok && projection_io::cluster_address_problem(node.address).empty();
    if (addresses_ok) {
      display.notes.push_back("a cluster section maps the " +
                              std::to_string(facet_cluster.nodes.size()) +
                              " nodes with projectors to facet's cluster nodes node<k>, on "
                              "ports 7400 + 2k of their addresses");
      display.cluster = std::move(facet_cluster);
    } else {
      display.notes.push_back(
          "a node address is not a host name or IP address: no cluster "
          "section written");
    }
  }
  if (display.projectors.empty()) {
    throw InputError(source, "Node/Window/Viewport@mesh",
                     "expected at least one viewport with a .sgc or .simcad correction mesh "
                     "(a mesh attribute, or for viewports with a <PlanarProjection>, .simcad "
                     "files next to the configuration)");
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
