#include "facet/projection_io/display_config.hpp"

#include <cmath>
#include <fstream>
#include <set>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"

namespace facet::projection_io {
namespace {

using nlohmann::json;

// Where in the document a value sits, for error messages: "projectors[1].output.window".
struct At {
  const std::string& source;
  std::string field;

  At operator[](const std::string& key) const {
    return {source, field.empty() ? key : field + "." + key};
  }
  At operator[](std::size_t index) const {
    return {source, field + "[" + std::to_string(index) + "]"};
  }
  [[noreturn]] void fail(const std::string& expected) const {
    throw InputError(source, field, expected);
  }
};

const json& object(const json& value, const At& at) {
  if (!value.is_object()) at.fail("a JSON object");
  return value;
}

const json* optional_member(const json& parent, const char* key) {
  const auto it = parent.find(key);
  return it == parent.end() || it->is_null() ? nullptr : &*it;
}

const json& member(const json& parent, const char* key, const At& at, const std::string& expected) {
  const json* value = optional_member(parent, key);
  if (value == nullptr) at[key].fail(expected + " (the field is missing)");
  return *value;
}

std::string text(const json& value, const At& at) {
  if (!value.is_string()) at.fail("a string");
  return value.get<std::string>();
}

double number(const json& value, const At& at) {
  // nlohmann parses NaN and Inf only from non-standard JSON; a float that holds them still fails.
  if (!value.is_number()) at.fail("a finite number");
  const double x = value.get<double>();
  if (!std::isfinite(x)) at.fail("a finite number");
  return x;
}

int integer(const json& value, const At& at) {
  const double x = number(value, at);
  if (x != std::floor(x) || std::abs(x) > 1e9) at.fail("an integer");
  return int(x);
}

template <int N, typename T, typename Read>
glm::vec<N, T> vector(const json& value, const At& at, const std::string& expected, Read read) {
  if (!value.is_array() || value.size() != N) at.fail(expected);
  glm::vec<N, T> result;
  for (int k = 0; k < N; ++k) result[k] = read(value[std::size_t(k)], at[std::size_t(k)]);
  return result;
}

glm::dvec3 dvec3(const json& value, const At& at) {
  return vector<3, double>(value, at, "a list of 3 numbers", number);
}

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

bool is_unit(const glm::dvec3& v) { return std::abs(glm::length(v) - 1.0) <= 1e-6; }
bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

DisplayScreen screen_from_json(const json& value, const At& at) {
  object(value, at);
  const std::string expected_type = "\"sphere\", \"cylinder\" or \"plane\"";
  const std::string type = text(member(value, "type", at, expected_type), at["type"]);
  DisplayScreen screen;
  auto unit = [&](const char* key) {
    const glm::dvec3 v = dvec3(member(value, key, at, "a list of 3 numbers"), at[key]);
    if (!(glm::length(v) > 1e-12)) at[key].fail("a non-zero vector");
    return glm::normalize(v);
  };
  if (type == "sphere" || type == "cylinder") {
    screen.type = type == "sphere" ? DisplayScreen::Type::sphere : DisplayScreen::Type::cylinder;
    screen.center = dvec3(member(value, "center", at, "a point in metres"), at["center"]);
    screen.radius =
        number(member(value, "radius", at, "a positive number of metres"), at["radius"]);
    if (type == "cylinder") screen.axis = unit("axis");
  } else if (type == "plane") {
    screen.type = DisplayScreen::Type::plane;
    screen.point = dvec3(member(value, "point", at, "a point in metres"), at["point"]);
    screen.normal = unit("normal");
  } else {
    at["type"].fail(expected_type);
  }
  return screen;
}

json screen_to_json(const DisplayScreen& screen) {
  auto list = [](const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); };
  switch (screen.type) {
    case DisplayScreen::Type::sphere:
      return {{"type", "sphere"}, {"center", list(screen.center)}, {"radius", screen.radius}};
    case DisplayScreen::Type::cylinder:
      return {{"type", "cylinder"},
              {"center", list(screen.center)},
              {"axis", list(screen.axis)},
              {"radius", screen.radius}};
    case DisplayScreen::Type::plane:
      return {{"type", "plane"}, {"point", list(screen.point)}, {"normal", list(screen.normal)}};
  }
  return {};
}

DisplayOutput output_from_json(const json& value, const At& at) {
  object(value, at);
  const std::string expected = "{\"monitor\": NAME} or {\"window\": [x, y, width, height]}";
  const json* monitor = optional_member(value, "monitor");
  const json* window = optional_member(value, "window");
  if ((monitor == nullptr) == (window == nullptr)) at.fail(expected + ", exactly one of them");
  DisplayOutput output;
  if (monitor != nullptr) {
    output.kind = DisplayOutput::Kind::monitor;
    output.monitor = text(*monitor, at["monitor"]);
    if (const json* position = optional_member(value, "position")) {
      output.position =
          vector<2, int>(*position, at["position"], "a list of 2 integers [x, y]", integer);
    }
    if (const json* size = optional_member(value, "size")) {
      output.size =
          vector<2, int>(*size, at["size"], "a list of 2 integers [width, height]", integer);
    }
  } else {
    output.kind = DisplayOutput::Kind::window;
    output.window = vector<4, int>(*window, at["window"],
                                   "a list of 4 integers [x, y, width, height]", integer);
  }
  return output;
}

json output_to_json(const DisplayOutput& output) {
  if (output.kind == DisplayOutput::Kind::window) {
    return {{"window", {output.window.x, output.window.y, output.window.z, output.window.w}}};
  }
  json result = {{"monitor", output.monitor}};
  if (output.position) result["position"] = {output.position->x, output.position->y};
  if (output.size) result["size"] = {output.size->x, output.size->y};
  return result;
}

void check_file(const DisplayConfig& config, const std::filesystem::path& relative, const At& at) {
  if (relative.empty()) at.fail("a file path relative to display.json");
  if (relative.is_absolute()) at.fail("a path relative to display.json, not an absolute path");
  std::error_code error;
  if (!std::filesystem::is_regular_file(config.resolve(relative), error)) {
    at.fail("an existing file, but '" + config.resolve(relative).string() + "' does not exist");
  }
}

void check_relative(const std::filesystem::path& relative, const At& at) {
  if (relative.empty()) at.fail("a file path relative to display.json");
  if (relative.is_absolute()) at.fail("a path relative to display.json, not an absolute path");
}

}  // namespace

