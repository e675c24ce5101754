#include "facet/driver/session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <glm/gtc/matrix_access.hpp>
#include <limits>
#include <map>
#include <numbers>

#include "../gl/image_rows.hpp"
#include "facet/driver/display_outputs.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet::driver {

namespace {

BlendMaps blend_maps_from(const projection_io::DisplayConfig& config,
                          const projection_io::DisplayProjector& projector) {
  BlendMaps maps;
  maps.size = projector.size;
  std::optional<projection_io::BlendMap> alpha, black;
  if (projector.blend)
    alpha =
        projection_io::read_blend_map(config.resolve(*projector.blend).string(), projector.size);
  if (projector.black)
    black =
        projection_io::read_blend_map(config.resolve(*projector.black).string(), projector.size);
  // One weight per colour in either map makes both per colour.
  maps.channels = (alpha && alpha->channels == 3) || (black && black->channels == 3) ? 3 : 1;
  auto expand = [&](const projection_io::BlendMap& map) {
    if (map.channels == maps.channels) return map.values;
    std::vector<float> rgb(map.values.size() * 3);
    for (std::size_t i = 0; i < map.values.size(); ++i)
      rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = map.values[i];
    return rgb;
  };
  if (alpha) maps.alpha = expand(*alpha);
  if (black) maps.black = expand(*black);
  return maps;
}

double angle_between(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// Weights of builtin:wall2x2: across each overlap band a smoothstep from one projector to the
// other, so that the weights of the projectors lighting a point sum to 1.
BlendMaps wall2x2_blend(const Warp& warp, int row, int column) {
  auto smoothstep = [](double edge0, double edge1, double x) {
    const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
    return t * t * (3 - 2 * t);
  };
  BlendMaps maps;
  maps.size = warp.output_size;
  maps.alpha.resize(std::size_t(maps.size.x) * maps.size.y);
  for (int y = 0; y < maps.size.y; ++y) {
    for (int x = 0; x < maps.size.x; ++x) {
      const glm::dvec2 st((x + 0.5) / maps.size.x, (y + 0.5) / maps.size.y);
      const glm::dvec3 v = warp.base.direction(st);
      const double tan_x = v.x / -v.z, tan_y = v.y / -v.z;
      const double right = smoothstep(-0.16, 0.16, tan_x), top = smoothstep(-0.1, 0.1, tan_y);
      maps.alpha[std::size_t(y) * maps.size.x + x] =
          float((column == 0 ? 1 - right : right) * (row == 0 ? top : 1 - top));
    }
  }
  return maps;
}

}  // namespace

SessionDisplay load_session_display(std::string_view display, std::optional<glm::ivec2> size) {
  SessionDisplay result;
  result.source = std::string(display);
  // A show goes on when its facets miss the tolerance by a near miss (with a warning, when the
  // caller gives facets.warn); the tolerance is the display's own, or the default of the
  // caller's tolerance option.
  result.settings.facets.near_miss = kRunNearMiss;
  result.settings.facets.origin = {"command line", OptionName{"tolerance_px"}, {}};
  // A display.json is read once: its outputs, settings and (for a cluster node) its cluster
  // section all come from this one value.
  LoadedDisplay loaded = load_display(display, size);
  std::vector<OutputSpec>& specs = loaded.outputs;
  if (loaded.config) {
    const projection_io::DisplayConfig& config = *loaded.config;
    result.method = config.render.method;
    result.settings.facets.layout = FacetTolerance{config.render.tolerance_px};
    result.settings.facets.origin = {std::string(display), "render.tolerance_px", {}};
    result.settings.z_near = config.render.z_near;
    result.missing_monitor = config.missing_monitor;
    for (std::size_t i = 0; i < config.projectors.size(); ++i) {
      const auto& projector = config.projectors[i];
      SessionOutput output;
      output.spec = std::move(specs.at(i));
      output.blend = blend_maps_from(config, projector);
      output.encoding.gamma = projector.gamma;  // nullopt: sRGB
      output.placement = projector.output;
      result.outputs.push_back(std::move(output));
    }
    result.config = std::move(loaded.config);
    return result;
  }
  result.settings.facets.layout = FacetTolerance{0.25};
  int x = 0;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    SessionOutput output;
    const glm::ivec2 output_size = specs[i].warp.output_size;
    output.placement.kind = projection_io::DisplayOutput::Kind::window;
    output.placement.window = {x, 0, output_size.x, output_size.y};
    x += output_size.x;
    if (display == "builtin:wall2x2")
      output.blend = wall2x2_blend(specs[i].warp, int(i) / 2, int(i) % 2);
    output.spec = std::move(specs[i]);
    result.outputs.push_back(std::move(output));
  }
  return result;
}

