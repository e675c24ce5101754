#include "facet/projection_io/display_config.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "facet/projection/warp.hpp"
#include "json_fields.hpp"

namespace facet::projection_io {
namespace {

using json_fields::FieldPath;
using json_fields::Fields;
using json_fields::Json;

bool valid_name(const std::string& name) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return name != "." && name != "..";
}

bool valid_method(const std::string& method) {
  if (method.empty()) return false;
  for (const char c : method) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-')) return false;
  }
  return true;
}

bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Positions and radii beyond this (1,000 km) are no venue's: refused before any arithmetic with
// them loses every digit (an eye at 1e308 m made the warps' directions all alike).
constexpr double kMaxDistance_m = 1e6;
bool within_reach(const glm::dvec3& p_m) {
  return finite(p_m) && std::abs(p_m.x) <= kMaxDistance_m && std::abs(p_m.y) <= kMaxDistance_m &&
         std::abs(p_m.z) <= kMaxDistance_m;
}

DisplayOutput output_from_json(const Json& value, const FieldPath& at) {
  Fields fields(value, at);
  const std::string expected = "{\"monitor\": NAME} or {\"window\": [x, y, width, height]}";
  const Json* monitor = fields.optional("monitor");
  const Json* window = fields.optional("window");
  if ((monitor == nullptr) == (window == nullptr)) at.fail(expected + ", exactly one of them");
  DisplayOutput output;
  if (monitor != nullptr) {
    output.kind = DisplayOutput::Kind::monitor;
    output.monitor = json_fields::to_string(*monitor, at["monitor"]);
    if (const Json* position = fields.optional("position")) {
      output.position =
          json_fields::to_ivec2(*position, at["position"], "a list of 2 integers [x, y]");
    }
    if (const Json* size = fields.optional("size")) {
      output.size =
          json_fields::to_ivec2(*size, at["size"], "a list of 2 integers [width, height]");
    }
  } else {
    output.kind = DisplayOutput::Kind::window;
    output.window =
        json_fields::to_ivec4(*window, at["window"], "a list of 4 integers [x, y, width, height]");
  }
  fields.finish();
  return output;
}

Json output_to_json(const DisplayOutput& output) {
  if (output.kind == DisplayOutput::Kind::window) {
    return {{"window", {output.window.x, output.window.y, output.window.z, output.window.w}}};
  }
  Json result = {{"monitor", output.monitor}};
  if (output.position) result["position"] = {output.position->x, output.position->y};
  if (output.size) result["size"] = {output.size->x, output.size->y};
  return result;
}

void check_file(const DisplayConfig& config, const std::filesystem::path& relative,
                const FieldPath& at) {
  if (relative.empty()) at.fail("a file path relative to display.json");
  if (relative.is_absolute()) at.fail("a path relative to display.json, not an absolute path");
  std::error_code error;
  if (!std::filesystem::is_regular_file(config.resolve(relative), error)) {
    at.fail("an existing file, but '" + config.resolve(relative).string() + "' does not exist");
  }
}

void check_relative(const std::filesystem::path& relative, const FieldPath& at) {
  if (relative.empty()) at.fail("a file path relative to display.json");
  if (relative.is_absolute()) at.fail("a path relative to display.json, not an absolute path");
}

// "tcp://HOST:PORT" split into host and port; false when it is not of that form.
bool split_tcp(const std::string& address, std::string& host, int& port) {
  constexpr std::string_view kTcp = "tcp://";
  if (!address.starts_with(kTcp)) return false;
  const std::string rest = address.substr(kTcp.size());
  const std::size_t colon = rest.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == rest.size()) return false;
  host = rest.substr(0, colon);
  const std::string digits = rest.substr(colon + 1);
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
  return error == std::errc() && end == digits.data() + digits.size() &&
         digits.find_first_not_of("0123456789") == std::string::npos;
}

