#include "facet/projection_io/glc_file.hpp"

#include <cmath>

#include "facet/projection/errors.hpp"
#include "json_fields.hpp"

namespace facet {
namespace {

using json_fields::FieldPath;
using json_fields::Fields;
using json_fields::Json;
using json_fields::to_dvec2;
using json_fields::to_dvec3;
using json_fields::to_int;
using json_fields::to_number;
using json_fields::to_string;

// The camera's frame in the eye frame, camera-like (x right, y down, z forward): "origin" (default
// the eye), and "look_at" with an optional "up" (default: looking down the eye's -z, y up).
GlcFrame frame_from_json(const Json* value, const FieldPath& at) {
  GlcFrame frame;
  frame.axes = glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1));
  if (value == nullptr) return frame;
  Fields fields(*value, at);
  if (const Json* o = fields.optional("origin")) frame.origin = to_dvec3(*o, at["origin"]);
  glm::dvec3 up(0, 1, 0);
  if (const Json* u = fields.optional("up")) up = to_dvec3(*u, at["up"]);
  if (const Json* target = fields.optional("look_at")) {
    frame.axes =
        json_fields::look_at_axes(frame.origin, to_dvec3(*target, at["look_at"]), up, at, "origin");
  }
  fields.finish();
  return frame;
}

SlitLine line_from_json(const Json& value, const FieldPath& at) {
  Fields fields(value, at);
  SlitLine line;
  line.point = to_dvec3(fields.required("point", "a point [x, y, z] in metres"), at["point"]);
  line.direction = to_dvec3(fields.required("direction", "a direction [x, y, z]"), at["direction"]);
  fields.finish();
  return line;
}

double positive(Fields& fields, const std::string& key, const std::string& expected) {
  const FieldPath at = fields.path(key);
  const double value = to_number(fields.required(key, expected), at);
  if (!(value > 0)) at.fail(expected, value);
  return value;
}

PiecewiseGlc camera_from_json(const Json& value, const FieldPath& at) {
  Fields fields(value, at);
  const std::string types =
      "\"generators\", \"cross-slit\", \"pushbroom\", \"pinhole\", \"panorama\" or "
      "\"mirror-sphere\"";
  const std::string type = to_string(fields.required("type", types), at["type"]);
  const glm::ivec2 size =
      json_fields::to_ivec2(fields.required("size", "the output size [width, height] in pixels"),
                            at["size"], "the output size [width, height] in pixels");
  check_glc_size(size, at.source(), at["size"].field());
  const std::string field = at.field();
  PiecewiseGlc camera;
  auto plane_size = [&] {
    return to_dvec2(fields.required("plane_size", "the image plane's [width, height] in metres"),
                    at["plane_size"], "the image plane's [width, height] in metres");
  };
  if (type == "generators") {
    const GlcFrame frame = frame_from_json(fields.optional("frame"), at["frame"]);
    const Json& list = fields.required("generators", "a list of 3 rays");
    if (!list.is_array() || list.size() != 3) at["generators"].fail("a list of 3 rays", list);
    std::array<EyeRay, 3> rays;
    std::array<glm::dvec2, 3> pixels;
    for (std::size_t k = 0; k < 3; ++k) {
      const FieldPath g = at["generators"][k];
      Fields ray(list[k], g);
      rays[k].origin =
          to_dvec3(ray.required("origin", "a point [x, y, z] in metres (frame)"), g["origin"]);
      rays[k].direction =
          to_dvec3(ray.required("direction", "a direction [x, y, z] (frame)"), g["direction"]);
      pixels[k] = to_dvec2(ray.required("pixel", "the ray's image point [x, y] in pixels"),
                           g["pixel"], "the ray's image point [x, y] in pixels");
      ray.finish();
    }
    camera = single_glc(
        Glc::from_frame_rays(frame, rays, pixels, at.source(), at["generators"].field()), size);
  } else if (type == "cross-slit") {
    const GlcFrame frame = frame_from_json(fields.optional("frame"), at["frame"]);
    const SlitLine slit1 =
        line_from_json(fields.required("slit1", "a line {point, direction}"), at["slit1"]);
    const SlitLine slit2 =
        line_from_json(fields.required("slit2", "a line {point, direction}"), at["slit2"]);
    camera = single_glc(cross_slit_glc(frame, slit1, slit2, plane_size(), size, at.source(), field),
                        size);
  } else if (type == "pushbroom") {
    const GlcFrame frame = frame_from_json(fields.optional("frame"), at["frame"]);
    const SlitLine slit =
        line_from_json(fields.required("slit", "a line {point, direction}"), at["slit"]);
    const glm::dvec3 normal =
        to_dvec3(fields.required("sweep_normal",
                                 "the normal [x, y, z] of the plane the rays are parallel to"),
                 at["sweep_normal"]);
    camera = single_glc(pushbroom_glc(frame, slit, normal, plane_size(), size, at.source(), field),
                        size);
  } else if (type == "pinhole") {
    const GlcFrame frame = frame_from_json(fields.optional("frame"), at["frame"]);
    const glm::dvec3 centre =
        to_dvec3(fields.required("centre", "a point [x, y, z] in metres (frame)"), at["centre"]);
    camera = single_glc(pinhole_glc(frame, centre, plane_size(), size, at.source(), field), size);
  } else if (type == "panorama") {
    const double angle = positive(fields, "angle_deg", "degrees in (0, 360]");
    const double radius = positive(fields, "radius", "the circle slit's radius in metres, > 0");
    const double fov = positive(fields, "vertical_fov_deg", "degrees in (0, 180)");
    const int strips = to_int(fields.required("strips", "a number of strips"), at["strips"]);
    camera = circular_panorama(angle, radius, fov, strips, size, at.source(), field);
  } else if (type == "mirror-sphere") {
    const glm::dvec3 centre =
        to_dvec3(fields.required("centre", "the sphere's centre [x, y, z] in metres (eye frame)"),
                 at["centre"]);
    const double radius = positive(fields, "radius", "the sphere's radius in metres, > 0");
    const double fov = positive(fields, "fov_deg", "the viewer's horizontal field in degrees");
    const int rings = to_int(fields.required("rings", "a number of rings"), at["rings"]);
    camera = mirror_sphere(centre, radius, fov, rings, size, at.source(), field);
  } else {
    at["type"].fail(types, value["type"]);
  }
  fields.finish();
  return camera;
}

PiecewiseGlc camera_from_root(const Json& root, const std::string& source) {
  const FieldPath at(source);
  Fields fields(root, at);
  const std::string expected_format = std::string("\"") + kGlcFormat + "\"";
  const Json& format = fields.required("format", expected_format);
  if (!format.is_string() || format.get<std::string>() != kGlcFormat) {
    at["format"].fail(expected_format, format);
  }
  PiecewiseGlc camera =
      camera_from_json(fields.required("camera", "the camera, an object"), at["camera"]);
  fields.finish();
  return camera;
}

}  // namespace

PiecewiseGlc parse_glc_camera(const std::string& text, const std::string& source) {
  return camera_from_root(json_fields::parse(text, source), source);
}

PiecewiseGlc read_glc_camera(const std::filesystem::path& path) {
  return camera_from_root(json_fields::parse_file(path), path.string());
}

}  // namespace facet
