// The application API (facet/facet.hpp) over the driver's Session, ContentPass and GL contexts,
// and interop's imports.
#include "facet/facet.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "facet/driver/blend_pass.hpp"
#include "facet/driver/content_pass.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/gl_objects.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/output_images.hpp"
#include "facet/driver/scene.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/driver/session.hpp"
#include "facet/interop/mpcdi.hpp"
#include "facet/interop/sgct_cluster.hpp"
#include "facet/projection/content_projection.hpp"
#include "facet/projection/warp.hpp"

namespace facet {

namespace {

// An imported display (MPCDI, SGCT) as a session display: sRGB encoding, its blend and black
// maps, the import's output placement.
driver::SessionDisplay session_display_from(const interop::ImportedDisplay& imported,
                                            const std::string& source) {
  driver::SessionDisplay display;
  display.source = source;
  display.settings.facets.layout = FacetTolerance{0.25};
  for (const interop::ImportedProjector& projector : imported.projectors) {
    driver::SessionOutput output;
    output.spec.name = projector.name;
    output.spec.warp = projector.warp;
    output.placement = projector.output;
    const projection_io::BlendMap* alpha = projector.blend ? &*projector.blend : nullptr;
    const projection_io::BlendMap* black = projector.black ? &*projector.black : nullptr;
    if (alpha || black) {
      output.blend.size = projector.warp.output_size;
      output.blend.channels =
          (alpha && alpha->channels == 3) || (black && black->channels == 3) ? 3 : 1;
      const auto expand = [&](const projection_io::BlendMap& map) {
        if (map.channels == output.blend.channels) return map.values;
        std::vector<float> rgb(map.values.size() * 3);
        for (std::size_t i = 0; i < map.values.size(); ++i)
          rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = map.values[i];
        return rgb;
      };
      if (alpha) output.blend.alpha = expand(*alpha);
      if (black) output.blend.black = expand(*black);
    }
    display.outputs.push_back(std::move(output));
  }
  return display;
}

bool ends_with_lower(const std::string& text, std::string_view suffix) {
  if (text.size() < suffix.size()) return false;
  std::string tail = text.substr(text.size() - suffix.size());
  std::transform(tail.begin(), tail.end(), tail.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return tail == suffix;
}

// A finite affine matrix, else InputError naming `field`.
void check_affine(const glm::dmat4& T, const std::string& field) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(T[c][r])) throw InputError("API", field, "a matrix of finite numbers");
  if (T[0][3] != 0 || T[1][3] != 0 || T[2][3] != 0 || T[3][3] != 1)
    throw InputError("API", field, "an affine transform: the last row 0, 0, 0, 1");
}

}  // namespace

// ---- Display ----

Display Display::open(const std::string& name, std::optional<glm::ivec2> size) {
  Display display;
  if (ends_with_lower(name, ".mpcdi")) {
    const interop::ImportedDisplay imported =
        interop::import_mpcdi(interop::read_zip_file(name), name);
    display.display_ =
        std::make_shared<driver::SessionDisplay>(session_display_from(imported, name));
  } else if (ends_with_lower(name, ".xml")) {
    const interop::ImportedDisplay imported = interop::import_sgct_cluster(name, {});
    display.display_ =
        std::make_shared<driver::SessionDisplay>(session_display_from(imported, name));
  } else {
    display.display_ =
        std::make_shared<driver::SessionDisplay>(driver::load_session_display(name, size));
  }
  if (display.display_->outputs.empty())
    throw InputError(name, "projectors", "a display with at least one projector");
  return display;
}

std::size_t Display::output_count() const { return display_->outputs.size(); }

std::string Display::output_name(std::size_t output) const {
  return display_->outputs.at(output).spec.name;
}

glm::ivec2 Display::output_size(std::size_t output) const {
  return display_->outputs.at(output).spec.warp.output_size;
}

