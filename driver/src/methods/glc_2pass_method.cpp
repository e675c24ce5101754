// Two-pass GLC rasterization ("glc-2pass"; Yu, Yu & McMillan, "Towards multi-perspective
// rasterization", The Visual Computer 25, 2009), for an output given as a *.glc.json camera
// (OutputSpec::glc), one GLC piece at a time as the paper renders a piecewise camera.
//
// Pass 1 ("samples"): the scene is rasterized through a proxy pinhole of the piece, a perspective
// camera whose frustum holds every point the piece's rays reach at frame depth z_near or beyond:
// its centre is the point nearest (least squares) to the piece's rays, moved back along their mean
// direction until that whole volume lies in front of it within 75° of its axis. Every vertex
// carries the piece's GLC projection coefficients (glc/glc_sample.vert: the 2×2 system of the
// closed-form projection, affine in the point), the rasterizer interpolates them, and every
// sample solves them for its GLC image point (glc/glc_sample.frag), written beside its shaded
// colour (the material interface, as every method shades) and its triangle ID. The samples of all
// pieces share one atlas, kSamplesPerPixel per output pixel along each axis where the proxy's
// tangent plane is as dense as the GLC's image at infinity. Points at frame depth below z_near are
// clipped, since the GLC does not see them.
//
// Pass 2 ("splat"): every cell of four neighbouring samples becomes two triangles at the
// samples' GLC image points (glc/glc_splat.vert), depth-tested, so that no holes open between
// samples however the GLC stretches the proxy's image; a sample that saw nothing goes to infinity
// along its proxy ray. A fragment takes the colour and ID of the nearest sample in the grid and
// is kept where its pixel belongs to the piece (the camera's piece map, the oracle's).
//
// Its errors are those of the paper's method: visibility is the proxy's, not the GLC's, so where
// their rays part (at depth edges) the GLC may see surface the proxy did not sample, which the
// triangles across the edge stretch over; and edges lie where the nearest sample changes, within
// about half a sample of the exact ones.
#include <algorithm>
#include <array>
#include <cmath>
#include <glm/gtc/matrix_access.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>

#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/perspective_image.hpp"
#include "facet/driver/program.hpp"
#include "facet/projection/errors.hpp"
#include "material_programs.hpp"
#include "object_baseline.hpp"
#include "render_methods_internal.hpp"
#include "replication_common.hpp"