void validate_cluster(const DisplayConfig& config, const FieldPath& root) {
  const DisplayCluster& cluster = *config.cluster;
  const FieldPath at = root["cluster"];
  if (cluster.nodes.empty()) at["nodes"].fail("a list of at least one node");
  std::vector<std::string> projector_names;
  for (const DisplayProjector& projector : config.projectors)
    projector_names.push_back(projector.name);
  std::map<std::string, std::string> node_of_projector;
  std::set<std::string> node_names, addresses;
  for (std::size_t k = 0; k < cluster.nodes.size(); ++k) {
    const ClusterNode& node = cluster.nodes[k];
    const FieldPath node_at = at["nodes"][k];
    if (!valid_name(node.name))
      node_at["name"].fail("a non-empty node name of letters, digits, '_', '-' and '.'");
    if (!node_names.insert(node.name).second)
      node_at["name"].fail("a name no other node has, but '" + node.name + "' repeats");
    if (const std::string problem = cluster_address_problem(node.address); !problem.empty())
      node_at["address"].fail(problem + ", got '" + node.address + "'");
    // A node listens on its address and the next one: neither may be another node's.
    for (const std::string& address : {node.address, cluster_barrier_address(node.address)}) {
      if (!addresses.insert(address).second)
        node_at["address"].fail("an address pair of its own, but " + address +
                                " is another node's (a node listens on its address and on " +
                                cluster_barrier_address(node.address) + ")");
    }
    if (node.projectors.empty())
      node_at["projectors"].fail("a list of at least one projector name");
    for (std::size_t p = 0; p < node.projectors.size(); ++p) {
      const std::string& name = node.projectors[p];
      const FieldPath projector_at = node_at["projectors"][p];
      if (std::find(projector_names.begin(), projector_names.end(), name) ==
          projector_names.end()) {
        const std::string nearest = json_fields::nearest_key(name, projector_names);
        projector_at.fail("the name of one of the display's projectors, but there is no '" + name +
                          "'" + (nearest.empty() ? "" : "; did you mean '" + nearest + "'?"));
      }
      const auto [owner, added] = node_of_projector.emplace(name, node.name);
      if (!added)
        projector_at.fail("a projector of this node only, but '" + name + "' is also on node '" +
                          owner->second + "'");
    }
  }
  for (const std::string& name : projector_names) {
    if (!node_of_projector.contains(name))
      at["nodes"].fail("every projector on one node, but '" + name + "' is on none");
  }
  if (cluster.master.empty()) at["master"].fail("the name of the master node");
  if (!node_names.contains(cluster.master)) {
    const std::string nearest = json_fields::nearest_key(
        cluster.master, std::vector<std::string>(node_names.begin(), node_names.end()));
    at["master"].fail("the name of one of the nodes, but there is no node '" + cluster.master +
                      "'" + (nearest.empty() ? "" : "; did you mean '" + nearest + "'?"));
  }
  if (cluster.deadline_ms &&
      !(*cluster.deadline_ms > 0 && *cluster.deadline_ms <= kMaxClusterDeadline_ms))
    at["deadline_ms"].fail("a positive number of milliseconds, at most 600,000");
}

}  // namespace

std::string cluster_address_problem(const std::string& address) {
  const std::string expected = "tcp://HOST:PORT with PORT in 1..65534, or ipc://PATH";
  if (address.starts_with("ipc://"))
    return address.size() > 6 && address.find('\0') == std::string::npos ? "" : expected;
  std::string host;
  int port = 0;
  if (!split_tcp(address, host, port) || port < 1 || port > 65534) return expected;
  for (const char c : host) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '-' || c == '_' || c == '*' || c == '[' || c == ']' ||
                    c == ':';
    if (!ok) return expected + " (HOST: a name, an IPv4 address or [IPv6])";
  }
  return "";
}

std::string cluster_barrier_address(const std::string& address) {
  std::string host;
  int port = 0;
  if (split_tcp(address, host, port)) return "tcp://" + host + ":" + std::to_string(port + 1);
  return address + ".barrier";
}