void Display::set_method(const std::string& method) {
  driver::check_render_method(method);
  display_ = std::make_shared<driver::SessionDisplay>(*display_);
  display_->method = method;
}

const std::string& Display::method() const { return display_->method; }

void Display::set_tolerance_px(double tolerance_px) {
  if (!(tolerance_px > 0) || !std::isfinite(tolerance_px))
    throw InputError("API", "tolerance_px", "a positive number of output pixels");
  display_ = std::make_shared<driver::SessionDisplay>(*display_);
  display_->settings.facets.layout = FacetTolerance{tolerance_px};
  display_->settings.facets.origin.source = "API";
  display_->settings.facets.origin.field = "tolerance_px";
}

void Display::set_material_shader(const std::string& name_or_file) {
  driver::MaterialShader material = driver::load_material_shader(name_or_file);
  display_ = std::make_shared<driver::SessionDisplay>(*display_);
  display_->settings.material = std::move(material);
}

void Display::scale(double factor) {
  auto scaled = std::make_shared<driver::SessionDisplay>(*display_);
  driver::scale_session_display(*scaled, factor);
  display_ = std::move(scaled);
}

Display::Frustum Display::frustum(std::size_t output) const {
  const driver::SessionOutput& out = display_->outputs.at(output);
  const facet::Frustum covering = covering_frustum(out.spec.warp, out.spec.name);
  Frustum result;
  result.R_eye_view = covering.R_eye_frustum;
  result.tan_extent = covering.tan_extent;
  return result;
}

glm::dmat4 Display::Frustum::projection(double z_near, double z_far) const {
  facet::Frustum frustum;
  frustum.R_eye_frustum = R_eye_view;
  frustum.tan_extent = tan_extent;
  return frustum.gl_projection(z_near, z_far);
}

// ---- Scene ----

Scene Scene::load(const std::string& name) {
  Scene scene;
  scene.scene_ = std::make_shared<const driver::Scene>(driver::load_scene(name));
  return scene;
}

std::size_t Scene::object_count() const { return scene_ ? scene_->objects.size() : 0; }

std::size_t Scene::triangle_count() const { return scene_ ? scene_->triangle_count() : 0; }

std::optional<ObjectId> Scene::find_object(std::string_view name) const {
  if (!scene_) return std::nullopt;
  for (std::size_t o = 0; o < scene_->objects.size(); ++o)
    if (scene_->objects[o].name == name) return ObjectId(o);
  return std::nullopt;
}

std::pair<glm::vec3, glm::vec3> Scene::bounds_world() const {
  const driver::Aabb box = scene_ ? scene_->bounds_world() : driver::Aabb{};
  return {box.p_min, box.p_max};
}

SceneBuilder::SceneBuilder() : scene_(std::make_unique<driver::Scene>()) {
  scene_->name = "application";
}
SceneBuilder::~SceneBuilder() = default;
SceneBuilder::SceneBuilder(SceneBuilder&&) noexcept = default;
SceneBuilder& SceneBuilder::operator=(SceneBuilder&&) noexcept = default;

int SceneBuilder::add_texture(const TextureData& texture) {
  const std::string field = "textures[" + std::to_string(scene_->images.size()) + "]";
  if (texture.width < 1 || texture.height < 1 || texture.width > kMaxImageSide ||
      texture.height > kMaxImageSide)
    throw InputError("API", field + ".width/height",
                     "1 to " + std::to_string(kMaxImageSide) + " pixels a side");
  if (texture.rgba.size() != std::size_t(texture.width) * std::size_t(texture.height) * 4)
    throw InputError("API", field + ".rgba", "width · height · 4 bytes");
  driver::Image image;
  image.name = field;
  image.width = texture.width;
  image.height = texture.height;
  image.rgba.assign(texture.rgba.begin(), texture.rgba.end());
  scene_->images.push_back(std::move(image));
  return int(scene_->images.size() - 1);
}

