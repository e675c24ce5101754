// The only file that includes tiny_gltf.h. Debian ships tinygltf as a shared library with stb
// and nlohmann json built in, so no TINYGLTF_IMPLEMENTATION here: the header only declares.
#include "facet/driver/gltf_loader.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
#include <map>
#include <optional>
#include <string>

#include "facet/driver/material_shader.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {

namespace {

class GltfReader {
 public:
  GltfReader(const tinygltf::Model& model, std::string source)
      : model_(model), source_(std::move(source)) {}

  Scene read() {
    Scene scene;
    read_materials(scene);
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      const int index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (index >= static_cast<int>(model_.scenes.size()))
        fail("scene", "a scene index below " + std::to_string(model_.scenes.size()));
      roots = model_.scenes[static_cast<std::size_t>(index)].nodes;
    } else {
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (const auto& node : model_.nodes)
        for (const int child : node.children)
          if (child >= 0 && child < static_cast<int>(model_.nodes.size()))
            is_child[static_cast<std::size_t>(child)] = true;
      for (std::size_t i = 0; i < model_.nodes.size(); ++i)
        if (!is_child[i]) roots.push_back(static_cast<int>(i));
    }
    animated_ = !model_.animations.empty();
    for (const int root : roots) visit(scene, root, glm::dmat4(1.0), 0, -1);
    if (animated_) read_animations(scene);
    if (needs_default_material_) {
      Material fallback;
      fallback.name = "default";
      scene.materials.push_back(fallback);
      const auto index = static_cast<std::uint32_t>(scene.materials.size() - 1);
      for (auto& primitive : scene.primitives)
        if (primitive.material == no_material) primitive.material = index;
    }
    scene.update_bounds();
    return scene;
  }

 private:
  static constexpr std::uint32_t no_material = 0xffffffffu;
  bool animated_ = false;  // the file has animations: record the node graph

  [[noreturn]] void fail(const std::string& field, const std::string& expected) const {
    throw InputError(source_, field, expected);
  }

  void read_materials(Scene& scene) {
    std::map<int, int> image_of_texture_source;
    for (std::size_t i = 0; i < model_.materials.size(); ++i) {
      const auto& in = model_.materials[i];
      Material out;
      out.name = in.name.empty() ? "material " + std::to_string(i) : in.name;
      const auto& factor = in.pbrMetallicRoughness.baseColorFactor;
      if (factor.size() == 4)
        out.base_colour = glm::vec4(static_cast<float>(factor[0]), static_cast<float>(factor[1]),
                                    static_cast<float>(factor[2]), static_cast<float>(factor[3]));
      const int texture = in.pbrMetallicRoughness.baseColorTexture.index;
      if (texture >= 0) {
        const std::string field = "textures[" + std::to_string(texture) + "]";
        if (texture >= static_cast<int>(model_.textures.size()))
          fail("materials[" + std::to_string(i) + "].pbrMetallicRoughness.baseColorTexture",
               "a texture index below " + std::to_string(model_.textures.size()));
        const auto& t = model_.textures[static_cast<std::size_t>(texture)];
        if (t.source < 0 || t.source >= static_cast<int>(model_.images.size()))
          fail(field + ".source", "an image index below " + std::to_string(model_.images.size()));
        auto [it, inserted] = image_of_texture_source.try_emplace(t.source, -1);
        if (inserted) {
          scene.images.push_back(convert_image(t.source));
          it->second = static_cast<int>(scene.images.size() - 1);
        }
        out.texture = it->second;
        if (t.sampler >= 0 && t.sampler < static_cast<int>(model_.samplers.size()))
          out.repeat = model_.samplers[static_cast<std::size_t>(t.sampler)].wrapS !=
                       TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      }
      out.unlit = in.extensions.count("KHR_materials_unlit") > 0;
      if (in.extras.IsObject() && in.extras.Has("facet_shader"))
        out.shader = read_shader(in.extras.Get("facet_shader"),
                                 "materials[" + std::to_string(i) + "].extras.facet_shader");
      scene.materials.push_back(out);
    }
  }

