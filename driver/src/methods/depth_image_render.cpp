// render_depth_image: a scene into a depth image. The facet pipeline finds the triangle seen at
// every pixel (IDs); the CPU then intersects the pixel's exact ray with that triangle's plane.
#include <algorithm>
#include <array>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>

#include "facet/driver/depth_image.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/driver/scene_view.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

float srgb_decode(std::uint8_t value) {
  const float e = float(value) / 255.0f;
  return e <= 0.04045f ? e / 12.92f : std::pow((e + 0.055f) / 1.055f, 2.4f);
}

// Bilinear sample of an sRGB8 image at uv ((0, 0) the first texel's corner), linear RGB.
glm::vec3 sample_texture(const Image& image, glm::vec2 uv, bool repeat,
                         const std::array<float, 256>& decode) {
  if (image.width < 1 || image.height < 1) return glm::vec3(1);
  const float x = uv.x * float(image.width) - 0.5f, y = uv.y * float(image.height) - 0.5f;
  if (!(std::abs(x) < 1e9f && std::abs(y) < 1e9f)) return glm::vec3(1);  // no texel to name
  const float fx = std::floor(x), fy = std::floor(y);
  const auto wrap = [&](long k, int n) {
    if (repeat) return int(((k % n) + n) % n);
    return int(std::clamp<long>(k, 0, n - 1));
  };
  glm::vec3 sum(0);
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const int i = wrap(long(fx) + dx, image.width), j = wrap(long(fy) + dy, image.height);
      const float w = (dx ? x - fx : 1 - (x - fx)) * (dy ? y - fy : 1 - (y - fy));
      const std::uint8_t* texel = &image.rgba[(std::size_t(j) * image.width + i) * 4];
      sum += w * glm::vec3(decode[texel[0]], decode[texel[1]], decode[texel[2]]);
    }
  }
  return sum;
}

}  // namespace

DepthImage render_depth_image(const Scene& scene, const DepthImageRequest& request) {
  check_image_size(request.size, "command line", OptionName{"size"});
  DepthImage image = request.kind == DepthImageKind::dpci
                         ? make_dpci(request.size)
                         : make_planar(request.size, request.fov_x_deg);
  image.T_world_image = request.T_world_image;
  std::int64_t pixels = 0;
  for (const DepthImagePart& part : image.parts) {
    check_image_size(part.size, "command line", OptionName{"size"});
    pixels += std::int64_t(part.size.x) * part.size.y;
  }
  if (pixels > kMaxDepthImagePixels)
    throw InputError("command line", OptionName{"size"},
                     "expected at most " + std::to_string(kMaxDepthImagePixels) +
                         " pixels in all parts together");

  std::vector<OutputSpec> outputs;
  for (const DepthImagePart& part : image.parts) outputs.push_back({part.name, part.warp()});
  const GpuScene gpu = upload_scene(scene);
  auto method = make_render_method("facets");
  RenderSettings settings;
  method->prepare(scene, gpu, outputs, settings);
  std::vector<OutputTarget> targets;
  for (const OutputSpec& output : outputs)
    targets.push_back(OutputTarget::create(output.warp.output_size));
  const glm::dmat4 T_image_world = glm::inverse(image.T_world_image);
  method->render(T_image_world, targets);

  // Triangle ID -> object, primitive and triangle.
  const std::vector<std::uint32_t> base = scene_triangle_base(scene);
  std::array<float, 256> decode{};
  for (int v = 0; v < 256; ++v) decode[std::size_t(v)] = srgb_decode(std::uint8_t(v));
  for (std::size_t p = 0; p < image.parts.size(); ++p) {
    DepthImagePart& part = image.parts[p];
    const std::vector<std::uint32_t> ids = targets[p].read_ids();
    part.source_id.assign(ids.size(), 0);
    for (int j = 0; j < part.size.y; ++j) {
      for (int i = 0; i < part.size.x; ++i) {
        const std::size_t k = part.pixel_index(i, j);
        const std::uint32_t id = ids[k];
        if (id == 0 || id > base.back()) continue;
        const std::size_t o =
            std::size_t(std::upper_bound(base.begin(), base.end(), id - 1) - base.begin()) - 1;
        const Object& object = scene.objects[o];
        std::uint32_t ordinal = id - 1 - base[o];
        const Primitive* primitive = nullptr;
        for (std::uint32_t q = 0; q < object.primitive_count; ++q) {
          const Primitive& candidate = scene.primitives[object.first_primitive + q];
          if (ordinal < candidate.index_count / 3) {
            primitive = &candidate;
            break;
          }
          ordinal -= candidate.index_count / 3;
        }
        if (!primitive) continue;
        const glm::dmat4 T_image_object = T_image_world * glm::dmat4(object.T_world_object);
        const glm::dmat3 N_image_object = glm::transpose(glm::inverse(glm::dmat3(T_image_object)));
        std::array<std::uint32_t, 3> index{};
        std::array<glm::dvec3, 3> corner{};
        for (int c = 0; c < 3; ++c) {
          index[std::size_t(c)] =
              scene.indices[primitive->first_index + 3 * ordinal + std::uint32_t(c)];
          corner[std::size_t(c)] = glm::dvec3(
              T_image_object * glm::dvec4(glm::dvec3(scene.positions[index[std::size_t(c)]]), 1.0));
        }
        // Möller–Trumbore from the eye (the image origin) along the pixel's ray.
        const glm::dvec3 v = part.v_image(i, j);
        const glm::dvec3 e1 = corner[1] - corner[0], e2 = corner[2] - corner[0];
        const glm::dvec3 h = glm::cross(v, e2);
        const double det = glm::dot(e1, h);
        if (std::abs(det) < 1e-18) continue;
        const glm::dvec3 s = -corner[0];
        const double b1 = glm::dot(s, h) / det;
        const glm::dvec3 q = glm::cross(s, e1);
        const double b2 = glm::dot(v, q) / det;
        const double t = glm::dot(e2, q) / det;
        if (!(t > 0) || !std::isfinite(t)) continue;
        // The rasterizer may give a pixel just past a triangle's edge to it: the plane's distance
        // there, the attributes from the nearest point of the triangle.
        glm::dvec3 w(std::max(0.0, 1 - b1 - b2), std::max(0.0, b1), std::max(0.0, b2));
        w /= std::max(w.x + w.y + w.z, 1e-12);
        glm::dvec3 n(0);
        glm::vec2 uv(0);
        for (int c = 0; c < 3; ++c) {
          n += w[c] * glm::dvec3(scene.normals[index[std::size_t(c)]]);
          uv += float(w[c]) * scene.uvs[index[std::size_t(c)]];
        }
        n = N_image_object * n;
        if (!(glm::length(n) > 1e-12)) n = glm::cross(e1, e2);
        n = glm::normalize(n);
        if (glm::dot(n, v) > 0) n = -n;  // two-sided, as the material shades it
        const Material& material = scene.materials[primitive->material];
        glm::vec3 colour(material.base_colour);
        if (material.texture >= 0 && std::size_t(material.texture) < scene.images.size())
          colour *= sample_texture(scene.images[std::size_t(material.texture)], uv, material.repeat,
                                   decode);
        part.distance_m[k] = float(t);
        part.normal[k] = glm::vec3(n);
        part.colour[k] = colour;
        part.source_id[k] = id;
      }
    }
  }
  image.validate("depth image");
  return image;
}

}  // namespace facet::driver