int SceneBuilder::add_material(const MaterialData& material) {
  const std::string field = "materials[" + std::to_string(scene_->materials.size()) + "]";
  if (material.texture < -1 || material.texture >= int(scene_->images.size()))
    throw InputError("API", field + ".texture",
                     "-1 or a texture index below " + std::to_string(scene_->images.size()));
  for (int c = 0; c < 4; ++c)
    if (!std::isfinite(material.base_colour[c]))
      throw InputError("API", field + ".base_colour", "finite numbers");
  driver::Material out;
  out.name = field;
  out.base_colour = material.base_colour;
  out.texture = material.texture;
  out.repeat = material.repeat;
  out.unlit = material.unlit;
  if (!material.shader.empty()) {
    try {
      out.shader = driver::load_material_shader(material.shader);
    } catch (const InputError& e) {
      throw InputError("API", field + ".shader", e.source() + ": " + e.expected());
    }
  }
  scene_->materials.push_back(out);
  return int(scene_->materials.size() - 1);
}

int SceneBuilder::add_mesh(const MeshData& mesh, int material) {
  const std::string field = "meshes[" + std::to_string(meshes_.size()) + "]";
  const std::size_t n = mesh.positions.size();
  if (material < 0 || material >= int(scene_->materials.size()))
    throw InputError("API", field + ".material",
                     "a material index below " + std::to_string(scene_->materials.size()));
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    throw InputError("API", field + ".normals", "none, or one per position");
  if (!mesh.uvs.empty() && mesh.uvs.size() != n)
    throw InputError("API", field + ".uvs", "none, or one per position");
  if (mesh.indices.size() % 3 != 0)
    throw InputError("API", field + ".indices", "a triangle list (a multiple of 3)");
  const std::uint64_t base = scene_->positions.size();
  if (base + n > std::numeric_limits<std::uint32_t>::max() ||
      scene_->indices.size() + mesh.indices.size() > std::numeric_limits<std::uint32_t>::max())
    throw InputError("API", field, "fewer than 2^32 vertices and indices in the scene");
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(mesh.positions[i][c]))
        throw InputError("API", field + ".positions[" + std::to_string(i) + "]",
                         "finite coordinates");
  for (std::size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= n)
      throw InputError("API", field + ".indices[" + std::to_string(i) + "]",
                       "an index below " + std::to_string(n) + " (the positions)");
  const auto first_index = std::uint32_t(scene_->indices.size());
  scene_->positions.insert(scene_->positions.end(), mesh.positions.begin(), mesh.positions.end());
  if (mesh.uvs.empty())
    scene_->uvs.resize(scene_->positions.size(), glm::vec2(0.0f));
  else
    scene_->uvs.insert(scene_->uvs.end(), mesh.uvs.begin(), mesh.uvs.end());
  if (!mesh.normals.empty()) {
    scene_->normals.insert(scene_->normals.end(), mesh.normals.begin(), mesh.normals.end());
  } else {
    // Area-weighted vertex normals (the cross product's length is twice the area).
    std::vector<glm::vec3> normals(n, glm::vec3(0.0f));
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
      const glm::vec3 &a = mesh.positions[mesh.indices[t]],
                      &b = mesh.positions[mesh.indices[t + 1]],
                      &c = mesh.positions[mesh.indices[t + 2]];
      const glm::vec3 weighted = glm::cross(b - a, c - a);
      for (int k = 0; k < 3; ++k) normals[mesh.indices[t + std::size_t(k)]] += weighted;
    }
    for (glm::vec3& normal : normals) {
      const float length = glm::length(normal);
      normal = length > 0 ? normal / length : glm::vec3(0, 1, 0);
    }
    scene_->normals.insert(scene_->normals.end(), normals.begin(), normals.end());
  }
  for (const std::uint32_t index : mesh.indices)
    scene_->indices.push_back(std::uint32_t(base) + index);
  scene_->primitives.push_back(
      {first_index, std::uint32_t(mesh.indices.size()), std::uint32_t(material)});
  meshes_.emplace_back(std::uint32_t(scene_->primitives.size() - 1), 1);
  return int(meshes_.size() - 1);
}