void validate_display_config(const DisplayConfig& config, const std::string& source,
                             bool check_files) {
  const FieldPath root(source);
  if (config.name.empty()) root["name"].fail("a non-empty display name");
  if (!within_reach(config.eye))
    root["eye"].fail("3 finite numbers (metres), each within ±1,000 km (1e6 m)");
  if (config.screen) json_fields::check_screen(*config.screen, root["screen"]);
  if (config.projectors.empty()) root["projectors"].fail("a list of at least one projector");
  std::set<std::string> names;
  for (std::size_t k = 0; k < config.projectors.size(); ++k) {
    const DisplayProjector& projector = config.projectors[k];
    const FieldPath at = root["projectors"][k];
    if (!valid_name(projector.name)) {
      at["name"].fail("a non-empty name of letters, digits, '_', '-' and '.'");
    }
    if (!names.insert(projector.name).second) {
      at["name"].fail("a name no other projector has, but '" + projector.name + "' repeats");
    }
    if (projector.size.x < 1 || projector.size.y < 1 || projector.size.x > 65536 ||
        projector.size.y > 65536) {
      at["size"].fail("[width, height] in output pixels, each in 1..65536");
    }
    if (projector.gamma && (!(*projector.gamma > 0) || !std::isfinite(*projector.gamma))) {
      at["gamma"].fail("\"srgb\" or a positive finite output gamma (e.g. 2.2)");
    }
    auto file = [&](const std::filesystem::path& relative, const char* key) {
      if (check_files) {
        check_file(config, relative, at[key]);
      } else {
        check_relative(relative, at[key]);
      }
    };
    file(projector.warp, "warp");
    if (projector.blend) file(*projector.blend, "blend");
    if (projector.black) file(*projector.black, "black");
    const DisplayOutput& output = projector.output;
    if (output.kind == DisplayOutput::Kind::monitor) {
      if (output.monitor.empty()) at["output"]["monitor"].fail("a non-empty monitor name");
      if (output.size && (output.size->x < 1 || output.size->y < 1)) {
        at["output"]["size"].fail("a positive width and height");
      }
    } else if (output.window.z < 1 || output.window.w < 1) {
      at["output"]["window"].fail("[x, y, width, height] with a positive width and height");
    }
  }
  const FieldPath render = root["render"];
  if (!valid_method(config.render.method)) {
    render["method"].fail("a render method name of lower-case letters, digits, '_' and '-'");
  }
  if (!(config.render.tolerance_px > 0 && config.render.tolerance_px <= kMaxImageSide)) {
    render["tolerance_px"].fail("a number of output pixels in (0, 16384]");
  }
  if (!(config.render.z_near > 0) || !std::isfinite(config.render.z_near)) {
    render["z_near"].fail("a positive number of metres");
  }
  if (config.cluster) validate_cluster(config, root);
}

namespace {

DisplayCluster cluster_from_json(const Json& value, const FieldPath& at) {
  using namespace json_fields;
  Fields fields(value, at);
  DisplayCluster cluster;
  const std::string expected_nodes = "a list of nodes {name, address, projectors, critical}";
  const Json& nodes = fields.required("nodes", expected_nodes);
  if (!nodes.is_array()) at["nodes"].fail(expected_nodes, nodes);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const FieldPath node_at = at["nodes"][k];
    Fields item(nodes[k], node_at);
    ClusterNode node;
    node.name = to_string(item.required("name", "the node's name"), node_at["name"]);
    node.address =
        to_string(item.required("address", "tcp://HOST:PORT or ipc://PATH"), node_at["address"]);
    const std::string expected_projectors = "a list of the names of the projectors it drives";
    const Json& projectors = item.required("projectors", expected_projectors);
    if (!projectors.is_array()) node_at["projectors"].fail(expected_projectors, projectors);
    for (std::size_t p = 0; p < projectors.size(); ++p)
      node.projectors.push_back(to_string(projectors[p], node_at["projectors"][p]));
    if (const Json* critical = item.optional("critical"))
      node.critical = to_bool(*critical, node_at["critical"]);
    item.finish();
    cluster.nodes.push_back(std::move(node));
  }
  cluster.master =
      to_string(fields.required("master", "the name of the master node"), at["master"]);
  if (const Json* deadline = fields.optional("deadline_ms"))
    cluster.deadline_ms = to_number(*deadline, at["deadline_ms"]);
  fields.finish();
  return cluster;
}