  // A material's own shading: a built-in material's name, or a .frag file relative to the glTF
  // file's folder (load_material_shader checks it; its error becomes one naming this field).
  MaterialShader read_shader(const tinygltf::Value& value, const std::string& field) const {
    const std::string expected = "a built-in material's name or a GLSL file (*.frag)";
    if (!value.IsString() || value.Get<std::string>().empty()) fail(field, expected);
    std::string name = value.Get<std::string>();
    if (name.ends_with(".frag") && std::filesystem::path(name).is_relative())
      name = (std::filesystem::path(source_).parent_path() / name).string();
    try {
      return load_material_shader(name);
    } catch (const InputError& e) {
      fail(field, expected + ": " + e.source() + ": " + e.expected());
    }
  }

  Image convert_image(int index) const {
    const auto& in = model_.images[static_cast<std::size_t>(index)];
    const std::string field = "images[" + std::to_string(index) + "]";
    if (in.width <= 0 || in.height <= 0 || in.component < 1 || in.component > 4)
      fail(field, "a decoded image (PNG or JPEG) with 1 to 4 channels");
    if (in.bits != 8 && in.bits != 16)
      fail(field, "8 or 16 bits per channel, not " + std::to_string(in.bits));
    const auto w = static_cast<std::size_t>(in.width), h = static_cast<std::size_t>(in.height);
    const auto channels = static_cast<std::size_t>(in.component);
    const std::size_t bytes_per_channel = in.bits == 16 ? 2u : 1u;
    if (in.image.size() < w * h * channels * bytes_per_channel)
      fail(field, "pixel data matching its size");
    Image out;
    out.name = in.name.empty() ? (in.uri.empty() ? field : in.uri) : in.name;
    out.width = in.width;
    out.height = in.height;
    out.rgba.resize(w * h * 4u);
    for (std::size_t p = 0; p < w * h; ++p) {
      auto channel = [&](std::size_t c) -> std::uint8_t {
        const std::size_t at = (p * channels + c) * bytes_per_channel;
        // 16-bit data is little-endian as stb decodes it; keep the high byte.
        return bytes_per_channel == 2 ? in.image[at + 1] : in.image[at];
      };
      std::uint8_t rgba[4] = {0, 0, 0, 255};
      if (channels <= 2) {
        rgba[0] = rgba[1] = rgba[2] = channel(0);
        if (channels == 2) rgba[3] = channel(1);
      } else {
        for (std::size_t c = 0; c < channels; ++c) rgba[c] = channel(c);
      }
      std::memcpy(&out.rgba[p * 4u], rgba, 4);
    }
    return out;
  }