ObjectId SceneBuilder::add_object(int mesh, const glm::dmat4& T_world_object,
                                  const std::string& name) {
  const std::string field = "objects[" + std::to_string(scene_->objects.size()) + "]";
  if (mesh < 0 || mesh >= int(meshes_.size()))
    throw InputError("API", field + ".mesh",
                     "a mesh index below " + std::to_string(meshes_.size()));
  check_affine(T_world_object, field + ".T_world_object");
  driver::Object object;
  object.name = name.empty() ? field : name;
  object.T_world_object = glm::mat4(T_world_object);
  object.first_primitive = meshes_[std::size_t(mesh)].first;
  object.primitive_count = meshes_[std::size_t(mesh)].second;
  scene_->objects.push_back(std::move(object));
  return ObjectId(scene_->objects.size() - 1);
}

Scene SceneBuilder::build() && {
  scene_->update_bounds();
  Scene scene;
  scene.scene_ = std::shared_ptr<const driver::Scene>(std::move(scene_));
  scene_ = std::make_unique<driver::Scene>();
  meshes_.clear();
  return scene;
}

// ---- Context ----

Context::Context(Context&&) noexcept = default;
Context& Context::operator=(Context&&) noexcept = default;
Context::~Context() = default;

Context Context::headless() {
  Context context;
  try {
    context.owned_ = driver::create_headless_context();
  } catch (const driver::GlContextError& e) {
    throw ContextError(e.what());
  }
  return context;
}

Context Context::window(glm::ivec2 size, const std::string& title) {
  Context context;
  driver::WindowOptions options;
  options.width = size.x;
  options.height = size.y;
  options.title = title;
  try {
    context.owned_ = driver::create_window_context(options);
  } catch (const driver::GlContextError& e) {
    throw ContextError(e.what());
  }
  return context;
}

Context Context::borrow_current() {
  // With no context current, glGetString(GL_VERSION) returns null and epoxy_gl_version 0.
  if (epoxy_gl_version() == 0)
    throw ContextError("borrow_current: no GL context is current on this thread");
  GLint major = 0, minor = 0, mask = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  if (major * 10 + minor < 45 || !(mask & GL_CONTEXT_CORE_PROFILE_BIT))
    throw ContextError("borrow_current: the current context is GL " + std::to_string(major) + "." +
                       std::to_string(minor) + "; facet needs 4.5 core");
  Context context;
  context.borrowed_ = true;
  return context;
}

void Context::make_current() {
  if (owned_) owned_->make_current();
}

bool Context::is_borrowed() const { return borrowed_; }

void Context::swap() {
  if (!owned_) return;
  owned_->swap_buffers();
  if (auto* window = dynamic_cast<driver::GlfwWindowContext*>(owned_.get())) window->poll_events();
}

bool Context::should_close() const {
  const auto* window = dynamic_cast<const driver::GlfwWindowContext*>(owned_.get());
  return window && window->should_close();
}

std::string Context::renderer() const {
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return name ? name : "";
}

// ---- Renderer ----

struct Renderer::Impl {
  std::shared_ptr<driver::SessionDisplay> display;
  std::optional<driver::Session> session;  // with a scene
  // Without a scene (mode 2 only): the outputs' targets and blends.
  std::vector<driver::OutputTarget> targets;
  std::vector<driver::BlendPass> blends;
  std::optional<driver::ContentPass> content_pass;  // made on the first warp_perspective
  std::map<std::size_t, driver::ContentTexture> content;
  std::vector<Display::Frustum> frusta;
  driver::FrameState state;
  std::map<ObjectId, glm::dmat4> moved;
  std::size_t object_count = 0;
  driver::Framebuffer present_source, copy_source, copy_target;
  std::vector<driver::Texture> raw_views;  // RGBA8 views of the colour targets, for present

