#include "facet/driver/pattern_presenter.hpp"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <optional>
#include <thread>

#include "../gl/image_rows.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/gl_objects.hpp"
#include "facet/driver/monitors.hpp"
#include "facet/driver/program.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

// A grey 8-bit texture shown as grey: red replicated into green and blue, alpha one.
Texture grey_texture(glm::ivec2 size) {
  Texture texture = Texture::create_2d(GL_R8, size.x, size.y);
  glTextureParameteri(texture.id(), GL_TEXTURE_SWIZZLE_G, GL_RED);
  glTextureParameteri(texture.id(), GL_TEXTURE_SWIZZLE_B, GL_RED);
  glTextureParameteri(texture.id(), GL_TEXTURE_SWIZZLE_A, GL_ONE);
  return texture;
}

// Uploads rows bottom first: GL's row 0 is the bottom of the image.
void upload_grey(const Texture& texture, glm::ivec2 size, std::span<const std::uint8_t> grey) {
  FACET_ASSERT(grey.size() == std::size_t(size.x) * std::size_t(size.y));
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int y = 0; y < size.y; ++y) {
    glTextureSubImage2D(texture.id(), 0, 0, flipped_row(y, size.y), size.x, 1, GL_RED,
                        GL_UNSIGNED_BYTE, grey.data() + std::size_t(y) * std::size_t(size.x));
  }
}