namespace facet::driver::detail {
namespace {

// Pass-1 samples per output pixel along each axis (where the proxy is as dense as the GLC).
constexpr double kSamplesPerPixel = 2.0;
// The proxy pinhole's widest half-angle from its axis.
constexpr double kMaxProxyHalfAngleDeg = 75.0;
// The sample atlas' side at most (GL guarantees 16384 on the drivers facet runs on).
constexpr int kMaxAtlasSide = 16384;
// Pass-2 cells per draw: llvmpipe's draw module costs time quadratic in a draw's batch
// (replication_common.hpp).
constexpr std::size_t kCellsPerDraw = 4096;

// A piece's proxy pinhole: centre (eye frame), frustum about it and the samples' rectangle in the
// atlas.
struct Proxy {
  glm::dvec3 centre{0.0};
  Frustum frustum;
  double near = 0;
  glm::ivec2 size{2, 2};        // samples
  glm::ivec2 origin{0, 0};      // in the atlas, GL rows from the bottom
  std::size_t first_index = 0;  // its cells' triangles in the output's grid indices
};

// The pixel points whose rays a piece's proxy must hold: the centres of the pixels at the ends of
// the piece's runs of owned pixels in every row (their convex hull holds every owned pixel centre,
// the only ones pass 2 shades, and a piece's rays are affine in the pixel). Not the pixels'
// corners: a mirror's piece is a few pixels wide, and its rays extrapolated to a corner outside
// the reflector triangle may turn far from the ones it casts.
std::vector<std::vector<glm::dvec2>> piece_outlines(const PiecewiseGlc& camera) {
  std::vector<std::vector<glm::dvec2>> outlines(camera.pieces.size());
  for (int y = 0; y < camera.size.y; ++y) {
    const std::int32_t* row = camera.piece_of_pixel.data() + std::size_t(y) * camera.size.x;
    int start = 0;
    for (int x = 1; x <= camera.size.x; ++x) {
      if (x < camera.size.x && row[x] == row[start]) continue;
      if (row[start] >= 0) {
        std::vector<glm::dvec2>& points = outlines[std::size_t(row[start])];
        points.push_back({start + 0.5, y + 0.5});
        if (x - 1 > start) points.push_back({x - 0.5, y + 0.5});
      }
      start = x;
    }
  }
  return outlines;
}

// The proxy of `glc` over the pixel points `outline` (piece_outlines) within the pixel box `box`
// (x0, y0, x1, y1), for frame depths >= z_near.
Proxy make_proxy(const Glc& glc, const glm::ivec4& box, const std::vector<glm::dvec2>& outline,
                 double z_near) {
  std::vector<EyeRay> rays;
  for (const glm::dvec2& p : outline) rays.push_back(glc.ray(p));
  glm::dvec3 axis(0.0), mean_origin(0.0);
  glm::dmat3 a(0.0);
  glm::dvec3 b(0.0);
  for (const EyeRay& r : rays) {
    const glm::dvec3 d = glm::normalize(r.direction);
    axis += d;
    mean_origin += r.origin;
    const glm::dmat3 m = glm::dmat3(1.0) - glm::outerProduct(d, d);
    a += m;
    b += m * r.origin;
  }
  axis = glm::normalize(axis);
  mean_origin /= double(rays.size());
  // The least-squares point of the rays' lines; near-parallel rays have none worth taking.
  glm::dvec3 centre = mean_origin;
  if (std::abs(glm::determinant(a)) > 1e-9 * std::pow(double(rays.size()), 3)) {
    centre = glm::inverse(a) * b;
  }
  // Points the piece sees: along each ray from z_near on (finite depths), and its direction (at
  // infinity).
  std::vector<glm::dvec3> points;
  for (const EyeRay& r : rays) {
    for (double t = z_near; t < 1e4; t *= 4) points.push_back(r.origin + t * r.direction);
  }
  double reach = 0;
  for (const EyeRay& r : rays) reach = std::max(reach, glm::length(r.origin - mean_origin));
  // The widest angle: kMaxProxyHalfAngleDeg, or more where the rays' own directions need it (a
  // mirror's piece at the silhouette), up to 88°.
  double max_tan = std::tan(glm::radians(kMaxProxyHalfAngleDeg));
  // Up: the eye's +y made perpendicular to the axis, or +x where they are parallel.
  glm::dvec3 up = glm::dvec3(0, 1, 0) - axis * axis.y;
  if (glm::length(up) < 1e-3) up = glm::dvec3(1, 0, 0) - axis * axis.x;
  up = glm::normalize(up);
  const glm::dvec3 right = glm::normalize(glm::cross(axis, up));
  Proxy proxy;
  proxy.frustum.R_eye_frustum = glm::dmat3(right, up, -axis);
  const glm::dmat3 R_frustum_eye = glm::transpose(proxy.frustum.R_eye_frustum);
  for (const EyeRay& r : rays) {
    const glm::dvec3 v = R_frustum_eye * r.direction;
    if (-v.z > 0) max_tan = std::max(max_tan, 1.05 * std::max(std::abs(v.x), std::abs(v.y)) / -v.z);
  }
  max_tan = std::min(max_tan, std::tan(glm::radians(88.0)));
  // Moved back along the axis until every point and direction lies within the widest angle.
  double back = 0, step = std::max(reach, z_near);
  for (int attempt = 0; attempt < 60; ++attempt) {
    const glm::dvec3 c = centre - axis * back;
    double worst = 0, nearest = std::numeric_limits<double>::infinity();
    for (const glm::dvec3& p : points) {
      const glm::dvec3 v = R_frustum_eye * (p - c);
      if (!(-v.z > 0)) {
        worst = std::numeric_limits<double>::infinity();
        break;
      }
      nearest = std::min(nearest, -v.z);
      worst = std::max({worst, std::abs(v.x / -v.z), std::abs(v.y / -v.z)});
    }
    for (const EyeRay& r : rays) {
      const glm::dvec3 v = R_frustum_eye * r.direction;
      worst = -v.z > 0 ? std::max({worst, std::abs(v.x / -v.z), std::abs(v.y / -v.z)})
                       : std::numeric_limits<double>::infinity();
    }
    if (worst <= max_tan) {
      proxy.centre = c;
      proxy.near = 0.5 * nearest;
      break;
    }
    back += step;
    step *= 2;
  }
  if (!(proxy.near > 0)) {
    throw InputError("GLC camera", "pieces",
                     "expected every GLC piece's rays within 176 degrees of each other (a proxy "
                     "pinhole for two-pass rasterization); one piece's are not");
  }
  // The frustum: the tangent box of the points and directions, padded by 2% of its span; and the
  // box at infinity alone, whose span gives the density of the GLC's pixels there.
  glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  glm::dvec2 lo_inf = lo, hi_inf = hi;
  for (const glm::dvec3& p : points) {
    const glm::dvec3 v = R_frustum_eye * (p - proxy.centre);
    const glm::dvec2 t(v.x / -v.z, v.y / -v.z);
    lo = glm::min(lo, t);
    hi = glm::max(hi, t);
  }
  for (const EyeRay& r : rays) {
    const glm::dvec3 v = R_frustum_eye * r.direction;
    const glm::dvec2 t(v.x / -v.z, v.y / -v.z);
    lo = glm::min(lo, t);
    hi = glm::max(hi, t);
    lo_inf = glm::min(lo_inf, t);
    hi_inf = glm::max(hi_inf, t);
  }
  const glm::dvec2 pad = 0.02 * (hi - lo) + 1e-6;
  lo -= pad;
  hi += pad;
  proxy.frustum.tan_extent = {lo.x, hi.x, hi.y, lo.y};
  // Samples: kSamplesPerPixel per pixel where the tangent plane spans the GLC's image at
  // infinity, the rest in proportion (up to 3 times the image's span).
  const glm::dvec2 box_px(std::max(1, box.z - box.x), std::max(1, box.w - box.y));
  const glm::dvec2 span = hi - lo, span_inf = hi_inf - lo_inf;
  for (int axis_k = 0; axis_k < 2; ++axis_k) {
    const double ratio =
        span_inf[axis_k] > 0 ? std::clamp(span[axis_k] / span_inf[axis_k], 1.0, 3.0) : 3.0;
    proxy.size[axis_k] =
        std::clamp(int(std::ceil(kSamplesPerPixel * box_px[axis_k] * ratio)) + 4, 5, 8192);
  }
  // One and a half samples more on every side, so that the grid of samples (at texel centres)
  // holds the rays at the outline with a sample to spare.
  for (int axis_k = 0; axis_k < 2; ++axis_k) {
    const double margin = 1.5 * span[axis_k] / (proxy.size[axis_k] - 3);
    lo[axis_k] -= margin;
    hi[axis_k] += margin;
  }
  proxy.frustum.tan_extent = {lo.x, hi.x, hi.y, lo.y};
  return proxy;
}

// Shelf-packs the proxies' sample rectangles into an atlas `width` wide; returns its height.
int pack_atlas(std::vector<Proxy>& proxies, int width) {
  int x = 0, y = 0, shelf = 0;
  for (Proxy& p : proxies) {
    if (x + p.size.x > width) {
      x = 0;
      y += shelf;
      shelf = 0;
    }
    p.origin = {x, y};
    x += p.size.x;
    shelf = std::max(shelf, p.size.y);
  }
  return y + shelf;
}

class Glc2PassMethod final : public ObjectBaseline {
 public:
  std::string_view name() const override { return "glc-2pass"; }