  const driver::OutputTarget& target(std::size_t output) const {
    if (output >= display->outputs.size())
      throw InputError("API", "output",
                       "an output index below " + std::to_string(display->outputs.size()));
    return session ? session->targets()[output] : targets[output];
  }
};

namespace {

// The application's framebuffer bindings and viewport, put back when facet is done.
class KeepFramebuffers {
 public:
  KeepFramebuffers() {
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_);
    glGetIntegerv(GL_VIEWPORT, viewport_);
  }
  KeepFramebuffers(const KeepFramebuffers&) = delete;
  KeepFramebuffers& operator=(const KeepFramebuffers&) = delete;
  ~KeepFramebuffers() {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(draw_));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(read_));
    glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
  }

 private:
  GLint draw_ = 0, read_ = 0, viewport_[4] = {0, 0, 0, 0};
};

void require_context() {
  if (epoxy_gl_version() == 0)
    throw ContextError("facet::Renderer: no GL context is current on this thread");
}
}  // namespace

Renderer::Renderer(const Display& display, const Scene& scene) : impl_(std::make_unique<Impl>()) {
  require_context();
  impl_->display = display.display_;
  impl_->session.emplace(*impl_->display, scene.scene_ ? *scene.scene_ : driver::Scene{});
  impl_->object_count = scene.object_count();
}

Renderer::Renderer(const Display& display) : impl_(std::make_unique<Impl>()) {
  require_context();
  impl_->display = display.display_;
  for (const driver::SessionOutput& output : impl_->display->outputs) {
    impl_->targets.push_back(driver::OutputTarget::create(output.spec.warp.output_size));
    impl_->blends.emplace_back(output.spec.warp.output_size, output.blend, output.encoding);
  }
}

Renderer::~Renderer() = default;

void Renderer::set_frame(const FrameInfo& frame) {
  check_affine(frame.T_world_eye, "T_world_eye");
  impl_->state.frame = frame.frame;
  impl_->state.time_s = frame.time_s;
  impl_->state.T_world_eye = frame.T_world_eye;
}

void Renderer::set_object_transform(ObjectId object, const glm::dmat4& T_world_object) {
  if (object >= impl_->object_count)
    throw InputError("API", "object",
                     "an object index below " + std::to_string(impl_->object_count));
  check_affine(T_world_object, "T_world_object");
  impl_->moved[object] = T_world_object;
}

void Renderer::reset_object_transform(ObjectId object) {
  if (object >= impl_->object_count)
    throw InputError("API", "object",
                     "an object index below " + std::to_string(impl_->object_count));
  impl_->moved.erase(object);
}

FrameReport Renderer::render(bool finish) {
  const KeepFramebuffers keep;
  FrameReport report;
  report.frame = impl_->state.frame;
  if (!impl_->session) {
    for (std::size_t i = 0; i < impl_->targets.size(); ++i) {
      impl_->targets[i].clear();
      impl_->blends[i].apply(impl_->targets[i].colour());
      report.outputs.push_back({impl_->display->outputs[i].spec.name, false, 0, 0, false});
    }
    return report;
  }
  impl_->state.object_poses.clear();
  for (const auto& [object, T_world_object] : impl_->moved)
    impl_->state.object_poses.push_back({object, T_world_object});
  const driver::FrameStats stats = impl_->session->render(impl_->state, finish);
  report.cpu_ms = stats.cpu_ms;
  for (const driver::OutputFrameStats& output : stats.outputs)
    report.outputs.push_back({output.name, output.rendered, output.render.triangles_in,
                              output.render.replicas, output.render.reused_replication});
  return report;
}