  // glTF animations: every node visit becomes an AnimationNode, every channel an
  // AnimationChannel (morph target weights are skipped).
  void read_animations(Scene& scene) const {
    for (std::size_t i = 0; i < model_.animations.size(); ++i) {
      const auto& in = model_.animations[i];
      const std::string field = "animations[" + std::to_string(i) + "]";
      AnimationClip clip;
      clip.name = in.name.empty() ? field : in.name;
      for (std::size_t j = 0; j < in.channels.size(); ++j) {
        const auto& channel = in.channels[j];
        const std::string channel_field = field + ".channels[" + std::to_string(j) + "]";
        if (channel.target_path == "weights" || channel.target_node < 0) continue;
        if (channel.target_node >= static_cast<int>(model_.nodes.size()))
          fail(channel_field + ".target.node",
               "a node index below " + std::to_string(model_.nodes.size()));
        AnimationChannel out;
        out.node = static_cast<std::uint32_t>(channel.target_node);
        if (channel.target_path == "translation")
          out.path = AnimationPath::translation;
        else if (channel.target_path == "rotation")
          out.path = AnimationPath::rotation;
        else if (channel.target_path == "scale")
          out.path = AnimationPath::scale;
        else
          fail(channel_field + ".target.path", "translation, rotation, scale or weights");
        if (channel.sampler < 0 || channel.sampler >= static_cast<int>(in.samplers.size()))
          fail(channel_field + ".sampler",
               "a sampler index below " + std::to_string(in.samplers.size()));
        const auto& sampler = in.samplers[static_cast<std::size_t>(channel.sampler)];
        const std::string sampler_field =
            field + ".samplers[" + std::to_string(channel.sampler) + "]";
        if (sampler.interpolation.empty() || sampler.interpolation == "LINEAR")
          out.interpolation = AnimationInterpolation::linear;
        else if (sampler.interpolation == "STEP")
          out.interpolation = AnimationInterpolation::step;
        else if (sampler.interpolation == "CUBICSPLINE")
          out.interpolation = AnimationInterpolation::cubic_spline;
        else
          fail(sampler_field + ".interpolation", "LINEAR, STEP or CUBICSPLINE");
        out.times_s = read_floats(sampler.input, 1, sampler_field + ".input");
        if (out.times_s.empty()) fail(sampler_field + ".input", "at least one key time");
        for (std::size_t k = 0; k < out.times_s.size(); ++k)
          if (!(out.times_s[k] >= 0) || (k > 0 && !(out.times_s[k] > out.times_s[k - 1])))
            fail(sampler_field + ".input", "key times >= 0 seconds, strictly increasing");
        const int components = out.path == AnimationPath::rotation ? 4 : 3;
        out.values = read_floats(sampler.output, components, sampler_field + ".output");
        const std::size_t per_key =
            out.interpolation == AnimationInterpolation::cubic_spline ? 3 : 1;
        if (out.values.size() != out.times_s.size() * per_key * std::size_t(components))
          fail(sampler_field + ".output",
               std::to_string(out.times_s.size() * per_key) + " values (" +
                   (per_key == 3 ? "in-tangent, value, out-tangent per key" : "one per key") +
                   "), as many as its input's key times");
        clip.duration_s = std::max(clip.duration_s, double(out.times_s.back()));
        clip.channels.push_back(std::move(out));
      }
      if (!clip.channels.empty()) scene.animation.clips.push_back(std::move(clip));
    }
    if (scene.animation.clips.empty()) scene.animation = {};
  }

