#include "facet/projection_io/rig_file.hpp"

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "json_fields.hpp"

namespace facet {
namespace detail {
// configs/rigs/*.json, generated into builtin_rigs.cpp by projection/CMakeLists.txt.
struct BuiltinRig {
  const char* name;
  const char* text;
};
extern const BuiltinRig kBuiltinRigs[];
extern const std::size_t kBuiltinRigCount;
}  // namespace detail

namespace {

using json_fields::FieldPath;
using json_fields::Fields;
using json_fields::Json;
using json_fields::to_dvec3;
using json_fields::to_number;
using json_fields::to_string;

// The pose's rotation (camera-like frame: x right, y down, z forward) from either a matrix or a
// point to look at from `position`. With a matrix, `look_at` and `up` are not read (and allowed).
glm::dmat3 rotation(Fields& fields, const std::string& matrix_key, const glm::dvec3& position,
                    const glm::dmat3& fallback) {
  const FieldPath& at = fields.path();
  if (const Json* R = fields.optional(matrix_key)) {
    fields.allow({"look_at", "up"});
    return json_fields::to_dmat3(*R, at[matrix_key]);
  }
  const Json* target = fields.optional("look_at");
  glm::dvec3 up(0, 1, 0);
  if (const Json* u = fields.optional("up")) up = to_dvec3(*u, at["up"]);
  if (target == nullptr) return fallback;
  return json_fields::look_at_axes(position, to_dvec3(*target, at["look_at"]), up, at, "position");
}

ProjectorModel projector_from_json(const Json& value, const FieldPath& at) {
  Fields fields(value, at);
  ProjectorModel p;
  p.name = to_string(fields.required("name", "a name"), at["name"]);
  const std::string expected_size = "[width, height] in projector pixels";
  p.size = json_fields::to_ivec2(fields.required("size", expected_size), at["size"],
                                 "[width, height] in pixels");
  if (const Json* focal = fields.optional("focal_px")) {
    p.focal_px = json_fields::to_dvec2(*focal, at["focal_px"], "[fx, fy] in pixels");
    fields.allow({"fov_deg"});
  } else if (const Json* fov = fields.optional("fov_deg")) {
    const double degrees = to_number(*fov, at["fov_deg"]);
    if (!(degrees > 0 && degrees < 180)) {
      at["fov_deg"].fail("a horizontal field of view in (0, 180) degrees", degrees);
    }
    const double f = 0.5 * p.size.x / std::tan(degrees * std::numbers::pi / 360.0);
    p.focal_px = {f, f};
  } else {
    at["focal_px"].fail("[fx, fy] in pixels, or fov_deg (the field is missing)");
  }
  p.principal_px = glm::dvec2(p.size) * 0.5;
  if (const Json* c = fields.optional("principal_px")) {
    p.principal_px = json_fields::to_dvec2(*c, at["principal_px"], "[cx, cy] in output pixels");
  }
  if (const Json* k = fields.optional("distortion")) {
    const auto values =
        json_fields::to_numbers(*k, at["distortion"], 0, 3, "a list of up to 3 numbers k1, k2, k3");
    for (std::size_t n = 0; n < values.size(); ++n) p.k[n] = values[n];
  }
  if (const Json* gamma = fields.optional("gamma")) p.gamma = to_number(*gamma, at["gamma"]);
  if (const Json* t = fields.optional("t_eye_projector")) {
    p.t_eye_projector = to_dvec3(*t, at["t_eye_projector"]);
  }
  if (fields.optional("R_eye_projector") == nullptr && fields.optional("look_at") == nullptr) {
    at["R_eye_projector"].fail("a rotation matrix, or look_at (the field is missing)");
  }
  p.R_eye_projector = rotation(fields, "R_eye_projector", p.t_eye_projector, glm::dmat3(1.0));
  fields.finish();
  return p;
}

RigCamera camera_from_json(const Json& value, const FieldPath& at) {
  Fields fields(value, at);
  RigCamera camera;
  camera.lensmodel =
      to_string(fields.required("lensmodel", "an mrcal lens model name"), at["lensmodel"]);
  const std::string expected_size = "[width, height] in camera pixels";
  camera.size = json_fields::to_ivec2(fields.required("size", expected_size), at["size"],
                                      "[width, height] in pixels");
  if (const Json* fov = fields.optional("fov_deg")) camera.fov_deg = to_number(*fov, at["fov_deg"]);
  if (const Json* intrinsics = fields.optional("intrinsics")) {
    camera.intrinsics =
        json_fields::to_numbers(*intrinsics, at["intrinsics"], 4, 100000,
                                "a list of intrinsics fx, fy, cx, cy, distortion...");
  }
  if (const Json* t = fields.optional("t_eye_camera")) {
    camera.t_eye_camera = to_dvec3(*t, at["t_eye_camera"]);
  }
  camera.R_eye_camera =
      rotation(fields, "R_eye_camera", camera.t_eye_camera, RigCamera{}.R_eye_camera);
  fields.finish();
  return camera;
}

SimulationSettings simulation_from_json(const Json& value, const FieldPath& at) {
  Fields fields(value, at);
  SimulationSettings s;
  auto read_number = [&](const char* key, double& out) {
    if (const Json* v = fields.optional(key)) out = to_number(*v, at[key]);
  };
  auto read_int = [&](const char* key, int& out) {
    if (const Json* v = fields.optional(key)) out = json_fields::to_int(*v, at[key]);
  };
  auto read_bool = [&](const char* key, bool& out) {
    if (const Json* v = fields.optional(key)) out = json_fields::to_bool(*v, at[key]);
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
  if (const Json* seed = fields.optional("seed")) {
    if (!seed->is_number_unsigned()) at["seed"].fail("a non-negative integer", *seed);
    s.seed = seed->get<std::uint64_t>();
  }
  fields.finish();
  return s;
}

Json simulation_to_json(const SimulationSettings& s) {
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
  const Json root = json_fields::parse(text_in, source);
  const FieldPath at(source);
  Fields fields(root, at);
  const std::string expected_format = std::string("\"") + kRigFormat + "\"";
  const Json& format = fields.required("format", expected_format);
  if (!format.is_string() || format.get<std::string>() != kRigFormat) {
    at["format"].fail(expected_format, format);
  }
  Rig rig;
  rig.screen = json_fields::to_screen(fields.required("screen", "a screen object"), at["screen"]);
  const Json& projectors = fields.required("projectors", "a list of projectors");
  if (!projectors.is_array()) at["projectors"].fail("a list of projectors", projectors);
  for (std::size_t k = 0; k < projectors.size(); ++k) {
    rig.projectors.push_back(projector_from_json(projectors[k], at["projectors"][k]));
  }
  rig.camera = camera_from_json(fields.required("camera", "a camera object"), at["camera"]);
  if (const Json* simulation = fields.optional("simulation")) {
    rig.simulation = simulation_from_json(*simulation, at["simulation"]);
  }
  fields.finish();
  rig.validate(source);
  return rig;
}

Rig read_rig(const std::filesystem::path& path) {
  const Activity activity("reading the rig " + path.string());
  require_regular_file(path);
  std::ifstream stream(path);
  if (!stream) throw InputError(path.string(), "", "a readable rig JSON file");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  return parse_rig(buffer.str(), path.string());
}

std::vector<std::string> builtin_rig_names() {
  std::vector<std::string> names;
  for (std::size_t k = 0; k < detail::kBuiltinRigCount; ++k)
    names.emplace_back(detail::kBuiltinRigs[k].name);
  return names;
}

Rig load_rig(const std::string& name_or_path) {
  constexpr std::string_view kPrefix = "builtin:";
  if (!name_or_path.starts_with(kPrefix)) return read_rig(name_or_path);
  const std::string_view name = std::string_view(name_or_path).substr(kPrefix.size());
  std::string known;
  for (std::size_t k = 0; k < detail::kBuiltinRigCount; ++k) {
    if (name == detail::kBuiltinRigs[k].name)
      return parse_rig(detail::kBuiltinRigs[k].text, name_or_path);
    known += std::string(known.empty() ? "" : ", ") + "builtin:" + detail::kBuiltinRigs[k].name;
  }
  throw InputError(name_or_path, "rig", "one of " + known + " or a rig file");
}

std::string format_rig(const Rig& rig) {
  Json projectors = Json::array();
  for (const ProjectorModel& p : rig.projectors) {
    projectors.push_back({{"name", p.name},
                          {"size", {p.size.x, p.size.y}},
                          {"focal_px", {p.focal_px.x, p.focal_px.y}},
                          {"principal_px", {p.principal_px.x, p.principal_px.y}},
                          {"distortion", {p.k[0], p.k[1], p.k[2]}},
                          {"gamma", p.gamma},
                          {"R_eye_projector", json_fields::from_dmat3(p.R_eye_projector)},
                          {"t_eye_projector", json_fields::from_dvec3(p.t_eye_projector)}});
  }
  Json camera{{"lensmodel", rig.camera.lensmodel},
              {"size", {rig.camera.size.x, rig.camera.size.y}},
              {"fov_deg", rig.camera.fov_deg},
              {"R_eye_camera", json_fields::from_dmat3(rig.camera.R_eye_camera)},
              {"t_eye_camera", json_fields::from_dvec3(rig.camera.t_eye_camera)}};
  if (!rig.camera.intrinsics.empty()) camera["intrinsics"] = rig.camera.intrinsics;
  const Json root{{"format", kRigFormat},
                  {"screen", json_fields::from_screen(rig.screen)},
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