void scale_session_display(SessionDisplay& display, double factor) {
  if (!(factor > 0 && factor <= 1))
    throw InputError("command line", OptionName{"factor"}, "a factor in (0, 1]");
  // Every output keeps at least 8 pixels a side: below that (--scale 1e-9 made 1x1 outputs)
  // there is nothing to preview.
  for (const SessionOutput& output : display.outputs) {
    const glm::dvec2 scaled = glm::round(glm::dvec2(output.spec.warp.output_size) * factor);
    if (scaled.x < 8 || scaled.y < 8) {
      throw InputError(
          "command line", OptionName{"factor"},
          "a factor in (0, 1] that leaves every output at least 8 pixels a side, but " +
              std::to_string(factor) + " makes " + output.spec.name + " " +
              std::to_string(int(scaled.x)) + "x" + std::to_string(int(scaled.y)));
    }
  }
  for (SessionOutput& output : display.outputs) {
    Warp& warp = output.spec.warp;
    const glm::ivec2 old_size = warp.output_size;
    const glm::ivec2 new_size =
        glm::max(glm::ivec2(1), glm::ivec2(glm::round(glm::dvec2(old_size) * factor)));
    const glm::dvec2 ratio = glm::dvec2(new_size) / glm::dvec2(old_size);
    for (glm::vec2& offset : warp.offset_px) offset *= glm::vec2(ratio);
    warp.output_size = new_size;
    auto resample = [&](const std::vector<float>& values) {
      if (values.empty()) return values;
      const int channels = output.blend.channels;
      std::vector<float> result(std::size_t(new_size.x) * new_size.y * channels);
      for (int y = 0; y < new_size.y; ++y) {
        const int from_y = std::min(old_size.y - 1, int((y + 0.5) / ratio.y));
        for (int x = 0; x < new_size.x; ++x) {
          const int from_x = std::min(old_size.x - 1, int((x + 0.5) / ratio.x));
          for (int c = 0; c < channels; ++c)
            result[(std::size_t(y) * new_size.x + x) * channels + c] =
                values[(std::size_t(from_y) * old_size.x + from_x) * channels + c];
        }
      }
      return result;
    };
    output.blend.alpha = resample(output.blend.alpha);
    output.blend.black = resample(output.blend.black);
    if (!output.blend.alpha.empty() || !output.blend.black.empty()) output.blend.size = new_size;
    if (output.placement.kind == projection_io::DisplayOutput::Kind::window)
      output.placement.window =
          glm::ivec4(glm::dvec4(output.placement.window) * glm::dvec4(ratio, ratio));
  }
}

void write_session_display(const SessionDisplay& display, const std::string& name,
                           const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  OutputFolderRules rules;
  rules.field = OptionName{"out"};
  write_folder_atomically(
      folder,
      [&](const fs::path& temporary) {
        projection_io::DisplayConfig config;
        config.name = name;
        config.render.method = display.method;
        if (const auto* tolerance = std::get_if<FacetTolerance>(&display.settings.facets.layout))
          config.render.tolerance_px = tolerance->px;
        config.render.z_near = display.settings.z_near;
        config.missing_monitor = display.missing_monitor;
        for (const SessionOutput& output : display.outputs) {
          projection_io::DisplayProjector projector;
          projector.name = output.spec.name;
          projector.size = output.spec.warp.output_size;
          projector.warp = output.spec.name + ".warp.exr";
          write_warp((temporary / projector.warp).string(), output.spec.warp);
          auto write_map = [&](const std::vector<float>& values, const std::string& file) {
            projection_io::BlendMap map;
            map.size = output.blend.size;
            map.channels = output.blend.channels;
            map.values = values;
            projection_io::write_blend_map((temporary / file).string(), map);
          };
          if (!output.blend.alpha.empty()) {
            projector.blend = output.spec.name + ".blend.exr";
            write_map(output.blend.alpha, projector.blend->string());
          }
          if (!output.blend.black.empty()) {
            projector.black = output.spec.name + ".black.exr";
            write_map(output.blend.black, projector.black->string());
          }
          projector.gamma = output.encoding.gamma;
          projector.output = output.placement;
          config.projectors.push_back(std::move(projector));
        }
        projection_io::write_display_config(config, temporary / "display.json");
      },
      rules);
}

