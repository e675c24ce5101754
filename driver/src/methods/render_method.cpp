#include "facet/driver/render_method.hpp"

#include <array>
#include <functional>
#include <utility>

#include "facet/projection/errors.hpp"
#include "render_methods_internal.hpp"

namespace facet::driver {
namespace {

constexpr std::array<std::string_view, 9> kNames = {"facets",  "facets-gs",   "tessellated",
                                                    "cubemap", "perspective", "naive",
                                                    "vertex",  "glc",         "glc-2pass"};

using Factory = std::unique_ptr<RenderMethod> (*)();

// The methods built so far; a listed name with no factory here is not available yet.
const std::array<std::pair<std::string_view, Factory>, 9> kFactories = {{
    {"facets", &detail::make_facet_pipeline},
    {"facets-gs", &detail::make_facet_gs_pipeline},
    {"tessellated", &detail::make_tessellated_pipeline},
    {"cubemap", &detail::make_cubemap_method},
    {"perspective", &detail::make_perspective_method},
    {"naive", &detail::make_naive_method},
    {"vertex", &detail::make_vertex_method},
    {"glc", &detail::make_glc_method},
    {"glc-2pass", &detail::make_glc_2pass_method},
}};

std::string joined_names() {
  std::string text;
  for (std::string_view name : kNames) {
    if (!text.empty()) text += ", ";
    text += name;
  }
  return text;
}

}  // namespace

void RenderMethod::replace_scene(const Scene& scene, const GpuScene& gpu_scene,
                                 std::span<const OutputSpec> outputs,
                                 const RenderSettings& settings) {
  prepare(scene, gpu_scene, outputs, settings);
}

std::span<const std::string_view> render_method_names() { return kNames; }

bool is_glc_method(std::string_view name) { return name == "glc" || name == "glc-2pass"; }

void check_render_method(std::string_view name) {
  for (const auto& [known, factory] : kFactories) {
    if (known == name) return;
  }
  for (std::string_view known : kNames) {
    if (known == name) {
      throw InputError("command line", OptionName{"method"},
                       "method '" + std::string(name) + "' is not available in this build");
    }
  }
  throw InputError("command line", OptionName{"method"},
                   "expected one of " + joined_names() + "; got '" + std::string(name) + "'");
}

std::unique_ptr<RenderMethod> make_render_method(std::string_view name) {
  check_render_method(name);
  for (const auto& [known, factory] : kFactories) {
    if (known == name) return factory();
  }
  FACET_ASSERT(false);
  return nullptr;
}

namespace detail {

void refuse_glc_outputs(std::span<const OutputSpec> outputs, std::string_view method) {
  for (const OutputSpec& output : outputs) {
    if (output.glc) {
      throw InputError("command line", OptionName{"method"},
                       "expected glc or glc-2pass for output '" + output.name +
                           "', a GLC camera's; got " + std::string(method));
    }
  }
}

}  // namespace detail

std::vector<std::uint32_t> scene_triangle_base(const Scene& scene) {
  std::vector<std::uint32_t> base(scene.objects.size() + 1, 0);
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    std::uint32_t triangles = 0;
    for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
      triangles += scene.primitives[object.first_primitive + k].index_count / 3;
    }
    base[o + 1] = base[o] + triangles;
  }
  return base;
}

}  // namespace facet::driver