Json cluster_to_json(const DisplayCluster& cluster) {
  Json nodes = Json::array();
  for (const ClusterNode& node : cluster.nodes)
    nodes.push_back({{"name", node.name},
                     {"address", node.address},
                     {"projectors", node.projectors},
                     {"critical", node.critical}});
  Json result = {{"nodes", std::move(nodes)}, {"master", cluster.master}};
  if (cluster.deadline_ms) result["deadline_ms"] = *cluster.deadline_ms;
  return result;
}

DisplayConfig display_from_json(const Json& document, const std::string& source,
                                const std::filesystem::path& folder, bool check_files) {
  using namespace json_fields;
  const FieldPath root(source);
  Fields fields(document, root);
  const std::string expected_format = std::string("\"") + kDisplayFormat + "\"";
  const Json& format = fields.required("format", expected_format);
  if (!format.is_string() || format.get<std::string>() != kDisplayFormat) {
    root["format"].fail(expected_format, format);
  }
  DisplayConfig config;
  config.folder = folder;
  config.name = to_string(fields.required("name", "the display's name"), root["name"]);
  config.eye = to_dvec3(fields.required("eye", "[x, y, z] in metres"), root["eye"]);
  if (const Json* screen = fields.optional("screen")) {
    config.screen = json_fields::to_screen(*screen, root["screen"]);
  }
  const std::string expected_projectors = "a list of at least one projector";
  const Json& projectors = fields.required("projectors", expected_projectors);
  if (!projectors.is_array()) root["projectors"].fail(expected_projectors, projectors);
  for (std::size_t k = 0; k < projectors.size(); ++k) {
    const FieldPath at = root["projectors"][k];
    Fields item(projectors[k], at);
    DisplayProjector projector;
    projector.name = to_string(item.required("name", "the projector's name"), at["name"]);
    const std::string expected_size = "[width, height] in output pixels";
    projector.size = to_ivec2(item.required("size", expected_size), at["size"], expected_size);
    projector.warp = to_string(
        item.required("warp", "the path of its .warp.exr, relative to display.json"), at["warp"]);
    if (const Json* blend = item.optional("blend"))
      projector.blend = to_string(*blend, at["blend"]);
    if (const Json* black = item.optional("black"))
      projector.black = to_string(*black, at["black"]);
    if (const Json* gamma = item.optional("gamma")) {
      if (gamma->is_string() && gamma->get<std::string>() == "srgb") {
        projector.gamma.reset();
      } else if (gamma->is_number()) {
        projector.gamma = to_number(*gamma, at["gamma"]);
      } else {
        at["gamma"].fail("\"srgb\" or a positive finite output gamma (e.g. 2.2)", *gamma);
      }
    }
    projector.output = output_from_json(
        item.required("output", "{\"monitor\": NAME} or {\"window\": [x, y, width, height]}"),
        at["output"]);
    item.finish();
    config.projectors.push_back(std::move(projector));
  }
  if (const Json* render_value = fields.optional("render")) {
    const FieldPath at = root["render"];
    Fields render(*render_value, at);
    if (const Json* method = render.optional("method")) {
      config.render.method = to_string(*method, at["method"]);
    }
    if (const Json* tolerance = render.optional("tolerance_px")) {
      config.render.tolerance_px = to_number(*tolerance, at["tolerance_px"]);
    }
    if (const Json* z_near = render.optional("z_near")) {
      config.render.z_near = to_number(*z_near, at["z_near"]);
    }
    render.finish();
  }
  if (const Json* missing = fields.optional("missing_monitor")) {
    const std::string value = to_string(*missing, root["missing_monitor"]);
    if (value == "error") {
      config.missing_monitor = MissingMonitor::error;
    } else if (value == "window") {
      config.missing_monitor = MissingMonitor::window;
    } else {
      root["missing_monitor"].fail("\"error\" or \"window\"", *missing);
    }
  }
  if (const Json* cluster = fields.optional("cluster"))
    config.cluster = cluster_from_json(*cluster, root["cluster"]);
  fields.finish();
  validate_display_config(config, source, check_files);
  return config;
}