// Draws `texture` 1:1 into the bound framebuffer's top-left size.x × size.y pixels, black around.
void draw_image(const Program& present, const VertexArray& vertex_array, const Texture* texture,
                glm::ivec2 size, glm::ivec2 framebuffer) {
  glDisable(GL_FRAMEBUFFER_SRGB);  // the values go out as they are: the projector applies gamma
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glViewport(0, 0, framebuffer.x, framebuffer.y);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  if (!texture) return;
  const glm::ivec2 origin(0, framebuffer.y - size.y);
  glViewport(origin.x, origin.y, size.x, size.y);
  present.use();
  glUniform2i(0, origin.x, origin.y);
  glUniform2f(1, 1.0f, 1.0f);
  texture->bind_unit(0);
  glBindVertexArray(vertex_array.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

// The top-left size.x × size.y pixels of the bound read framebuffer, red channel, row 0 on top.
std::vector<std::uint8_t> read_grey(glm::ivec2 size, glm::ivec2 framebuffer) {
  std::vector<std::uint8_t> rgba(std::size_t(size.x) * std::size_t(size.y) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, framebuffer.y - size.y, size.x, size.y, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  std::vector<std::uint8_t> grey(std::size_t(size.x) * std::size_t(size.y));
  for (int y = 0; y < size.y; ++y) {
    const std::uint8_t* row = rgba.data() + flipped_row_start(y, size.y, std::size_t(size.x) * 4);
    for (int x = 0; x < size.x; ++x) grey[std::size_t(y) * std::size_t(size.x) + x] = row[4 * x];
  }
  return grey;
}

Program present_program() {
  return ProgramBuilder().shader("output/present.vert").shader("output/present.frag").link();
}

class HeadlessPresenter : public PatternPresenter {
 public:
  HeadlessPresenter(std::vector<glm::ivec2> sizes, std::chrono::milliseconds settle)
      : context_(create_headless_context()), sizes_(std::move(sizes)), settle_(settle) {
    present_ = present_program();
    vertex_array_ = VertexArray::create();
    for (const glm::ivec2 size : sizes_) {
      FACET_ASSERT(size.x > 0 && size.y > 0);
      Output output;
      output.image = grey_texture(size);
      output.colour = Texture::create_2d(GL_RGBA8, size.x, size.y);
      output.framebuffer = Framebuffer::create();
      output.framebuffer.attach(GL_COLOR_ATTACHMENT0, output.colour);
      output.framebuffer.check_complete();
      output.shown.assign(std::size_t(size.x) * std::size_t(size.y), 0);
      outputs_.push_back(std::move(output));
    }
    for (std::size_t k = 0; k < outputs_.size(); ++k) draw(k, false);
    glFinish();
  }

  ~HeadlessPresenter() override {
    context_->make_current();
    outputs_.clear();
    vertex_array_.reset();
    present_.reset();
  }

  std::size_t output_count() const override { return sizes_.size(); }
  glm::ivec2 output_size(std::size_t k) const override { return sizes_.at(k); }

  void show(std::size_t output, std::span<const std::uint8_t> grey) override {
    FACET_ASSERT(output < outputs_.size());
    context_->make_current();
    upload_grey(outputs_[output].image, sizes_[output], grey);
    for (std::size_t k = 0; k < outputs_.size(); ++k) {
      if (k == output || lit_[k]) draw(k, k == output);
    }
    glFinish();
    std::this_thread::sleep_for(settle_);
  }

  void blank() override {
    context_->make_current();
    for (std::size_t k = 0; k < outputs_.size(); ++k) {
      if (lit_[k]) draw(k, false);
    }
    glFinish();
    std::this_thread::sleep_for(settle_);
  }

  const std::vector<std::uint8_t>& shown(std::size_t k) const override {
    return outputs_.at(k).shown;
  }
  bool closed() override { return false; }

 private:
  struct Output {
    Texture image, colour;
    Framebuffer framebuffer;
    std::vector<std::uint8_t> shown;
  };

  void draw(std::size_t k, bool lit) {
    Output& output = outputs_[k];
    glBindFramebuffer(GL_FRAMEBUFFER, output.framebuffer.id());
    draw_image(present_, vertex_array_, lit ? &output.image : nullptr, sizes_[k], sizes_[k]);
    output.shown = read_grey(sizes_[k], sizes_[k]);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    lit_.resize(outputs_.size(), false);
    lit_[k] = lit;
  }

  std::unique_ptr<GlContext> context_;
  std::vector<glm::ivec2> sizes_;
  std::chrono::milliseconds settle_;
  Program present_;
  VertexArray vertex_array_;
  std::vector<Output> outputs_;
  std::vector<bool> lit_ = std::vector<bool>(sizes_.size(), false);
};

class WindowedPresenter : public PatternPresenter {
 public:
  WindowedPresenter(const projection_io::DisplayConfig& display, const std::string& source,
                    std::chrono::milliseconds settle)
      : settle_(settle) {
    const std::vector<MonitorInfo> monitors = list_monitors();
    for (std::size_t i = 0; i < display.projectors.size(); ++i) {
      const projection_io::DisplayProjector& projector = display.projectors[i];
      const std::string field = "projectors[" + std::to_string(i) + "].output";
      const OutputPlacement placement =
          place_output(projector.output, monitors, display.missing_monitor, projector.size, source,
                       field + ".monitor");
      WindowOptions options;
      options.title = "facet capture: " + projector.name;
      options.vsync = true;
      apply_placement(placement, options);
      options.decorated = false;  // no effect full screen
      options.share = windows_.empty() ? nullptr : windows_.front().context.get();
      Window window;
      window.context = std::make_unique<GlfwWindowContext>(options);
      window.size = projector.size;
      window.framebuffer = window.context->framebuffer_size();
      if (window.framebuffer.x < projector.size.x || window.framebuffer.y < projector.size.y) {
        throw InputError(source, field,
                         "an output at least as large as the projector (" +
                             std::to_string(projector.size.x) + "x" +
                             std::to_string(projector.size.y) +
                             "), so that patterns land 1:1 on "
                             "its pixels, but its window is " +
                             std::to_string(window.framebuffer.x) + "x" +
                             std::to_string(window.framebuffer.y) + " (" + placement.how + ")");
      }
      window.shown.assign(std::size_t(projector.size.x) * std::size_t(projector.size.y), 0);
      windows_.push_back(std::move(window));
    }
    windows_.front().context->make_current();
    present_ = present_program();
    for (Window& window : windows_) window.image = grey_texture(window.size);
    for (Window& window : windows_) {
      window.context->make_current();
      window.vertex_array = VertexArray::create();
    }
    for (std::size_t k = 0; k < windows_.size(); ++k) present(k, false);
  }

  ~WindowedPresenter() override {
    for (Window& window : windows_) {
      window.context->make_current();
      window.vertex_array.reset();
    }
    windows_.front().context->make_current();
    for (Window& window : windows_) window.image.reset();
    present_.reset();
  }

  std::size_t output_count() const override { return windows_.size(); }
  glm::ivec2 output_size(std::size_t k) const override { return windows_.at(k).size; }

  void show(std::size_t output, std::span<const std::uint8_t> grey) override {
    FACET_ASSERT(output < windows_.size());
    windows_.front().context->make_current();
    upload_grey(windows_[output].image, windows_[output].size, grey);
    glFinish();  // the other contexts sample the texture next
    for (std::size_t k = 0; k < windows_.size(); ++k) {
      if (k == output || windows_[k].lit) present(k, k == output);
    }
    glfwPollEvents();
    std::this_thread::sleep_for(settle_);
  }

  void blank() override {
    for (std::size_t k = 0; k < windows_.size(); ++k) {
      if (windows_[k].lit) present(k, false);
    }
    glfwPollEvents();
    std::this_thread::sleep_for(settle_);
  }

  const std::vector<std::uint8_t>& shown(std::size_t k) const override {
    return windows_.at(k).shown;
  }

  bool closed() override {
    glfwPollEvents();
    for (const Window& window : windows_) {
      auto* native = static_cast<GLFWwindow*>(window.context->native_window());
      if (window.context->should_close() || glfwGetKey(native, GLFW_KEY_ESCAPE) == GLFW_PRESS) {
        return true;
      }
    }
    return false;
  }

 private:
  struct Window {
    std::unique_ptr<GlfwWindowContext> context;
    glm::ivec2 size{0, 0}, framebuffer{0, 0};
    Texture image;             // made in the first context, shared
    VertexArray vertex_array;  // per context
    std::vector<std::uint8_t> shown;
    bool lit = false;
  };

  // Draws into the back buffer, reads back what will be presented, swaps (vsync) and waits until
  // the swap has been done.
  void present(std::size_t k, bool lit) {
    Window& window = windows_[k];
    window.context->make_current();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    draw_image(present_, window.vertex_array, lit ? &window.image : nullptr, window.size,
               window.framebuffer);
    glReadBuffer(GL_BACK);
    window.shown = read_grey(window.size, window.framebuffer);
    window.context->swap_buffers();
    glFinish();
    window.lit = lit;
  }

  std::chrono::milliseconds settle_;
  std::vector<Window> windows_;
  Program present_;
};

}  // namespace

std::unique_ptr<PatternPresenter> create_headless_presenter(std::vector<glm::ivec2> sizes,
                                                            std::chrono::milliseconds settle) {
  return std::make_unique<HeadlessPresenter>(std::move(sizes), settle);
}

std::unique_ptr<PatternPresenter> create_windowed_presenter(
    const projection_io::DisplayConfig& display, const std::string& source,
    std::chrono::milliseconds settle) {
  FACET_ASSERT(!display.projectors.empty());
  return std::make_unique<WindowedPresenter>(display, source, settle);
}

}  // namespace facet::driver