namespace {

// The application's texture `texture` (2D, or a cube map with `cube`; RGBA8 or SRGB8_ALPHA8),
// checked; the size of its content image (a cube map's: its six faces side by side).
glm::ivec2 application_texture_size(unsigned int texture, bool cube, const std::string& source) {
  const std::string kind = cube ? "cube-map" : "2D";
  if (texture == 0 || !glIsTexture(texture))
    throw InputError("API", source, "the name of a " + kind + " texture of the current context");
  GLint target = 0, width = 0, height = 0, format = 0;
  glGetTextureParameteriv(texture, GL_TEXTURE_TARGET, &target);
  if (target != GLint(cube ? GL_TEXTURE_CUBE_MAP : GL_TEXTURE_2D))
    throw InputError("API", source, "a " + kind + " texture; this one has another target");
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_WIDTH, &width);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_HEIGHT, &height);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
  if (width < 1 || height < 1 || (format != GL_RGBA8 && format != GL_SRGB8_ALPHA8))
    throw InputError("API", source, "an RGBA8 or SRGB8_ALPHA8 " + kind + " texture with pixels");
  if (!cube) return {width, height};
  if (width != height)
    throw InputError(
        "API", source,
        "a cube map of square faces; got " + std::to_string(width) + "x" + std::to_string(height));
  return {6 * width, height};
}

}  // namespace