Json display_to_json(const DisplayConfig& config) {
  Json document = {{"format", kDisplayFormat},
                   {"name", config.name},
                   {"eye", {config.eye.x, config.eye.y, config.eye.z}}};
  if (config.screen) document["screen"] = json_fields::from_screen(*config.screen);
  Json projectors = Json::array();
  for (const DisplayProjector& projector : config.projectors) {
    Json item = {{"name", projector.name},
                 {"size", {projector.size.x, projector.size.y}},
                 {"warp", projector.warp.generic_string()}};
    if (projector.blend) item["blend"] = projector.blend->generic_string();
    if (projector.black) item["black"] = projector.black->generic_string();
    if (projector.gamma) {
      item["gamma"] = *projector.gamma;
    } else {
      item["gamma"] = "srgb";
    }
    item["output"] = output_to_json(projector.output);
    projectors.push_back(std::move(item));
  }
  document["projectors"] = std::move(projectors);
  document["render"] = {{"method", config.render.method},
                        {"tolerance_px", config.render.tolerance_px},
                        {"z_near", config.render.z_near}};
  document["missing_monitor"] =
      config.missing_monitor == MissingMonitor::window ? "window" : "error";
  if (config.cluster) document["cluster"] = cluster_to_json(*config.cluster);
  return document;
}

}  // namespace

DisplayConfig parse_display_config(const std::string& text, const std::string& source,
                                   const std::filesystem::path& folder, bool check_files) {
  return display_from_json(json_fields::parse(text, source), source, folder, check_files);
}

DisplayConfig read_display_config(const std::filesystem::path& path, bool check_files) {
  const Activity activity("reading the display " + path.string());
  std::error_code error;
  const std::filesystem::path file =
      std::filesystem::is_directory(path, error) ? path / "display.json" : path;
  return display_from_json(json_fields::parse_file(file), file.string(), file.parent_path(),
                           check_files);
}

DisplayConfig read_display_template(const std::filesystem::path& path) {
  std::error_code error;
  const std::filesystem::path file =
      std::filesystem::is_directory(path, error) ? path / "display.json" : path;
  json_fields::Json root = json_fields::parse_file(file);
  if (root.is_object() && root.contains("projectors") && root["projectors"].is_array()) {
    for (auto& projector : root["projectors"]) {
      if (projector.is_object() && !projector.contains("warp") && projector.contains("name") &&
          projector["name"].is_string())
        projector["warp"] = projector["name"].get<std::string>() + ".warp.exr";
    }
  }
  return display_from_json(root, file.string(), file.parent_path(), false);
}

std::string format_display_config(const DisplayConfig& config) {
  return display_to_json(config).dump(2) + "\n";
}

void write_display_config(const DisplayConfig& config, const std::filesystem::path& path) {
  validate_display_config(config, path.string(), false);
  const std::string text = format_display_config(config);
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    std::ofstream stream(temporary, std::ios::binary);
    stream << text;
    stream.close();
    if (!stream) throw InputError(path.string(), "", "cannot write the file");
  });
}

}  // namespace facet::projection_io
