#include "facet/projection_io/rig_file.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"

namespace facet {
namespace {

using nlohmann::json;

struct At {
  std::string source, field;
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

const json* find(const json& parent, const std::string& key) {
  auto it = parent.find(key);
  return it == parent.end() || it->is_null() ? nullptr : &*it;
}

const json& need(const json& parent, const std::string& key, const At& at,
                 const std::string& expected) {
  const json* value = find(parent, key);
  if (value == nullptr) at[key].fail(expected + " (the field is missing)");
  return *value;
}

double number(const json& value, const At& at) {
  if (!value.is_number()) at.fail("a number");
  const double x = value.get<double>();
  if (!std::isfinite(x)) at.fail("a finite number");
  return x;
}

int integer(const json& value, const At& at) {
  if (value.is_number_integer()) {
    const auto x = value.get<long long>();
    if (x < -1'000'000'000 || x > 1'000'000'000) at.fail("an integer of sensible size");
    return int(x);
  }
  if (value.is_number_float()) {
    const double x = value.get<double>();
    if (std::isfinite(x) && x == std::floor(x) && std::abs(x) < 1e9) return int(x);
  }
  at.fail("an integer");
}

bool boolean(const json& value, const At& at) {
  if (!value.is_boolean()) at.fail("true or false");
  return value.get<bool>();
}

std::string text(const json& value, const At& at) {
  if (!value.is_string()) at.fail("a string");
  return value.get<std::string>();
}

std::vector<double> numbers(const json& value, const At& at, std::size_t min_count,
                            std::size_t max_count, const std::string& expected) {
  if (!value.is_array() || value.size() < min_count || value.size() > max_count) at.fail(expected);
  std::vector<double> out;
  for (std::size_t k = 0; k < value.size(); ++k) out.push_back(number(value[k], at[k]));
  return out;
}

glm::dvec3 dvec3(const json& value, const At& at) {
  const auto v = numbers(value, at, 3, 3, "a list of 3 numbers");
  return {v[0], v[1], v[2]};
}

glm::dvec2 dvec2(const json& value, const At& at, const std::string& expected) {
  const auto v = numbers(value, at, 2, 2, expected);
  return {v[0], v[1]};
}

glm::ivec2 size2(const json& value, const At& at) {
  const std::string expected = "[width, height] in pixels";
  if (!value.is_array() || value.size() != 2) at.fail(expected);
  return {integer(value[0], at[0]), integer(value[1], at[1])};
}

// A matrix in JSON is a list of rows; glm stores columns.
glm::dmat3 dmat3(const json& value, const At& at) {
  if (!value.is_array() || value.size() != 3) at.fail("a 3x3 matrix as a list of 3 rows");
  glm::dmat3 m(0.0);
  for (std::size_t row = 0; row < 3; ++row) {
    const glm::dvec3 values = dvec3(value[row], at[row]);
    for (int col = 0; col < 3; ++col) m[col][int(row)] = values[col];
  }
  return m;
}

json from_dvec3(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }
json from_dmat3(const glm::dmat3& m) {
  json rows = json::array();
  for (int row = 0; row < 3; ++row) rows.push_back({m[0][row], m[1][row], m[2][row]});
  return rows;
}

// The pose's rotation (camera-like frame: x right, y down, z forward) from either a matrix or a
// point to look at from `position`.
glm::dmat3 rotation(const json& parent, const std::string& matrix_key, const glm::dvec3& position,
                    const At& at, const glm::dmat3& fallback) {
  if (const json* R = find(parent, matrix_key)) return dmat3(*R, at[matrix_key]);
  const json* target = find(parent, "look_at");
  if (target == nullptr) return fallback;
  const glm::dvec3 forward_raw = dvec3(*target, at["look_at"]) - position;
  if (!(glm::length(forward_raw) > 1e-9)) {
    at["look_at"].fail("a point other than the position itself");
  }
  glm::dvec3 up(0, 1, 0);
  if (const json* u = find(parent, "up")) up = dvec3(*u, at["up"]);
  const glm::dvec3 forward = glm::normalize(forward_raw);
  const glm::dvec3 right_raw = glm::cross(forward, up);
  if (!(glm::length(right_raw) > 1e-9 * std::max(1.0, glm::length(up)))) {
    at["up"].fail("an up vector that is not parallel to the viewing direction");
  }
  const glm::dvec3 right = glm::normalize(right_raw);
  const glm::dvec3 down = glm::cross(forward, right);
  return glm::dmat3(right, down, forward);
}

Screen screen_from_json(const json& value, const At& at) {
  object(value, at);
  const std::string expected = "\"sphere\", \"cylinder\" or \"plane\"";
  const std::string type = text(need(value, "type", at, expected), at["type"]);
  Screen screen;
  auto radius = [&] {
    const double r = number(need(value, "radius", at, "a positive number of metres"), at["radius"]);
    if (!(r > 0)) at["radius"].fail("a positive number of metres");
    return r;
  };
  auto unit = [&](const std::string& key) {
    const glm::dvec3 v = dvec3(need(value, key, at, "a list of 3 numbers"), at[key]);
    if (!(glm::length(v) > 1e-12)) at[key].fail("a non-zero vector");
    return glm::normalize(v);
  };
  if (type == "sphere") {
    screen.type = Screen::Type::sphere;
    screen.center = dvec3(need(value, "center", at, "a point in metres"), at["center"]);
    screen.radius = radius();
  } else if (type == "cylinder") {
    screen.type = Screen::Type::cylinder;
    screen.center = dvec3(need(value, "center", at, "a point in metres"), at["center"]);
    screen.axis = unit("axis");
    screen.radius = radius();
  } else if (type == "plane") {
    screen.type = Screen::Type::plane;
    screen.point = dvec3(need(value, "point", at, "a point in metres"), at["point"]);
    screen.normal = unit("normal");
  } else {
    at["type"].fail(expected);
  }
  return screen;
}

json screen_to_json(const Screen& screen) {
  switch (screen.type) {
    case Screen::Type::sphere:
      return {{"type", "sphere"}, {"center", from_dvec3(screen.center)}, {"radius", screen.radius}};
    case Screen::Type::cylinder:
      return {{"type", "cylinder"},
              {"center", from_dvec3(screen.center)},
              {"axis", from_dvec3(screen.axis)},
              {"radius", screen.radius}};
    case Screen::Type::plane:
      return {{"type", "plane"},
              {"point", from_dvec3(screen.point)},
              {"normal", from_dvec3(screen.normal)}};
  }
  return {};
}

ProjectorModel projector_from_json(const json& value, const At& at) {
  object(value, at);
  ProjectorModel p;
  p.name = text(need(value, "name", at, "a name"), at["name"]);
  p.size = size2(need(value, "size", at, "[width, height] in projector pixels"), at["size"]);
  if (const json* focal = find(value, "focal_px")) {
    p.focal_px = dvec2(*focal, at["focal_px"], "[fx, fy] in pixels");
  } else if (const json* fov = find(value, "fov_deg")) {
    const double degrees = number(*fov, at["fov_deg"]);
    if (!(degrees > 0 && degrees < 180))
      at["fov_deg"].fail("a horizontal field of view in (0, 180) degrees");
    const double f = 0.5 * p.size.x / std::tan(degrees * std::numbers::pi / 360.0);
    p.focal_px = {f, f};
  } else {
    at["focal_px"].fail("[fx, fy] in pixels, or fov_deg (the field is missing)");
  }
  p.principal_px = glm::dvec2(p.size) * 0.5;
  if (const json* c = find(value, "principal_px")) {
    p.principal_px = dvec2(*c, at["principal_px"], "[cx, cy] in output pixels");
  }
  if (const json* k = find(value, "distortion")) {
    const auto values = numbers(*k, at["distortion"], 0, 3, "a list of up to 3 numbers k1, k2, k3");
    for (std::size_t n = 0; n < values.size(); ++n) p.k[n] = values[n];
  }
  if (const json* gamma = find(value, "gamma")) p.gamma = number(*gamma, at["gamma"]);
  if (const json* t = find(value, "t_eye_projector")) {
    p.t_eye_projector = dvec3(*t, at["t_eye_projector"]);
  }
  p.R_eye_projector = rotation(value, "R_eye_projector", p.t_eye_projector, at, glm::dmat3(1.0));
  if (find(value, "R_eye_projector") == nullptr && find(value, "look_at") == nullptr) {
    at["R_eye_projector"].fail("a rotation matrix, or look_at (the field is missing)");
  }
  return p;
}

RigCamera camera_from_json(const json& value, const At& at) {
  object(value, at);
  RigCamera camera;
  camera.lensmodel =
      text(need(value, "lensmodel", at, "an mrcal lens model name"), at["lensmodel"]);
  camera.size = size2(need(value, "size", at, "[width, height] in camera pixels"), at["size"]);
  if (const json* fov = find(value, "fov_deg")) camera.fov_deg = number(*fov, at["fov_deg"]);
  if (const json* intrinsics = find(value, "intrinsics")) {
    camera.intrinsics = numbers(*intrinsics, at["intrinsics"], 4, 100000,
                                "a list of intrinsics fx, fy, cx, cy, distortion...");
  }
  if (const json* t = find(value, "t_eye_camera"))
    camera.t_eye_camera = dvec3(*t, at["t_eye_camera"]);
  camera.R_eye_camera =
      rotation(value, "R_eye_camera", camera.t_eye_camera, at, RigCamera{}.R_eye_camera);
  return camera;
}

SimulationSettings simulation_from_json(const json& value, const At& at) {
  object(value, at);
  SimulationSettings s;
  auto read_number = [&](const char* key, double& out) {
    if (const json* v = find(value, key)) out = number(*v, at[key]);
  };
  auto read_int = [&](const char* key, int& out) {
    if (const json* v = find(value, key)) out = integer(*v, at[key]);
  };
  auto read_bool = [&](const char* key, bool& out) {
    if (const json* v = find(value, key)) out = boolean(*v, at[key]);
  };
  read_bool("phase", s.phase);
  read_number("phase_period", s.phase_period);
  read_int("phase_steps", s.phase_steps);
  read_number("defocus_px", s.defocus_px);
  read_bool("falloff", s.falloff);
  read_number("peak", s.peak);
  read_number("ambient", s.ambient);
  read_number("camera_blur_px", s.camera_blur_px);
  read_number("noise", s.noise);
  read_int("bits", s.bits);
  if (const json* seed = find(value, "seed")) {
    if (!seed->is_number_unsigned()) at["seed"].fail("a non-negative integer");
    s.seed = seed->get<std::uint64_t>();
  }
  return s;
}

json simulation_to_json(const SimulationSettings& s) {
  return {{"phase", s.phase},
          {"phase_period", s.phase_period},
          {"phase_steps", s.phase_steps},
          {"defocus_px", s.defocus_px},
          {"falloff", s.falloff},
          {"peak", s.peak},
          {"ambient", s.ambient},
          {"camera_blur_px", s.camera_blur_px},
          {"noise", s.noise},
          {"bits", s.bits},
          {"seed", s.seed}};
}

}  // namespace

Rig parse_rig(const std::string& text_in, const std::string& source) {
  json root;
  try {
    root = json::parse(text_in);
  } catch (const json::parse_error& error) {
    throw InputError(source, "", std::string("valid JSON (") + error.what() + ")");
  }
  const At at{source, ""};
  object(root, at);
  const json& format = need(root, "format", at, std::string("\"") + kRigFormat + "\"");
  if (!format.is_string() || format.get<std::string>() != kRigFormat) {
    at["format"].fail(std::string("\"") + kRigFormat + "\"");
  }
  Rig rig;
  rig.screen = screen_from_json(need(root, "screen", at, "a screen object"), at["screen"]);
  const json& projectors = need(root, "projectors", at, "a list of projectors");
  if (!projectors.is_array()) at["projectors"].fail("a list of projectors");
  for (std::size_t k = 0; k < projectors.size(); ++k) {
    rig.projectors.push_back(projector_from_json(projectors[k], at["projectors"][k]));
  }
  rig.camera = camera_from_json(need(root, "camera", at, "a camera object"), at["camera"]);
  if (const json* simulation = find(root, "simulation")) {
    rig.simulation = simulation_from_json(*simulation, at["simulation"]);
  }
  rig.validate(source);
  return rig;
}

Rig read_rig(const std::filesystem::path& path) {
  require_regular_file(path);
  std::ifstream stream(path);
  if (!stream) throw InputError(path.string(), "", "a readable rig JSON file");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  return parse_rig(buffer.str(), path.string());
}

std::string format_rig(const Rig& rig) {
  json projectors = json::array();
  for (const ProjectorModel& p : rig.projectors) {
    projectors.push_back({{"name", p.name},
                          {"size", {p.size.x, p.size.y}},
                          {"focal_px", {p.focal_px.x, p.focal_px.y}},
                          {"principal_px", {p.principal_px.x, p.principal_px.y}},
                          {"distortion", {p.k[0], p.k[1], p.k[2]}},
                          {"gamma", p.gamma},
                          {"R_eye_projector", from_dmat3(p.R_eye_projector)},
                          {"t_eye_projector", from_dvec3(p.t_eye_projector)}});
  }
  json camera{{"lensmodel", rig.camera.lensmodel},
              {"size", {rig.camera.size.x, rig.camera.size.y}},
              {"fov_deg", rig.camera.fov_deg},
              {"R_eye_camera", from_dmat3(rig.camera.R_eye_camera)},
              {"t_eye_camera", from_dvec3(rig.camera.t_eye_camera)}};
  if (!rig.camera.intrinsics.empty()) camera["intrinsics"] = rig.camera.intrinsics;
  const json root{{"format", kRigFormat},
                  {"screen", screen_to_json(rig.screen)},
                  {"projectors", projectors},
                  {"camera", camera},
                  {"simulation", simulation_to_json(rig.simulation)}};
  // nlohmann prints doubles with enough digits to read back the same value.
  return root.dump(1) + "\n";
}

void write_rig(const std::filesystem::path& path, const Rig& rig) {
  rig.validate(path.string());
  const std::string content = format_rig(rig);
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    std::ofstream stream(temporary);
    stream << content;
    stream.close();
    if (!stream) throw InputError(path.string(), "", "a writable file");
  });
}

}  // namespace facet