namespace {

nlohmann::json matrix_rows(const glm::dmat4& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < 4; ++c) row.push_back(m[c][r]);
    rows.push_back(row);
  }
  return rows;
}

// A 4x4 matrix written as 4 rows of 4 finite numbers; `field` names it in errors.
glm::dmat4 matrix_from_rows(const nlohmann::json* rows, const std::string& source,
                            const std::string& field) {
  if (!rows || !rows->is_array() || rows->size() != 4)
    throw InputError(source, field, "expected a 4x4 matrix as a list of 4 rows");
  glm::dmat4 m(1.0);
  for (int r = 0; r < 4; ++r) {
    const nlohmann::json& row = (*rows)[r];
    if (!row.is_array() || row.size() != 4)
      throw InputError(source, field + "[" + std::to_string(r) + "]", "expected 4 numbers");
    for (int c = 0; c < 4; ++c) {
      if (!row[c].is_number() || !std::isfinite(row[c].get<double>()))
        throw InputError(source, field + "[" + std::to_string(r) + "][" + std::to_string(c) + "]",
                         "expected a finite number");
      m[c][r] = row[c].get<double>();
    }
  }
  return m;
}

}  // namespace

nlohmann::json frame_state_to_json(const FrameState& state) {
  nlohmann::json json = {{"frame", state.frame},
                         {"time_s", state.time_s},
                         {"T_world_eye", matrix_rows(state.T_world_eye)}};
  if (!state.object_poses.empty()) {
    nlohmann::json poses = nlohmann::json::array();
    for (const ObjectPose& pose : state.object_poses)
      poses.push_back(
          {{"object", pose.object}, {"T_world_object", matrix_rows(pose.T_world_object)}});
    json["object_poses"] = std::move(poses);
  }
  return json;
}

FrameState frame_state_from_json(const nlohmann::json& value, const std::string& source) {
  FrameState state;
  if (!value.is_object()) throw InputError(source, "(root)", "expected a JSON object");
  if (!value.contains("frame") || !value["frame"].is_number_unsigned())
    throw InputError(source, "frame", "expected a non-negative integer");
  state.frame = value["frame"].get<std::uint64_t>();
  if (!value.contains("time_s") || !value["time_s"].is_number() ||
      !std::isfinite(value["time_s"].get<double>()))
    throw InputError(source, "time_s", "expected a finite number of seconds");
  state.time_s = value["time_s"].get<double>();
  state.T_world_eye = matrix_from_rows(
      value.contains("T_world_eye") ? &value["T_world_eye"] : nullptr, source, "T_world_eye");
  if (!value.contains("object_poses")) return state;
  const nlohmann::json& poses = value["object_poses"];
  if (!poses.is_array() || poses.size() > kMaxObjectPoses)
    throw InputError(source, "object_poses",
                     "expected a list of at most " + std::to_string(kMaxObjectPoses) +
                         " {object, T_world_object}");
  std::vector<std::uint32_t> seen;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::string field = "object_poses[" + std::to_string(i) + "]";
    const nlohmann::json& pose = poses[i];
    if (!pose.is_object()) throw InputError(source, field, "expected {object, T_world_object}");
    if (!pose.contains("object") || !pose["object"].is_number_unsigned() ||
        pose["object"].get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max())
      throw InputError(source, field + ".object", "expected an object index (0 to 2^32 - 1)");
    ObjectPose result;
    result.object = pose["object"].get<std::uint32_t>();
    result.T_world_object =
        matrix_from_rows(pose.contains("T_world_object") ? &pose["T_world_object"] : nullptr,
                         source, field + ".T_world_object");
    const glm::dvec4 last_row(glm::row(result.T_world_object, 3));
    if (last_row != glm::dvec4(0, 0, 0, 1))
      throw InputError(source, field + ".T_world_object[3]",
                       "an affine transform: the last row 0, 0, 0, 1");
    seen.push_back(result.object);
    state.object_poses.push_back(result);
  }
  std::sort(seen.begin(), seen.end());
  if (const auto twice = std::adjacent_find(seen.begin(), seen.end()); twice != seen.end())
    throw InputError(
        source, "object_poses",
        "each object at most once; object " + std::to_string(*twice) + " is listed twice");
  return state;
}