  void visit(Scene& scene, int node_index, const glm::dmat4& T_world_parent, int depth,
             std::int32_t parent_entry) {
    const std::string field = "nodes[" + std::to_string(node_index) + "]";
    if (node_index < 0 || node_index >= static_cast<int>(model_.nodes.size()))
      fail(field, "a node index below " + std::to_string(model_.nodes.size()));
    // A valid node graph is a forest, so depth never exceeds the node count.
    if (depth > static_cast<int>(model_.nodes.size())) fail(field, "an acyclic node hierarchy");
    const auto& node = model_.nodes[static_cast<std::size_t>(node_index)];
    const glm::dmat4 T_world_node = T_world_parent * local_transform(node, field);
    std::int32_t entry = -1;
    if (animated_) {
      AnimationNode record;
      record.gltf_node = static_cast<std::uint32_t>(node_index);
      record.parent = parent_entry;
      record.has_matrix = !node.matrix.empty();
      if (record.has_matrix) record.matrix = local_transform(node, field);
      if (node.translation.size() == 3)
        record.translation =
            glm::dvec3(node.translation[0], node.translation[1], node.translation[2]);
      if (node.rotation.size() == 4)
        record.rotation = glm::normalize(
            glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
      if (node.scale.size() == 3)
        record.scale = glm::dvec3(node.scale[0], node.scale[1], node.scale[2]);
      entry = static_cast<std::int32_t>(scene.animation.nodes.size());
      scene.animation.nodes.push_back(record);
    }
    if (node.mesh >= 0) {
      if (node.mesh >= static_cast<int>(model_.meshes.size()))
        fail(field + ".mesh", "a mesh index below " + std::to_string(model_.meshes.size()));
      const auto [first, count] = mesh_primitives(scene, node.mesh);
      Object object;
      object.name = node.name.empty() ? field : node.name;
      object.T_world_object = glm::mat4(T_world_node);
      object.first_primitive = first;
      object.primitive_count = count;
      scene.objects.push_back(std::move(object));
      if (animated_) scene.animation.object_node.push_back(entry);
    }
    if (node.camera >= 0) {
      if (node.camera >= static_cast<int>(model_.cameras.size()))
        fail(field + ".camera", "a camera index below " + std::to_string(model_.cameras.size()));
      const auto& camera = model_.cameras[static_cast<std::size_t>(node.camera)];
      SceneCamera out;
      out.camera_name = camera.name;
      out.name = !node.name.empty() ? node.name : !camera.name.empty() ? camera.name : field;
      out.T_world_camera = rigid_part(T_world_node, field);
      out.orthographic = camera.type == "orthographic";
      scene.cameras.push_back(std::move(out));
    }
    for (const int child : node.children) visit(scene, child, T_world_node, depth + 1, entry);
  }

  // The rotation and translation of a node transform: its axes made orthonormal (scale and
  // shear dropped), keeping -z as the viewing direction and +y as up as far as they allow.
  glm::dmat4 rigid_part(const glm::dmat4& T, const std::string& field) const {
    const glm::dvec3 z_axis(T[2]), y_axis(T[1]);
    const glm::dvec3 x_axis = glm::cross(y_axis, z_axis);
    if (!(glm::length(z_axis) > 0) || !(glm::length(x_axis) > 0))
      fail(field, "a camera node transform that is not degenerate (zero scale)");
    const glm::dvec3 z = glm::normalize(z_axis);
    const glm::dvec3 x = glm::normalize(x_axis);
    const glm::dvec3 y = glm::cross(z, x);
    glm::dmat4 out(1.0);
    out[0] = glm::dvec4(x, 0.0);
    out[1] = glm::dvec4(y, 0.0);
    out[2] = glm::dvec4(z, 0.0);
    out[3] = T[3];
    return out;
  }

  glm::dmat4 local_transform(const tinygltf::Node& node, const std::string& field) const {
    if (!node.matrix.empty()) {
      if (node.matrix.size() != 16) fail(field + ".matrix", "16 numbers");
      return glm::make_mat4(node.matrix.data());  // both column-major
    }
    glm::dmat4 T(1.0);
    if (!node.translation.empty()) {
      if (node.translation.size() != 3) fail(field + ".translation", "3 numbers");
      T[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    glm::dmat4 R(1.0);
    if (!node.rotation.empty()) {
      if (node.rotation.size() != 4) fail(field + ".rotation", "a quaternion (x, y, z, w)");
      const glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
      R = glm::mat4_cast(glm::normalize(q));
    }
    glm::dmat4 S(1.0);
    if (!node.scale.empty()) {
      if (node.scale.size() != 3) fail(field + ".scale", "3 numbers");
      S[0][0] = node.scale[0];
      S[1][1] = node.scale[1];
      S[2][2] = node.scale[2];
    }
    return T * R * S;
  }

  // Reads a mesh once; later instances reuse its primitives.
  std::pair<std::uint32_t, std::uint32_t> mesh_primitives(Scene& scene, int mesh_index) {
    if (const auto it = meshes_.find(mesh_index); it != meshes_.end()) return it->second;
    const auto& mesh = model_.meshes[static_cast<std::size_t>(mesh_index)];
    const auto first = static_cast<std::uint32_t>(scene.primitives.size());
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
      read_primitive(
          scene, mesh.primitives[p],
          "meshes[" + std::to_string(mesh_index) + "].primitives[" + std::to_string(p) + "]");
    const auto range =
        std::pair{first, static_cast<std::uint32_t>(scene.primitives.size()) - first};
    meshes_.emplace(mesh_index, range);
    return range;
  }

  // The accessor's elements as floats, `components` per element. Normalized integer types map
  // to [0, 1]; anything else fails.
  std::vector<float> read_floats(int accessor_index, int components,
                                 const std::string& field) const {
    const auto& accessor = checked_accessor(accessor_index, field);
    const int type_components =
        tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(accessor.type));
    if (type_components != components)
      fail(field, std::to_string(components) + "-component elements");
    const auto [data, stride] = element_data(accessor, field);
    std::vector<float> out(accessor.count * static_cast<std::size_t>(components));
    for (std::size_t i = 0; i < accessor.count; ++i) {
      const unsigned char* element = data + i * stride;
      for (int c = 0; c < components; ++c) {
        float value = 0;
        switch (accessor.componentType) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT:
            std::memcpy(&value, element + 4 * c, 4);
            if (!std::isfinite(value)) fail(field, "finite float components");
            break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            if (!accessor.normalized) fail(field, "float or normalized integer components");
            value = static_cast<float>(element[c]) / 255.0f;
            break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            if (!accessor.normalized) fail(field, "float or normalized integer components");
            std::uint16_t v = 0;
            std::memcpy(&v, element + 2 * c, 2);
            value = static_cast<float>(v) / 65535.0f;
            break;
          }
          default:
            fail(field, "float or normalized unsigned byte/short components");
        }
        out[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)] = value;
      }
    }
    return out;
  }

  std::vector<std::uint32_t> read_indices(int accessor_index, const std::string& field) const {
    const auto& accessor = checked_accessor(accessor_index, field);
    if (accessor.type != TINYGLTF_TYPE_SCALAR) fail(field, "scalar indices");
    const auto [data, stride] = element_data(accessor, field);
    std::vector<std::uint32_t> out(accessor.count);
    for (std::size_t i = 0; i < accessor.count; ++i) {
      const unsigned char* element = data + i * stride;
      switch (accessor.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          out[i] = element[0];
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          std::uint16_t v = 0;
          std::memcpy(&v, element, 2);
          out[i] = v;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
          std::memcpy(&out[i], element, 4);
          break;
        default:
          fail(field, "unsigned byte, short or int indices");
      }
    }
    return out;
  }

  const tinygltf::Accessor& checked_accessor(int index, const std::string& field) const {
    if (index < 0 || index >= static_cast<int>(model_.accessors.size()))
      fail(field, "an accessor index below " + std::to_string(model_.accessors.size()));
    const auto& accessor = model_.accessors[static_cast<std::size_t>(index)];
    if (accessor.sparse.isSparse) fail(field, "a non-sparse accessor (sparse is not supported)");
    if (accessor.bufferView < 0) fail(field, "an accessor with a bufferView");
    return accessor;
  }

  // Start and stride of the accessor's elements, after checking that all lie inside the buffer.
  std::pair<const unsigned char*, std::size_t> element_data(const tinygltf::Accessor& accessor,
                                                            const std::string& field) const {
    if (accessor.bufferView >= static_cast<int>(model_.bufferViews.size()))
      fail(field, "a bufferView index below " + std::to_string(model_.bufferViews.size()));
    const auto& view = model_.bufferViews[static_cast<std::size_t>(accessor.bufferView)];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(model_.buffers.size()))
      fail(field,
           "a bufferView whose buffer index is below " + std::to_string(model_.buffers.size()));
    const auto& buffer = model_.buffers[static_cast<std::size_t>(view.buffer)];
    const int element_size =
        tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(accessor.componentType)) *
        tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(accessor.type));
    if (element_size <= 0) fail(field, "a known component type and element type");
    const int stride = accessor.ByteStride(view);
    if (stride <= 0) fail(field, "a valid byteStride");
    const std::size_t size = static_cast<std::size_t>(element_size);
    const std::size_t step = static_cast<std::size_t>(stride);
    // Offsets, lengths and counts come from the file: compared by subtraction, which cannot
    // overflow the way their sums could.
    const std::size_t buffer_size = buffer.data.size();
    if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset ||
        accessor.byteOffset > view.byteLength)
      fail(field, "elements that lie inside their bufferView and buffer");
    const std::size_t room = view.byteLength - accessor.byteOffset;
    if (accessor.count > 0 && (size > room || accessor.count - 1 > (room - size) / step))
      fail(field, "elements that lie inside their bufferView and buffer");
    return {buffer.data.data() + view.byteOffset + accessor.byteOffset, step};
  }

  void read_primitive(Scene& scene, const tinygltf::Primitive& primitive,
                      const std::string& field) {
    const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN)
      return;  // points and lines carry no surface
    const auto position = primitive.attributes.find("POSITION");
    if (position == primitive.attributes.end())
      fail(field + ".attributes.POSITION", "a POSITION attribute");
    const std::vector<float> p = read_floats(position->second, 3, field + ".attributes.POSITION");
    const std::size_t vertex_count = p.size() / 3;

    std::vector<std::uint32_t> order;
    if (primitive.indices >= 0) {
      order = read_indices(primitive.indices, field + ".indices");
      for (const std::uint32_t index : order)
        if (index >= vertex_count)
          fail(field + ".indices",
               "indices below the vertex count " + std::to_string(vertex_count));
    } else {
      order.resize(vertex_count);
      for (std::size_t i = 0; i < vertex_count; ++i) order[i] = static_cast<std::uint32_t>(i);
    }
    std::vector<std::uint32_t> triangles;  // local vertex indices, three per triangle
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (order.size() % 3 != 0) fail(field, "a triangle list with a multiple of 3 indices");
      triangles = std::move(order);
    } else {
      for (std::size_t i = 2; i < order.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_FAN)
          triangles.insert(triangles.end(), {order[0], order[i - 1], order[i]});
        else if (i % 2 == 0)
          triangles.insert(triangles.end(), {order[i - 2], order[i - 1], order[i]});
        else  // odd strip triangles swap two vertices to keep the winding
          triangles.insert(triangles.end(), {order[i - 1], order[i - 2], order[i]});
      }
    }

    std::vector<float> n, uv;
    if (const auto it = primitive.attributes.find("NORMAL"); it != primitive.attributes.end()) {
      n = read_floats(it->second, 3, field + ".attributes.NORMAL");
      if (n.size() != p.size()) fail(field + ".attributes.NORMAL", "one normal per position");
    }
    if (const auto it = primitive.attributes.find("TEXCOORD_0"); it != primitive.attributes.end()) {
      uv = read_floats(it->second, 2, field + ".attributes.TEXCOORD_0");
      if (uv.size() / 2 != vertex_count) fail(field + ".attributes.TEXCOORD_0", "one per position");
    }

    const auto base = static_cast<std::uint32_t>(scene.positions.size());
    for (std::size_t i = 0; i < vertex_count; ++i) {
      scene.positions.emplace_back(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      scene.normals.emplace_back(n.empty() ? glm::vec3(0)
                                           : glm::vec3(n[3 * i], n[3 * i + 1], n[3 * i + 2]));
      scene.uvs.emplace_back(uv.empty() ? glm::vec2(0) : glm::vec2(uv[2 * i], uv[2 * i + 1]));
    }
    if (n.empty()) {
      // Area-weighted vertex normals: the cross product's length is twice the triangle's area.
      for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const glm::vec3 a = scene.positions[base + triangles[t]];
        const glm::vec3 b = scene.positions[base + triangles[t + 1]];
        const glm::vec3 c = scene.positions[base + triangles[t + 2]];
        const glm::vec3 weighted = glm::cross(b - a, c - a);
        for (int k = 0; k < 3; ++k)
          scene.normals[base + triangles[t + static_cast<std::size_t>(k)]] += weighted;
      }
      for (std::size_t i = 0; i < vertex_count; ++i) {
        glm::vec3& normal = scene.normals[base + i];
        const float length = glm::length(normal);
        normal = length > 0 ? normal / length : glm::vec3(0, 1, 0);
      }
    }

    Primitive out;
    out.first_index = static_cast<std::uint32_t>(scene.indices.size());
    out.index_count = static_cast<std::uint32_t>(triangles.size());
    for (const std::uint32_t index : triangles) scene.indices.push_back(base + index);
    if (primitive.material >= static_cast<int>(model_.materials.size()))
      fail(field + ".material",
           "a material index below " + std::to_string(model_.materials.size()));
    if (primitive.material < 0) {
      out.material = no_material;
      needs_default_material_ = true;
    } else {
      out.material = static_cast<std::uint32_t>(primitive.material);
    }
    scene.primitives.push_back(out);
  }

  const tinygltf::Model& model_;
  std::string source_;
  std::map<int, std::pair<std::uint32_t, std::uint32_t>> meshes_;
  bool needs_default_material_ = false;
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// External buffers and images are read only from the glTF file's own folder or below it, and only
// as regular files: a URI such as ../../etc/passwd, a link leading out, or a FIFO is refused, and
// tinygltf's error names it.
struct UriFolder {
  std::filesystem::path folder;  // canonical