void Renderer::warp_content(const std::vector<std::size_t>& outputs, unsigned int texture,
                            const ContentProjection& projection, std::size_t key,
                            const std::string& source) {
  if (impl_->session)
    throw InputError("API", source, "a Renderer made without a scene (Renderer(display))");
  const bool cube = projection.format == ContentFormat::cubemap;
  const glm::ivec2 size = application_texture_size(texture, cube, source);
  const KeepFramebuffers keep;
  if (!impl_->content_pass) {
    std::vector<driver::OutputSpec> specs;
    for (const driver::SessionOutput& out : impl_->display->outputs) specs.push_back(out.spec);
    impl_->content_pass.emplace(specs);
    impl_->copy_source = driver::Framebuffer::create();
    impl_->copy_target = driver::Framebuffer::create();
  }
  auto it = impl_->content.find(key);
  if (it == impl_->content.end() || it->second.image_size() != size ||
      it->second.format() != projection.format) {
    impl_->content.erase(key);
    it = impl_->content
             .emplace(key, driver::ContentTexture(projection.format, size,
                                                  driver::ContentImage::Pixels::srgb8, source))
             .first;
  }
  const driver::Texture& content = it->second.texture();
  if (cube) {
    // Both are GL cube maps with the same face layout: the bytes of all six faces as they are
    // (RGBA8 and SRGB8_ALPHA8 copy into each other unconverted).
    glCopyImageSubData(texture, GL_TEXTURE_CUBE_MAP, 0, 0, 0, 0, content.id(), GL_TEXTURE_CUBE_MAP,
                       0, 0, 0, 0, size.y, size.y, 6);
  } else {
    // The application's texture has GL's row order (row 0 at the bottom), content images row 0
    // at the top: copy the bytes upside down (a blit with FRAMEBUFFER_SRGB off converts nothing).
    glNamedFramebufferTexture(impl_->copy_source.id(), GL_COLOR_ATTACHMENT0, texture, 0);
    glNamedFramebufferTexture(impl_->copy_target.id(), GL_COLOR_ATTACHMENT0, content.id(), 0);
    const GLboolean srgb = glIsEnabled(GL_FRAMEBUFFER_SRGB);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glBlitNamedFramebuffer(impl_->copy_source.id(), impl_->copy_target.id(), 0, 0, size.x, size.y,
                           0, size.y, size.x, 0, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    if (srgb) glEnable(GL_FRAMEBUFFER_SRGB);
  }
  glGenerateTextureMipmap(content.id());
  for (const std::size_t output : outputs) {
    driver::OutputTarget& target = impl_->targets[output];
    target.clear();
    target.bind();
    impl_->content_pass->draw(output, it->second, projection);
    impl_->blends[output].apply(target.colour());
  }
}

void Renderer::warp_perspective(std::size_t output, unsigned int texture) {
  const std::string source = "warp_perspective(" + std::to_string(output) + ")";
  if (output >= impl_->display->outputs.size())
    throw InputError("API", source,
                     "an output index below " + std::to_string(impl_->display->outputs.size()));
  if (impl_->frusta.empty()) {
    for (const driver::SessionOutput& out : impl_->display->outputs) {
      const facet::Frustum covering = covering_frustum(out.spec.warp, out.spec.name);
      impl_->frusta.push_back({covering.R_eye_frustum, covering.tan_extent});
    }
  }
  ContentProjection projection;
  projection.format = ContentFormat::perspective;
  projection.R_eye_content = impl_->frusta[output].R_eye_view;
  projection.tan_extent = impl_->frusta[output].tan_extent;
  warp_content({output}, texture, projection, output, source);
}

void Renderer::warp_image(unsigned int texture, ImageKind kind, double fisheye_fov_deg) {
  const std::string source = "warp_image";
  warp_whole_view(
      texture, kind == ImageKind::fisheye ? fisheye_content(fisheye_fov_deg) : equirect_content(),
      source);
}

void Renderer::warp_cubemap(unsigned int texture) {
  warp_whole_view(texture, cubemap_content(), "warp_cubemap");
}

void Renderer::warp_whole_view(unsigned int texture, const ContentProjection& projection,
                               const std::string& source) {
  projection.validate(source);
  std::vector<std::size_t> outputs(impl_->display->outputs.size());
  for (std::size_t i = 0; i < outputs.size(); ++i) outputs[i] = i;
  warp_content(outputs, texture, projection, std::numeric_limits<std::size_t>::max(), source);
}

std::size_t Renderer::output_count() const { return impl_->display->outputs.size(); }

glm::ivec2 Renderer::output_size(std::size_t output) const { return impl_->target(output).size(); }

unsigned int Renderer::output_texture(std::size_t output) const {
  return impl_->target(output).colour().id();
}

void Renderer::present(std::size_t output, const glm::ivec4& viewport) const {
  const driver::OutputTarget& target = impl_->target(output);
  if (impl_->raw_views.empty()) {
    for (std::size_t i = 0; i < output_count(); ++i)
      impl_->raw_views.push_back(driver::Texture::create_view(impl_->target(i).colour(), GL_RGBA8));
    impl_->present_source = driver::Framebuffer::create();
  }
  GLint draw_framebuffer = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_framebuffer);
  glNamedFramebufferTexture(impl_->present_source.id(), GL_COLOR_ATTACHMENT0,
                            impl_->raw_views[output].id(), 0);
  const GLboolean srgb = glIsEnabled(GL_FRAMEBUFFER_SRGB);
  glDisable(GL_FRAMEBUFFER_SRGB);
  const glm::ivec2 size = target.size();
  glBlitNamedFramebuffer(impl_->present_source.id(), GLuint(draw_framebuffer), 0, 0, size.x, size.y,
                         viewport.x, viewport.y, viewport.x + viewport.z, viewport.y + viewport.w,
                         GL_COLOR_BUFFER_BIT,
                         size == glm::ivec2(viewport.z, viewport.w) ? GL_NEAREST : GL_LINEAR);
  if (srgb) glEnable(GL_FRAMEBUFFER_SRGB);
}

std::vector<std::uint8_t> Renderer::read_output_rgba8(std::size_t output) const {
  return impl_->target(output).read_colour_rgba8();
}

std::vector<std::uint32_t> Renderer::read_output_ids(std::size_t output) const {
  return impl_->target(output).read_ids();
}

void Renderer::write_output_png(std::size_t output, const std::filesystem::path& path) const {
  const driver::OutputTarget& target = impl_->target(output);
  driver::write_png_rgba8(path, target.size(), target.read_colour_rgba8());
}

}  // namespace facet