std::uint64_t FrameStats::triangles_in() const {
  std::uint64_t sum = 0;
  for (const OutputFrameStats& output : outputs) sum += output.render.triangles_in;
  return sum;
}

std::uint64_t FrameStats::replicas() const {
  std::uint64_t sum = 0;
  for (const OutputFrameStats& output : outputs) sum += output.render.replicas;
  return sum;
}

double FrameStats::replication_ratio() const {
  std::uint64_t scene_triangles = 0;
  for (const OutputFrameStats& output : outputs)
    scene_triangles = std::max(scene_triangles, output.render.triangles_scene);
  return scene_triangles == 0 ? 0.0 : double(replicas()) / double(scene_triangles);
}

nlohmann::json frame_stats_to_json(const FrameStats& stats) {
  nlohmann::json outputs = nlohmann::json::array();
  for (const OutputFrameStats& output : stats.outputs) {
    outputs.push_back({{"name", output.name},
                       {"rendered", output.rendered},
                       {"triangles_in", output.render.triangles_in},
                       {"triangles_visible", output.render.triangles_visible},
                       {"replicas", output.render.replicas},
                       {"facets", output.render.facets},
                       {"reused_replication", output.render.reused_replication},
                       {"blend_tiles", output.blend_tiles}});
  }
  nlohmann::json passes = nlohmann::json::object();
  for (const PassTime& pass : stats.pass_ms) passes[pass.pass] = pass.milliseconds;
  return {{"frame", stats.frame},
          {"time_s", stats.time_s},
          {"cpu_ms", stats.cpu_ms},
          {"triangles_in", stats.triangles_in()},
          {"replicas", stats.replicas()},
          {"replication_ratio", stats.replication_ratio()},
          {"pass_ms", passes},
          {"outputs", outputs}};
}

Session::Session(SessionDisplay display, Scene scene)
    : display_(std::move(display)), scene_(std::move(scene)), gpu_scene_(upload_scene(scene_)) {
  for (const Object& object : scene_.objects)
    rest_poses_.push_back({object.T_world_object, object.bounds_world, std::nullopt});
  for (const SessionOutput& output : display_.outputs) {
    const Warp& warp = output.spec.warp;
    std::unique_ptr<RenderMethod> method = make_render_method(display_.method);
    RenderSettings settings = display_.settings;  // its facets' messages name the projector
    settings.facets.origin.output = output.spec.name;
    method->prepare(scene_, gpu_scene_, std::span(&output.spec, 1), settings);
    methods_.push_back(std::move(method));
    targets_.push_back(OutputTarget::create(warp.output_size, display_.settings.msaa_samples));
    blends_.emplace_back(warp.output_size, output.blend, output.encoding);

    // The cone around every covered direction: the axis is the mean direction, and the half angle
    // the largest angle to a sample plus the largest angle between neighbouring samples, so no
    // covered direction between samples falls outside.
    constexpr int kSamples = 65;
    std::vector<glm::dvec3> v_covered;
    glm::dvec3 sum{0.0};
    double spacing = 0;
    for (int j = 0; j < kSamples; ++j) {
      for (int i = 0; i < kSamples; ++i) {
        const glm::dvec2 st(i / double(kSamples - 1), j / double(kSamples - 1));
        const glm::dvec3 v = glm::normalize(warp.v_eye_from_st(st));
        if (i > 0) {
          const glm::dvec2 left((i - 1) / double(kSamples - 1), st.y);
          spacing = std::max(spacing, angle_between(v, glm::normalize(warp.v_eye_from_st(left))));
        }
        if (j > 0) {
          const glm::dvec2 up(st.x, (j - 1) / double(kSamples - 1));
          spacing = std::max(spacing, angle_between(v, glm::normalize(warp.v_eye_from_st(up))));
        }
        if (warp.coverage_at(st) > 0) {
          v_covered.push_back(v);
          sum += v;
        }
      }
    }
    CoverageCone cone;
    if (v_covered.empty()) {
      cone.half_angle = -1;  // covers nothing
    } else if (glm::length(sum) < 1e-6 * double(v_covered.size())) {
      cone.half_angle = 2 * std::numbers::pi;
    } else {
      cone.axis = glm::normalize(sum);
      for (const glm::dvec3& v : v_covered)
        cone.half_angle = std::max(cone.half_angle, angle_between(cone.axis, v));
      cone.half_angle += spacing;
    }
    cones_.push_back(cone);
  }
}