void validate_display_config(const DisplayConfig& config, const std::string& source,
                             bool check_files) {
  const At root{source, ""};
  if (config.name.empty()) root["name"].fail("a non-empty display name");
  if (!finite(config.eye)) root["eye"].fail("3 finite numbers (metres)");
  if (config.screen) {
    const DisplayScreen& screen = *config.screen;
    const At at = root["screen"];
    if (!finite(screen.center) || !finite(screen.point) || !finite(screen.axis) ||
        !finite(screen.normal)) {
      at.fail("finite numbers");
    }
    if (screen.type != DisplayScreen::Type::plane && !(screen.radius > 0)) {
      at["radius"].fail("a positive number of metres");
    }
    if (screen.type == DisplayScreen::Type::cylinder && !is_unit(screen.axis)) {
      at["axis"].fail("a unit vector");
    }
    if (screen.type == DisplayScreen::Type::plane && !is_unit(screen.normal)) {
      at["normal"].fail("a unit vector");
    }
  }
  if (config.projectors.empty()) root["projectors"].fail("a list of at least one projector");
  std::set<std::string> names;
  for (std::size_t k = 0; k < config.projectors.size(); ++k) {
    const DisplayProjector& projector = config.projectors[k];
    const At at = root["projectors"][k];
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
  const At render = root["render"];
  if (!valid_method(config.render.method)) {
    render["method"].fail("a render method name of lower-case letters, digits, '_' and '-'");
  }
  if (!(config.render.tolerance_px > 0) || !std::isfinite(config.render.tolerance_px)) {
    render["tolerance_px"].fail("a positive number of output pixels");
  }
  if (!(config.render.z_near > 0) || !std::isfinite(config.render.z_near)) {
    render["z_near"].fail("a positive number of metres");
  }
}

DisplayConfig display_config_from_json(const json& document, const std::string& source,
                                       const std::filesystem::path& folder, bool check_files) {
  const At root{source, ""};
  object(document, root);
  const json& format = member(document, "format", root, std::string("\"") + kDisplayFormat + "\"");
  if (!format.is_string() || format.get<std::string>() != kDisplayFormat) {
    root["format"].fail(std::string("\"") + kDisplayFormat + "\"");
  }
  DisplayConfig config;
  config.folder = folder;
  config.name = text(member(document, "name", root, "the display's name"), root["name"]);
  config.eye = dvec3(member(document, "eye", root, "[x, y, z] in metres"), root["eye"]);
  if (const json* screen = optional_member(document, "screen")) {
    config.screen = screen_from_json(*screen, root["screen"]);
  }
  const json& projectors = member(document, "projectors", root, "a list of at least one projector");
  if (!projectors.is_array()) root["projectors"].fail("a list of at least one projector");
  for (std::size_t k = 0; k < projectors.size(); ++k) {
    const At at = root["projectors"][k];
    const json& item = object(projectors[k], at);
    DisplayProjector projector;
    projector.name = text(member(item, "name", at, "the projector's name"), at["name"]);
    projector.size = vector<2, int>(member(item, "size", at, "[width, height] in output pixels"),
                                    at["size"], "[width, height] in output pixels", integer);
    projector.warp =
        text(member(item, "warp", at, "the path of its .warp.exr, relative to display.json"),
             at["warp"]);
    if (const json* blend = optional_member(item, "blend")) {
      projector.blend = text(*blend, at["blend"]);
    }
    if (const json* black = optional_member(item, "black")) {
      projector.black = text(*black, at["black"]);
    }
    if (const json* gamma = optional_member(item, "gamma")) {
      if (gamma->is_string() && gamma->get<std::string>() == "srgb") {
        projector.gamma.reset();
      } else if (gamma->is_number()) {
        projector.gamma = number(*gamma, at["gamma"]);
      } else {
        at["gamma"].fail("\"srgb\" or a positive finite output gamma (e.g. 2.2)");
      }
    }
    projector.output = output_from_json(
        member(item, "output", at, "{\"monitor\": NAME} or {\"window\": [x, y, width, height]}"),
        at["output"]);
    config.projectors.push_back(std::move(projector));
  }
  if (const json* render = optional_member(document, "render")) {
    const At at = root["render"];
    object(*render, at);
    if (const json* method = optional_member(*render, "method")) {
      config.render.method = text(*method, at["method"]);
    }
    if (const json* tolerance = optional_member(*render, "tolerance_px")) {
      config.render.tolerance_px = number(*tolerance, at["tolerance_px"]);
    }
    if (const json* z_near = optional_member(*render, "z_near")) {
      config.render.z_near = number(*z_near, at["z_near"]);
    }
  }
  if (const json* missing = optional_member(document, "missing_monitor")) {
    const std::string value = text(*missing, root["missing_monitor"]);
    if (value == "error") {
      config.missing_monitor = MissingMonitor::error;
    } else if (value == "window") {
      config.missing_monitor = MissingMonitor::window;
    } else {
      root["missing_monitor"].fail("\"error\" or \"window\", not \"" + value + "\"");
    }
  }
  validate_display_config(config, source, check_files);
  return config;
}

DisplayConfig read_display_config(const std::filesystem::path& path, bool check_files) {
  std::error_code error;
  const std::filesystem::path file =
      std::filesystem::is_directory(path, error) ? path / "display.json" : path;
  require_regular_file(file);
  std::ifstream stream(file);
  if (!stream) throw InputError(file.string(), "", "cannot open the file");
  json document;
  try {
    document = json::parse(stream);
  } catch (const json::exception& e) {
    throw InputError(file.string(), "", std::string("expected valid JSON: ") + e.what());
  }
  return display_config_from_json(document, file.string(), file.parent_path(), check_files);
}

json display_config_to_json(const DisplayConfig& config) {
  json document = {{"format", kDisplayFormat},
                   {"name", config.name},
                   {"eye", {config.eye.x, config.eye.y, config.eye.z}}};
  if (config.screen) document["screen"] = screen_to_json(*config.screen);
  json projectors = json::array();
  for (const DisplayProjector& projector : config.projectors) {
    json item = {{"name", projector.name},
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
  return document;
}

void write_display_config(const DisplayConfig& config, const std::filesystem::path& path) {
  validate_display_config(config, path.string(), false);
  const std::string text = display_config_to_json(config).dump(2) + "\n";
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    std::ofstream stream(temporary, std::ios::binary);
    stream << text;
    stream.close();
    if (!stream) throw InputError(path.string(), "", "cannot write the file");
  });
}

}  // namespace facet::projection_io