namespace facet::driver {

glm::dmat4 depth_image_pose(const Scene& scene, bool builtin_city, DepthImageKind kind,
                            const std::optional<glm::dvec3>& eye_world) {
  if (eye_world) return glm::translate(glm::dmat4(1.0), *eye_world);
  const SceneView view = choose_scene_view(scene, {}, builtin_city);
  const glm::dmat4 T_world_eye = FrameViews(view, 0.0).T_world_eye(0);
  if (kind == DepthImageKind::planar) return T_world_eye;
  return glm::translate(glm::dmat4(1.0), glm::dvec3(T_world_eye[3]));
}

DepthImage run_depth_image_command(const DepthImageCommand& command) {
  DepthImageRequest request;
  if (command.kind == "dpci") {
    request.kind = DepthImageKind::dpci;
  } else if (command.kind == "planar") {
    request.kind = DepthImageKind::planar;
  } else {
    throw InputError("command line", OptionName{"kind"},
                     "expected planar or dpci; got '" + command.kind + "'");
  }
  if (command.out.empty() || command.out.extension() != ".exr")
    throw InputError("command line", OptionName{"out"},
                     "expected a FILE.exr to write; got '" + command.out.string() + "'");
  check_output_file(command.out, OptionName{"out"});  // before any work
  if (command.size) request.size = *command.size;
  check_image_size(request.size, "command line", OptionName{"size"});
  const SceneName name = parse_scene_name(command.scene);
  {
    std::vector<std::filesystem::path> inputs;
    for (const DepthImageName& image : name.depth_images) inputs.push_back(image.file);
    if (name.kind == SceneName::Kind::file) inputs.push_back(name.file);
    for (const std::filesystem::path& input : inputs)
      refuse_output_over_inputs(command.out, OptionName{"out"}, {input});
  }
  const Scene scene = load_scene(name);
  request.T_world_image =
      depth_image_pose(scene, name.builtin_city(), request.kind, command.eye_world);
  auto context = create_headless_context();
  DepthImage image = render_depth_image(scene, request);
  write_depth_image(command.out, image);
  return image;
}

}  // namespace facet::driver