Session::~Session() = default;

bool Session::output_sees_scene(std::size_t index, const glm::dmat4& T_world_eye) const {
  const CoverageCone& cone = cones_.at(index);
  if (cone.half_angle < 0) return false;
  if (cone.half_angle >= std::numbers::pi) return !scene_.objects.empty();
  const glm::dmat4 T_eye_world = glm::inverse(T_world_eye);
  constexpr double kRightAngle = std::numbers::pi / 2;
  for (const Object& object : scene_.objects) {
    const Aabb& box = object.bounds_world;
    if (box.empty()) continue;
    if (box.contains(glm::vec3(T_world_eye[3]))) return true;
    // Seen from outside, the box lies inside the cone around the direction to its centre whose
    // half angle is the largest angle to a corner, as long as that angle is below 90° (such a
    // cone is convex, so the corners' hull stays inside it).
    const glm::dvec3 centre_eye(T_eye_world * glm::dvec4(glm::dvec3(box.centre()), 1.0));
    double box_half_angle = 0;
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec3 p_world(corner & 1 ? box.p_max.x : box.p_min.x,
                               corner & 2 ? box.p_max.y : box.p_min.y,
                               corner & 4 ? box.p_max.z : box.p_min.z);
      const glm::dvec3 p_eye(T_eye_world * glm::dvec4(p_world, 1.0));
      box_half_angle = std::max(box_half_angle, angle_between(centre_eye, p_eye));
    }
    if (box_half_angle >= kRightAngle) return true;
    if (angle_between(cone.axis, centre_eye) <= cone.half_angle + box_half_angle) return true;
  }
  return false;
}

void Session::place_objects(const std::vector<ObjectPose>& poses,
                            const std::vector<ObjectPose>& animated) {
  std::vector<const ObjectPose*> pose_of(scene_.objects.size(), nullptr);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::string field = "object_poses[" + std::to_string(i) + "].object";
    const std::uint32_t o = poses[i].object;
    if (o >= scene_.objects.size())
      throw InputError("frame state", field,
                       "an object index below " + std::to_string(scene_.objects.size()) +
                           " (the scene's objects); got " + std::to_string(o));
    if (pose_of[o])
      throw InputError(
          "frame state", field,
          "each object at most once; object " + std::to_string(o) + " is listed twice");
    pose_of[o] = &poses[i];
  }
  for (const ObjectPose& pose : animated)
    if (pose.object < pose_of.size() && !pose_of[pose.object]) pose_of[pose.object] = &pose;
  for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
    Object& object = scene_.objects[o];
    RestPose& rest = rest_poses_[o];
    const glm::mat4 T_world_object =
        pose_of[o] ? glm::mat4(pose_of[o]->T_world_object) : rest.T_world_object;
    if (T_world_object == object.T_world_object) continue;
    object.T_world_object = T_world_object;
    if (!pose_of[o]) {
      object.bounds_world = rest.bounds_world;
      continue;
    }
    if (!rest.bounds_object) {
      Aabb box;
      for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
        const Primitive& primitive = scene_.primitives[object.first_primitive + k];
        for (std::uint32_t i = 0; i < primitive.index_count; ++i)
          box.extend(scene_.positions[scene_.indices[primitive.first_index + i]]);
      }
      rest.bounds_object = box;
    }
    // The box around the moved object-frame box's corners: it holds every moved vertex.
    object.bounds_world = Aabb{};
    if (rest.bounds_object->empty()) continue;
    for (int corner = 0; corner < 8; ++corner) {
      const glm::vec3 p_object(
          corner & 1 ? rest.bounds_object->p_max.x : rest.bounds_object->p_min.x,
          corner & 2 ? rest.bounds_object->p_max.y : rest.bounds_object->p_min.y,
          corner & 4 ? rest.bounds_object->p_max.z : rest.bounds_object->p_min.z);
      object.bounds_world.extend(glm::vec3(T_world_object * glm::vec4(p_object, 1.0f)));
    }
  }
}