  void prepare(const Scene& scene, const GpuScene& gpu_scene, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    for (const OutputSpec& output : outputs) {
      if (!output.glc) {
        throw InputError("command line", OptionName{"method"},
                         "expected a GLC camera display (*.glc.json) for method glc-2pass; "
                         "output '" +
                             output.name + "' is a warp");
      }
    }
    keep_scene(scene, gpu_scene, settings);
    sample_programs_.prepare(scene, settings.material, [](const MaterialShader& shader) {
      ProgramBuilder builder;
      builder.define("WRITE_TRIANGLE_ID", "1")
          .define("EXTRA_OUTPUTS", "1")
          .shader("glc/glc_sample.vert")
          .shader("baselines/pull_scene.vert");
      add_material_stages(builder, shader);
      builder.shader("glc/glc_sample.frag");
      return link_with_material(builder, shader);
    });
    if (!splat_program_) {
      splat_program_ =
          ProgramBuilder().shader("glc/glc_splat.vert").shader("glc/glc_splat.frag").link();
    }
    outputs_.clear();
    buffer_bytes_ = 0;
    for (const OutputSpec& output : outputs) {
      OutputState out;
      out.camera = output.glc;
      const PiecewiseGlc& camera = *out.camera;
      FACET_ASSERT(camera.size == output.warp.output_size);
      std::vector<std::vector<glm::dvec2>> outlines = piece_outlines(camera);
      for (std::size_t k = 0; k < camera.pieces.size(); ++k) {
        if (outlines[k].empty()) outlines[k].push_back(glm::dvec2(camera.piece_boxes[k]));
        out.proxies.push_back(
            make_proxy(camera.pieces[k], camera.piece_boxes[k], outlines[k], settings.z_near));
      }
      // About square: as wide as the widest rectangle or the square root of their area.
      int width = 0;
      double area = 0;
      for (const Proxy& p : out.proxies) {
        width = std::max(width, p.size.x);
        area += double(p.size.x) * double(p.size.y);
      }
      width = std::min(kMaxAtlasSide, std::max(width, int(std::ceil(1.1 * std::sqrt(area)))));
      int height = pack_atlas(out.proxies, width);
      // An atlas that would be too tall gets fewer samples per pixel.
      while (height > kMaxAtlasSide) {
        for (Proxy& p : out.proxies) p.size = glm::max(glm::ivec2(2), p.size * 3 / 4);
        height = pack_atlas(out.proxies, width);
      }
      out.atlas_size = {width, height};
      // Every piece's cells: two triangles of its local sample numbers (row by row).
      std::vector<std::uint32_t> indices;
      for (Proxy& p : out.proxies) {
        p.first_index = indices.size();
        const std::uint32_t w = std::uint32_t(p.size.x);
        for (std::uint32_t j = 0; j + 1 < std::uint32_t(p.size.y); ++j) {
          for (std::uint32_t i = 0; i + 1 < w; ++i) {
            const std::uint32_t a = j * w + i, b = a + 1, c = a + w, d = c + 1;
            for (std::uint32_t v : {a, b, c, c, b, d}) indices.push_back(v);
          }
        }
      }
      out.grid_indices = Buffer::create_from(indices);
      out.grid_vao = VertexArray::create();
      glVertexArrayElementBuffer(out.grid_vao.id(), out.grid_indices.id());
      buffer_bytes_ += 4ull * indices.size();
      out.colour = Texture::create_2d(GL_SRGB8_ALPHA8, width, height);
      out.ids = Texture::create_2d(GL_R32UI, width, height);
      out.samples = Texture::create_2d(GL_RGBA32F, width, height);
      out.depth = Texture::create_2d(GL_DEPTH_COMPONENT32F, width, height);
      for (const Texture* t : {&out.colour, &out.ids, &out.samples}) {
        glTextureParameteri(t->id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(t->id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      }
      out.framebuffer = Framebuffer::create();
      out.framebuffer.attach(GL_COLOR_ATTACHMENT0, out.colour);
      out.framebuffer.attach(GL_COLOR_ATTACHMENT1, out.ids);
      out.framebuffer.attach(GL_COLOR_ATTACHMENT2, out.samples);
      out.framebuffer.attach(GL_DEPTH_ATTACHMENT, out.depth);
      const GLenum buffers[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
      glNamedFramebufferDrawBuffers(out.framebuffer.id(), 3, buffers);
      out.framebuffer.check_complete();
      out.piece_map = upload_piece_map(camera);
      // The atlas' colour (4), IDs (4), samples (16) and depth (4) bytes a texel; the piece map.
      buffer_bytes_ += 28ull * std::uint64_t(width) * std::uint64_t(height) +
                       4ull * std::uint64_t(camera.size.x) * std::uint64_t(camera.size.y);
      outputs_.push_back(std::move(out));
    }
    check_gl_error("glc-2pass prepare");
  }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(scene_ && targets.size() == outputs_.size());
    RenderStats stats;
    stats.triangles_scene = scene_->triangle_count();
    stats.triangles_in = stats.triangles_scene;
    stats.gpu_buffer_bytes = buffer_bytes_;
    const std::vector<BoundingSphere> spheres = object_spheres(*scene_, T_eye_world);
    std::vector<std::uint8_t> object_drawn(scene_->objects.size(), 0);
    for (std::size_t i = 0; i < outputs_.size(); ++i) {
      OutputState& out = outputs_[i];
      const PiecewiseGlc& camera = *out.camera;
      {
        TimedPass samples_pass(timer, "samples");
        glEnable(GL_FRAMEBUFFER_SRGB);
        begin_pulling(settings_.cull_back_faces);
        glEnable(GL_CLIP_DISTANCE0);
        glEnable(GL_SCISSOR_TEST);
        glBindFramebuffer(GL_FRAMEBUFFER, out.framebuffer.id());
        const float background[4] = {0, 0, 0, 1}, no_sample[4] = {0, 0, 0, 0};
        const GLuint zero_id[4] = {0, 0, 0, 0};
        const float far_depth = 0;
        glScissor(0, 0, out.atlas_size.x, out.atlas_size.y);
        glClearNamedFramebufferfv(out.framebuffer.id(), GL_COLOR, 0, background);
        glClearNamedFramebufferuiv(out.framebuffer.id(), GL_COLOR, 1, zero_id);
        glClearNamedFramebufferfv(out.framebuffer.id(), GL_COLOR, 2, no_sample);
        glClearNamedFramebufferfv(out.framebuffer.id(), GL_DEPTH, 0, &far_depth);
        for (std::size_t k = 0; k < camera.pieces.size(); ++k) {
          const glm::ivec4 box = camera.piece_boxes[k];
          if (box.x >= box.z || box.y >= box.w) continue;
          stats.replicas +=
              draw_piece(camera.pieces[k], out.proxies[k], T_eye_world, spheres, object_drawn);
        }
        glDisable(GL_SCISSOR_TEST);
        glDisable(GL_CLIP_DISTANCE0);
      }
      TimedPass splat_pass(timer, "splat");
      targets[i].clear();
      targets[i].bind();
      begin_reversed_z_scene(false);
      glDepthMask(GL_TRUE);
      splat_program_.use();
      glEnable(GL_CLIP_DISTANCE0);
      glBindVertexArray(out.grid_vao.id());
      glBindTextureUnit(0, out.samples.id());
      glBindTextureUnit(1, out.colour.id());
      glBindTextureUnit(2, out.ids.id());
      glBindTextureUnit(3, out.piece_map.id());
      for (GLuint unit = 0; unit < 4; ++unit) glBindSampler(unit, 0);
      glUniform2f(0, float(camera.size.x), float(camera.size.y));
      glUniform1f(1, float(settings_.z_near));
      for (std::size_t k = 0; k < camera.pieces.size(); ++k) {
        const glm::ivec4 box = camera.piece_boxes[k];
        if (box.x >= box.z || box.y >= box.w) continue;
        const Glc& glc = camera.pieces[k];
        const Proxy& proxy = out.proxies[k];
        const Coefficients c = coefficients(glc);
        glUniform4i(2, proxy.origin.x, proxy.origin.y, proxy.size.x, proxy.size.y);
        glUniform1i(3, int(k));
        const glm::mat3 R_frame_proxy(glm::transpose(glc.frame().axes) *
                                      proxy.frustum.R_eye_frustum);
        glUniformMatrix3fv(4, 1, GL_FALSE, glm::value_ptr(R_frame_proxy));
        const auto& e = proxy.frustum.tan_extent;
        glUniform4f(5, float(e[0]), float(e[1]), float(e[3]), float(e[2]));
        glUniformMatrix2fv(6, 1, GL_FALSE, glm::value_ptr(c.m1));
        glUniform2fv(7, 1, glm::value_ptr(c.duv0));
        glUniformMatrix3fv(8, 1, GL_FALSE, glm::value_ptr(c.pixel_from_ab));
        const std::size_t cells = std::size_t(proxy.size.x - 1) * std::size_t(proxy.size.y - 1);
        for (std::size_t first = 0; first < cells; first += kCellsPerDraw) {
          const std::size_t offset = 4 * (proxy.first_index + 6 * first);
          glDrawElements(GL_TRIANGLES, GLsizei(6 * std::min(kCellsPerDraw, cells - first)),
                         GL_UNSIGNED_INT, reinterpret_cast<const void*>(offset));
        }
      }
      glDisable(GL_CLIP_DISTANCE0);
      glBindVertexArray(0);
      targets[i].resolve();
      end_reversed_z_scene();
      splat_pass.end();
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (timer) timer->end_frame();
    for (std::size_t o = 0; o < scene_->objects.size(); ++o) {
      if (!object_drawn[o]) continue;
      const Object& object = scene_->objects[o];
      for (std::uint32_t p = 0; p < object.primitive_count; ++p) {
        stats.triangles_visible += scene_->primitives[object.first_primitive + p].index_count / 3;
      }
    }
    check_gl_error("glc-2pass render");
    return stats;
  }

 private:
  struct OutputState {
    std::shared_ptr<const PiecewiseGlc> camera;
    std::vector<Proxy> proxies;  // per piece
    glm::ivec2 atlas_size{0, 0};
    Texture colour, ids, samples, depth, piece_map;
    Framebuffer framebuffer;
    Buffer grid_indices;  // pass 2's triangles, per piece from Proxy::first_index
    VertexArray grid_vao;
  };

  // A GLC's projection coefficients in its frame (glc/glc_sample.vert): M(z) = m0 + z·m1,
  // P0(z) = st0 + z·duv0, and the image pixel of (α, β).
  struct Coefficients {
    glm::mat2 m0{1.0f}, m1{1.0f};
    glm::vec2 st0{0.0f}, duv0{0.0f};
    glm::mat3 pixel_from_ab{1.0f};
    glm::mat4 T_frame_eye{1.0f};
  };
  static Coefficients coefficients(const Glc& glc) {
    const auto& g = glc.generators();
    Coefficients c;
    const glm::dvec2 d0 = g[0].uv - g[0].st, d1 = g[1].uv - g[1].st, d2 = g[2].uv - g[2].st;
    c.m0 = glm::mat2(glm::dmat2(g[1].st - g[0].st, g[2].st - g[0].st));
    c.m1 = glm::mat2(glm::dmat2(d1 - d0, d2 - d0));
    c.st0 = glm::vec2(g[0].st);
    c.duv0 = glm::vec2(d0);
    c.pixel_from_ab = glm::mat3(glc.pixel_from_ab());
    const glm::dmat3 R_frame_eye = glm::transpose(glc.frame().axes);
    glm::dmat4 T(R_frame_eye);
    T[3] = glm::dvec4(-(R_frame_eye * glc.frame().origin), 1.0);
    c.T_frame_eye = glm::mat4(T);
    return c;
  }

  // Pass 1 of one piece into its atlas rectangle: every object whose bounding sphere may meet the
  // proxy's frustum and the GLC's half-space z >= z_near. Returns the triangles drawn.
  std::uint64_t draw_piece(const Glc& glc, const Proxy& proxy, const glm::dmat4& T_eye_world,
                           const std::vector<BoundingSphere>& spheres,
                           std::vector<std::uint8_t>& object_drawn) {
    glViewport(proxy.origin.x, proxy.origin.y, proxy.size.x, proxy.size.y);
    glScissor(proxy.origin.x, proxy.origin.y, proxy.size.x, proxy.size.y);
    const glm::dmat4 T_clip_eye = perspective_image_clip_from_eye(proxy.frustum, proxy.near) *
                                  glm::translate(glm::dmat4(1.0), -proxy.centre);
    glm::dvec4 planes[6];
    std::ranges::copy(frustum_side_planes(T_clip_eye), planes);
    // Reversed-Z: depth <= w in front of the near plane.
    planes[4] = glm::row(T_clip_eye, 3) - glm::row(T_clip_eye, 2);
    const glm::dvec3 n = glc.frame().axes[2];
    planes[5] = glm::dvec4(n, -glm::dot(n, glc.frame().origin) - settings_.z_near);
    const Coefficients c = coefficients(glc);
    std::uint64_t drawn = 0;
    const Program* in_use = nullptr;
    for (std::size_t o = 0; o < scene_->objects.size(); ++o) {
      const Object& object = scene_->objects[o];
      const BoundingSphere& sphere = spheres[o];
      if (sphere.radius < 0) continue;
      if (sphere_outside_a_plane(sphere, planes)) continue;
      object_drawn[o] = 1;
      const glm::dmat4 T_eye_object = T_eye_world * glm::dmat4(object.T_world_object);
      const glm::mat4 T_clip_object(T_clip_eye * T_eye_object), T_eye_object_f(T_eye_object);
      drawn += draw_object_primitives(
          *scene_, *gpu_scene_, o, triangle_base_[o] + 1, sample_programs_, in_use, GL_TRIANGLES,
          [&] {
            glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(T_clip_object));
            glUniformMatrix4fv(1, 1, GL_FALSE, glm::value_ptr(object.T_world_object));
            glUniformMatrix4fv(4, 1, GL_FALSE, glm::value_ptr(T_eye_object_f));
            glUniformMatrix4fv(10, 1, GL_FALSE, glm::value_ptr(c.T_frame_eye));
            glUniformMatrix2fv(11, 1, GL_FALSE, glm::value_ptr(c.m0));
            glUniformMatrix2fv(12, 1, GL_FALSE, glm::value_ptr(c.m1));
            glUniform2fv(13, 1, glm::value_ptr(c.st0));
            glUniform2fv(14, 1, glm::value_ptr(c.duv0));
            glUniformMatrix3fv(15, 1, GL_FALSE, glm::value_ptr(c.pixel_from_ab));
            glUniform1f(16, float(settings_.z_near));
          });
    }
    return drawn;
  }

  std::vector<OutputState> outputs_;
  std::uint64_t buffer_bytes_ = 0;
  MaterialPrograms sample_programs_;
  Program splat_program_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_glc_2pass_method() { return std::make_unique<Glc2PassMethod>(); }

}  // namespace facet::driver::detail