  std::optional<std::string> refusal(const std::string& path) const {
    std::error_code error;
    const std::filesystem::path file = std::filesystem::weakly_canonical(path, error);
    if (error) return "'" + path + "' cannot be resolved (" + error.message() + ")";
    const std::filesystem::path relative = file.lexically_relative(folder);
    if (relative.empty() || relative.is_absolute() || *relative.begin() == "..")
      return "'" + path + "' lies outside the glTF file's folder";
    if (!std::filesystem::is_regular_file(file, error))
      return "'" + path + "' is not a regular file";
    return std::nullopt;
  }
};

// URIs are paths as written: no `~` or `$VAR` expansion (tinygltf's default runs wordexp).
std::string uri_as_written(const std::string& path, void*) { return path; }

bool uri_exists(const std::string& path, void* user) {
  return !static_cast<const UriFolder*>(user)->refusal(path);
}

bool read_uri(std::vector<unsigned char>* out, std::string* err, const std::string& path,
              void* user) {
  if (const auto refused = static_cast<const UriFolder*>(user)->refusal(path)) {
    if (err) *err += *refused + "\n";
    return false;
  }
  return tinygltf::ReadWholeFile(out, err, path, nullptr);
}

}  // namespace

Scene load_gltf(const std::filesystem::path& path) {
  const Activity activity("loading the glTF scene " + path.string());
  const std::string source = path.string();
  const std::string extension = lower(path.extension().string());
  if (extension != ".gltf" && extension != ".glb")
    throw InputError(source, "", "a glTF 2.0 file named *.gltf or *.glb");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(source, "", "an existing, readable glTF file");
  tinygltf::TinyGLTF loader;
  UriFolder uri_folder{
      std::filesystem::weakly_canonical(std::filesystem::absolute(path), ec).parent_path()};
  tinygltf::FsCallbacks callbacks{&uri_exists, &uri_as_written, &read_uri,
                                  &tinygltf::WriteWholeFile, &uri_folder};
  loader.SetFsCallbacks(callbacks);
  tinygltf::Model model;
  std::string error, warning;
  const bool ok = extension == ".glb" ? loader.LoadBinaryFromFile(&model, &error, &warning, source)
                                      : loader.LoadASCIIFromFile(&model, &error, &warning, source);
  if (!ok || !error.empty()) {
    while (!error.empty() && (error.back() == '\n' || error.back() == ' ')) error.pop_back();
    throw InputError(source, "",
                     "a valid glTF 2.0 file (" + (error.empty() ? "parse failed" : error) + ")");
  }
  // glTF 1.0 is a different format; tinygltf reads any version string as 2.0.
  if (!model.asset.version.starts_with("2."))
    throw InputError(source, "asset.version",
                     "\"2.0\" (glTF 2), not \"" + model.asset.version + "\"");
  Scene scene = GltfReader(model, source).read();
  scene.name = path.stem().string();
  return scene;
}

}  // namespace facet::driver