void Session::set_pattern(std::optional<TestPattern> pattern) {
  pattern_rows_up_.clear();
  pattern_ = pattern;
  if (!pattern) return;
  for (std::size_t i = 0; i < display_.outputs.size(); ++i) {
    const SessionOutput& output = display_.outputs[i];
    const std::vector<std::uint8_t> rows_down =
        test_pattern_image(*pattern, output.spec.warp, i, output.spec.name);
    const glm::ivec2 size = output.spec.warp.output_size;
    const std::size_t row_bytes = std::size_t(size.x) * 4;
    std::vector<std::uint8_t> rows_up(rows_down.size());
    for (int y = 0; y < size.y; ++y)
      std::copy_n(&rows_down[flipped_row_start(y, size.y, row_bytes)], row_bytes,
                  &rows_up[std::size_t(y) * row_bytes]);
    pattern_rows_up_.push_back(std::move(rows_up));
  }
}

void Session::set_view_dependent_scene(std::unique_ptr<ViewDependentScene> scene) {
  view_dependent_ = std::move(scene);
  if (view_dependent_) replace_scene(view_dependent_->scene());
}

void Session::replace_scene(const Scene& scene) {
  scene_ = scene;
  rest_poses_.clear();
  for (const Object& object : scene_.objects)
    rest_poses_.push_back({object.T_world_object, object.bounds_world, std::nullopt});
  replace_geometry(gpu_scene_, scene_);
  for (std::size_t i = 0; i < methods_.size(); ++i) {
    const SessionOutput& output = display_.outputs[i];
    RenderSettings settings = display_.settings;  // as the constructor prepared it
    settings.facets.origin.output = output.spec.name;
    methods_[i]->replace_scene(scene_, gpu_scene_, std::span(&output.spec, 1), settings);
  }
}

FrameStats Session::render(const FrameState& state, bool finish) {
  const auto start = std::chrono::steady_clock::now();
  bool rebuilt = false;
  if (view_dependent_ && view_dependent_->update(glm::dvec3(state.T_world_eye[3]))) {
    replace_scene(view_dependent_->scene());
    rebuilt = true;
  }
  place_objects(state.object_poses, animated_object_poses(scene_.animation, state.time_s));
  FrameStats stats;
  stats.frame = state.frame;
  stats.time_s = state.time_s;
  stats.scene_rebuilt = rebuilt;
  const glm::dmat4 T_eye_world = glm::inverse(state.T_world_eye);
  for (std::size_t i = 0; i < methods_.size(); ++i) {
    OutputFrameStats output;
    output.name = display_.outputs[i].spec.name;
    if (pattern_) {
      const glm::ivec2 size = targets_[i].size();
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      glTextureSubImage2D(targets_[i].colour().id(), 0, 0, 0, size.x, size.y, GL_RGBA,
                          GL_UNSIGNED_BYTE, pattern_rows_up_[i].data());
      if (test_pattern_is_blended(*pattern_)) {
        auto scope = timer_.scope("blend");
        blends_[i].apply(targets_[i].colour());
        output.blend_tiles = blends_[i].tiles_listed();
      }
      output.rendered = true;
      stats.outputs.push_back(std::move(output));
      continue;
    }
    targets_[i].clear();
    if (output_sees_scene(i, state.T_world_eye)) {
      output.rendered = true;
      output.render = methods_[i]->render(T_eye_world, std::span(&targets_[i], 1), &timer_);
    }
    {
      auto scope = timer_.scope("blend");
      blends_[i].apply(targets_[i].colour());
    }
    output.blend_tiles = blends_[i].tiles_listed();
    stats.outputs.push_back(std::move(output));
  }
  timer_.end_frame();
  // Timer results arrive a few frames late; report the newest complete frame, summed per pass.
  while (auto frame = timer_.poll(finish)) {
    std::map<std::string, double> sums;
    std::vector<PassTime> ordered;
    for (const PassTime& pass : *frame) {
      if (!sums.contains(pass.pass)) ordered.push_back({pass.pass, 0});
      sums[pass.pass] += pass.milliseconds;
    }
    for (PassTime& pass : ordered) pass.milliseconds = sums[pass.pass];
    last_pass_ms_ = std::move(ordered);
  }
  stats.pass_ms = last_pass_ms_;
  if (finish) glFinish();
  stats.cpu_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace facet::driver
