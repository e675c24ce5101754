// Multi-perspective rasterization of a (piecewise) general linear camera ("glc"; Yu, Yu &
// McMillan), for an output given as a *.glc.json camera (OutputSpec::glc).
//
// Per frame, on the CPU (the pieces shared out over every hardware thread): every triangle is
// carried into the eye frame, and for every GLC piece whose rays it may meet,
// Glc::triangle_bounds gives a conservative box of the pixels whose rays can hit it (exact extremes
// of the projection over the triangle clipped to z >= z_near: on each depth plane the map is
// affine, so the extremes lie on the clipped triangle's edges; a slit depth inside the triangle
// makes the box the whole piece), clipped to the piece's pixel box. Per piece a triangle
// is first tested against a cone that holds every ray the piece casts (the rays at the pixel
// centres it owns: its axis the mean direction of the rays at the ends of the piece's pixel runs in
// each row, its apex behind their origins), with its bounding sphere, and objects likewise with
// theirs; a triangle that passes is then tested against the cones of the piece's tiles (up to 16
// about square parts of its box), and its box is clipped to the box of the tiles it may meet, or
// dropped where it meets none. On the GPU: one quad per (triangle, piece) box; every fragment whose
// pixel belongs to that piece (the piece map, the same that the oracle reads) casts its pixel
// centre's GLC ray and intersects the triangle exactly, writing depth from the hit. The image is
// therefore the ray cast of the camera's own rays: hole-free, whatever the camera does to straight
// lines. The hit is shaded through the material interface (glc/glc_hit.frag gathers MaterialInput),
// one program per distinct material shader as in every method; the quads are drawn grouped by scene
// material, each group with its material's uniforms and texture.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <glm/gtc/type_ptr.hpp>
#include <memory>
#include <thread>

#include "facet/driver/gpu_timer.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/program.hpp"
#include "facet/projection/errors.hpp"
#include "material_programs.hpp"
#include "render_methods_internal.hpp"
#include "replication_common.hpp"

namespace facet::driver::detail {
namespace {

struct GpuQuad {
  glm::vec4 box, a, b, c;
  glm::uvec4 ids;     // triangle ID, piece, material
  glm::uvec4 source;  // the triangle's first index in Scene::indices, its object
};
static_assert(sizeof(GpuQuad) == 96);

struct GpuPiece {
  glm::vec4 o0, ox, oy, d0, dx, dy;
};

// A cone holding every ray of a piece from its origin on: apex, unit axis, cos and sin of the
// half-angle; `all` when no cone narrower than a half-space does.
struct RayCone {
  glm::dvec3 apex{0.0}, axis{0.0, 0.0, -1.0};
  double cos_angle = -1, sin_angle = 1;
  bool all = true;

  // Whether the sphere may meet the cone (conservative).
  bool may_meet(const glm::dvec3& centre, double radius) const {
    if (all) return true;
    const glm::dvec3 v = centre - apex;
    const double d = glm::length(v);
    if (d <= radius) return true;
    // The angle between v and the axis is at most the half-angle plus asin(radius / d).
    const double sin_r = radius / d, cos_r = std::sqrt(std::max(0.0, 1 - sin_r * sin_r));
    // cos(half-angle + r): the half-angle is below 80 degrees and r at most 90.
    const double cos_limit = cos_angle * cos_r - sin_angle * sin_r;
    return glm::dot(v, axis) / d >= cos_limit - 1e-9;
  }
};

// A piece's pixels cut into up to kTilesPerPiece tiles of its box (kMinTilePixels a side at
// least), each with its owned pixels' box and the pixel centres at the ends of its runs in every
// row: their convex hull holds every pixel centre of the tile that the piece owns, the only ones
// whose rays are cast.
constexpr int kTilesPerPiece = 16, kMinTilePixels = 16;
struct PieceTile {
  glm::ivec4 box{0};  // owned pixels, [x0, x1) x [y0, y1)
  std::vector<glm::dvec2> run_ends;
};

std::vector<std::vector<PieceTile>> piece_tiles(const PiecewiseGlc& camera) {
  const std::size_t n = camera.pieces.size();
  // Piece k's box is cut into nx[k] x ny[k] tiles, about square.
  std::vector<int> nx(n, 1), ny(n, 1);
  std::vector<std::vector<PieceTile>> tiles(n);
  for (std::size_t k = 0; k < n; ++k) {
    const glm::ivec4 b = camera.piece_boxes[k];
    const double w = std::max(1, b.z - b.x), h = std::max(1, b.w - b.y);
    nx[k] = std::clamp(int(std::lround(std::sqrt(kTilesPerPiece * w / h))), 1, kTilesPerPiece);
    ny[k] = std::max(1, kTilesPerPiece / nx[k]);
    nx[k] = std::min(nx[k], std::max(1, int(w) / kMinTilePixels));
    ny[k] = std::min(ny[k], std::max(1, int(h) / kMinTilePixels));
    tiles[k].resize(std::size_t(nx[k] * ny[k]));
    for (PieceTile& tile : tiles[k]) tile.box = {camera.size.x, camera.size.y, 0, 0};
  }
  auto tile_of = [&](std::size_t k, int x, int y) -> PieceTile& {
    const glm::ivec4 b = camera.piece_boxes[k];
    const int tx = int(std::int64_t(x - b.x) * nx[k] / std::max(1, b.z - b.x));
    const int ty = int(std::int64_t(y - b.y) * ny[k] / std::max(1, b.w - b.y));
    return tiles[k][std::size_t(ty * nx[k] + tx)];
  };
  for (int y = 0; y < camera.size.y; ++y) {
    const std::int32_t* row = camera.piece_of_pixel.data() + std::size_t(y) * camera.size.x;
    // Runs of pixels of one piece and one tile.
    int start = 0;
    for (int x = 1; x <= camera.size.x; ++x) {
      const std::int32_t piece = row[start];
      if (x < camera.size.x && row[x] == piece &&
          (piece < 0 ||
           &tile_of(std::size_t(piece), x, y) == &tile_of(std::size_t(piece), start, y))) {
        continue;
      }
      if (piece >= 0) {
        PieceTile& tile = tile_of(std::size_t(piece), start, y);
        tile.run_ends.push_back({start + 0.5, y + 0.5});
        if (x - 1 > start) tile.run_ends.push_back({x - 0.5, y + 0.5});
        tile.box = {std::min(tile.box.x, start), std::min(tile.box.y, y), std::max(tile.box.z, x),
                    std::max(tile.box.w, y + 1)};
      }
      start = x;
    }
  }
  for (std::vector<PieceTile>& piece : tiles) {
    std::erase_if(piece, [](const PieceTile& tile) { return tile.run_ends.empty(); });
  }
  return tiles;
}

// The cone of the rays of a piece at `points` (pixels). A piece's rays are affine in the pixel,
// so the pixels whose rays (from their origins on) lie in a cone form a convex set: a cone that
// holds the rays at the points holds every ray of their convex hull.
RayCone ray_cone(const Glc& glc, const std::vector<glm::dvec2>& points) {
  RayCone cone;
  if (points.empty()) return cone;
  std::vector<EyeRay> rays;
  rays.reserve(points.size());
  glm::dvec3 axis(0.0), centre(0.0);
  for (const glm::dvec2& p : points) {
    rays.push_back(glc.ray(p));
    axis += glm::normalize(rays.back().direction);
    centre += rays.back().origin;
  }
  centre /= double(points.size());
  if (!(glm::length(axis) > 1e-9)) return cone;
  axis = glm::normalize(axis);
  double cos_angle = 1, reach = 0;
  for (const EyeRay& r : rays) {
    cos_angle = std::min(cos_angle, glm::dot(glm::normalize(r.direction), axis));
    reach = std::max(reach, glm::length(r.origin - centre));
  }
  if (!(cos_angle > 0.17)) return cone;  // 80 degrees or more: no useful cone
  cone.all = false;
  cone.axis = axis;
  // A margin for rounding.
  cone.cos_angle = std::max(0.0, cos_angle - 1e-6);
  cone.sin_angle = std::sqrt(1 - cone.cos_angle * cone.cos_angle);
  // Every origin lies within `reach` of the centre: from an apex reach / sin behind it, every
  // origin is inside the cone, and so is every ray from it (a sum of two vectors in the cone).
  cone.apex = centre - axis * (reach * (1 + 1e-6) / std::max(cone.sin_angle, 1e-6));
  return cone;
}

class GlcMethod final : public RenderMethod {
 public:
  std::string_view name() const override { return "glc"; }

  void prepare(const Scene& scene, const GpuScene& gpu, std::span<const OutputSpec> outputs,
               const RenderSettings& settings) override {
    for (const OutputSpec& output : outputs) {
      if (!output.glc) {
        throw InputError("command line", OptionName{"method"},
                         "expected a GLC camera display (*.glc.json) for method glc; output '" +
                             output.name + "' is a warp");
      }
    }
    if (!(settings.z_near > 0)) {
      throw InputError("render settings", "z_near", "expected a positive near distance");
    }
    scene_ = &scene;
    gpu_ = &gpu;
    settings_ = settings;
    triangle_base_ = scene_triangle_base(scene);
    programs_.prepare(scene, settings.material, [](const MaterialShader& shader) {
      ProgramBuilder builder;
      builder.shader("glc/glc_quad.vert");
      add_material_stages(builder, shader, "glc/glc_hit.frag");
      return link_with_material(builder, shader);
    });
    outputs_.clear();
    for (const OutputSpec& output : outputs) {
      OutputState out;
      out.camera = output.glc;
      const PiecewiseGlc& camera = *out.camera;
      FACET_ASSERT(camera.size == output.warp.output_size);
      std::vector<GpuPiece> pieces;
      const std::vector<std::vector<PieceTile>> tiles =
          camera.pieces.size() > 1 ? piece_tiles(camera) : std::vector<std::vector<PieceTile>>{};
      out.tiles.resize(camera.pieces.size());
      for (std::size_t k = 0; k < camera.pieces.size(); ++k) {
        const Glc& glc = camera.pieces[k];
        // Affine in the pixel: differences of rays one pixel apart, about the piece box's corner.
        const glm::dvec2 at(camera.piece_boxes[k].x, camera.piece_boxes[k].y);
        const EyeRay r0 = glc.ray(at), rx = glc.ray(at + glm::dvec2(1, 0)),
                     ry = glc.ray(at + glm::dvec2(0, 1));
        const glm::dvec3 ox = rx.origin - r0.origin, oy = ry.origin - r0.origin;
        const glm::dvec3 dx = rx.direction - r0.direction, dy = ry.direction - r0.direction;
        pieces.push_back({glm::vec4(r0.origin - at.x * ox - at.y * oy, 0), glm::vec4(ox, 0),
                          glm::vec4(oy, 0), glm::vec4(r0.direction - at.x * dx - at.y * dy, 0),
                          glm::vec4(dx, 0), glm::vec4(dy, 0)});
        if (camera.pieces.size() == 1) {
          out.cones.push_back(RayCone{});
          continue;
        }
        std::vector<glm::dvec2> run_ends;
        for (const PieceTile& tile : tiles[k]) {
          run_ends.insert(run_ends.end(), tile.run_ends.begin(), tile.run_ends.end());
        }
        out.cones.push_back(ray_cone(glc, run_ends));
        if (tiles[k].size() > 1) {
          for (const PieceTile& tile : tiles[k]) {
            out.tiles[k].push_back({ray_cone(glc, tile.run_ends), tile.box});
          }
        }
      }
      out.pieces = Buffer::create_from(pieces);
      out.piece_map = upload_piece_map(camera);
      outputs_.push_back(std::move(out));
    }
    vao_ = VertexArray::create();
    // Quad k of a draw: triangles (0, 1, 2) and (2, 1, 3) over its corners 4k..4k+3 (the draw's
    // base vertex picks the first quad).
    std::vector<std::uint32_t> corners;
    for (std::uint32_t k = 0; k < kSoftwareReplicasPerDraw; ++k) {
      for (std::uint32_t c : {0u, 1u, 2u, 2u, 1u, 3u}) corners.push_back(4 * k + c);
    }
    quad_corners_ = Buffer::create_from(corners);
    glVertexArrayElementBuffer(vao_.id(), quad_corners_.id());
  }

  RenderStats render(const glm::dmat4& T_eye_world, std::span<OutputTarget> targets,
                     GpuTimer* timer) override {
    FACET_ASSERT(targets.size() == outputs_.size());
    const Scene& scene = *scene_;
    RenderStats stats;
    stats.triangles_scene = scene.triangle_count();
    // The triangles in the eye frame, in ID order, and per object its range and sphere.
    triangles_.clear();
    object_ranges_.assign(scene.objects.size() + 1, 0);
    const std::vector<BoundingSphere> spheres = object_spheres(scene, T_eye_world);
    for (std::size_t o = 0; o < scene.objects.size(); ++o) {
      const Object& object = scene.objects[o];
      const glm::mat4 T_eye_object = glm::mat4(T_eye_world * glm::dmat4(object.T_world_object));
      for (std::uint32_t k = 0; k < object.primitive_count; ++k) {
        const Primitive& primitive = scene.primitives[object.first_primitive + k];
        FACET_ASSERT(primitive.material < scene.materials.size());
        for (std::uint32_t i = 0; i + 2 < primitive.index_count; i += 3) {
          EyeTriangle t;
          for (int v = 0; v < 3; ++v) {
            const glm::vec3& p = scene.positions[scene.indices[primitive.first_index + i + v]];
            t.v[v] = glm::vec3(T_eye_object * glm::vec4(p, 1.0f));
          }
          t.material = primitive.material;
          t.first_index = primitive.first_index + i;
          const glm::dvec3 centre =
              (glm::dvec3(t.v[0]) + glm::dvec3(t.v[1]) + glm::dvec3(t.v[2])) / 3.0;
          t.centre = centre;
          t.radius = 0;
          for (int v = 0; v < 3; ++v) {
            t.radius = std::max(t.radius, glm::length(glm::dvec3(t.v[v]) - centre));
          }
          triangles_.push_back(t);
        }
      }
      object_ranges_[o + 1] = std::uint32_t(triangles_.size());
    }
    stats.triangles_in = triangles_.size();
    std::vector<std::uint8_t> visible(triangles_.size(), 0);

    begin_reversed_z_scene(false);
    glDepthMask(GL_TRUE);
    for (std::size_t i = 0; i < outputs_.size(); ++i) {
      OutputState& out = outputs_[i];
      const PiecewiseGlc& camera = *out.camera;
      // "bounds": the CPU's per-(triangle, piece) boxes; "draw": the GPU's quads.
      TimedPass bounds_pass(timer, "bounds");
      // The pieces are boxed on every hardware thread, each piece's quads in a list of its own,
      // then joined in piece order, so that the draw order does not depend on the threads.
      piece_quads_.resize(camera.pieces.size());
      std::atomic<std::size_t> next_piece{0};
      const std::size_t workers = std::min<std::size_t>(
          camera.pieces.size(), std::max(1u, std::thread::hardware_concurrency()));
      // A worker's exception (std::bad_alloc) is rethrown here, after every worker has ended.
      std::vector<std::exception_ptr> failures(workers);
      auto box_pieces = [&](std::size_t worker) {
        try {
          for (std::size_t k = next_piece++; k < camera.pieces.size(); k = next_piece++) {
            piece_quads_[k].clear();
            box_piece(camera, out.cones[k], out.tiles[k], k, spheres, piece_quads_[k]);
          }
        } catch (...) {
          failures[worker] = std::current_exception();
          next_piece = camera.pieces.size();
        }
      };
      std::vector<std::thread> pool;
      for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(box_pieces, w);
      box_pieces(0);
      for (std::thread& thread : pool) thread.join();
      for (const std::exception_ptr& failure : failures) {
        if (failure) std::rethrow_exception(failure);
      }
      // Joined by scene material (each group is drawn with its material's uniforms and
      // texture), in piece order within a material.
      material_first_.assign(scene.materials.size() + 1, 0);
      for (const std::vector<GpuQuad>& quads : piece_quads_) {
        for (const GpuQuad& quad : quads) ++material_first_[quad.ids.z + 1];
      }
      for (std::size_t m = 0; m < scene.materials.size(); ++m) {
        material_first_[m + 1] += material_first_[m];
      }
      quads_.resize(material_first_.back());
      {
        std::vector<std::size_t> next(material_first_.begin(), material_first_.end() - 1);
        for (const std::vector<GpuQuad>& quads : piece_quads_) {
          for (const GpuQuad& quad : quads) quads_[next[quad.ids.z]++] = quad;
        }
      }
      for (const GpuQuad& quad : quads_) visible[quad.ids.x - 1] = 1;
      stats.replicas += quads_.size();
      bounds_pass.end();
      TimedPass draw_pass(timer, "draw");
      targets[i].clear();
      targets[i].bind();
      glDepthMask(GL_TRUE);
      if (!quads_.empty()) {
        ensure_capacity(out.quads, quads_.size() * sizeof(GpuQuad));
        out.quads.sub_data(0, quads_.size() * sizeof(GpuQuad), quads_.data());
        out.quads.bind_base(GL_SHADER_STORAGE_BUFFER, 0);
        out.pieces.bind_base(GL_SHADER_STORAGE_BUFFER, 1);
        gpu_->bind_for_pulling();  // indices (binding 3) and vertex texels
        gpu_->objects.bind_base(GL_SHADER_STORAGE_BUFFER, 4);
        glBindTextureUnit(1, out.piece_map.id());
        glBindSampler(1, 0);  // the scene's samplers would filter it
        glBindVertexArray(vao_.id());
        const glm::mat4 T_world_eye = glm::mat4(glm::inverse(T_eye_world));
        const Program* in_use = nullptr;
        for (std::size_t m = 0; m < scene.materials.size(); ++m) {
          const std::size_t begin = material_first_[m], end = material_first_[m + 1];
          if (begin == end) continue;
          const Program& program = programs_.program_of(std::uint32_t(m));
          if (&program != in_use) {
            program.use();
            in_use = &program;
            glUniform2f(0, float(camera.size.x), float(camera.size.y));
            glUniform1f(1, float(settings_.z_near));
            glUniform1i(2, settings_.cull_back_faces ? 1 : 0);
            glUniformMatrix4fv(3, 1, GL_FALSE, glm::value_ptr(T_world_eye));
          }
          const Material& material = scene.materials[m];
          glUniform4fv(8, 1, glm::value_ptr(material.base_colour));
          glUniform1i(9, material.texture >= 0 ? 1 : 0);
          gpu_->bind_material_texture(std::uint32_t(m), 0);
          // Draws of kSoftwareReplicasPerDraw quads: llvmpipe's draw module costs time quadratic
          // in a draw's batch (replication_common.hpp).
          const std::size_t per_draw = kSoftwareReplicasPerDraw;
          for (std::size_t first = begin; first < end; first += per_draw) {
            const std::size_t count = std::min(per_draw, end - first);
            glDrawElementsBaseVertex(GL_TRIANGLES, GLsizei(6 * count), GL_UNSIGNED_INT, nullptr,
                                     GLint(4 * first));
          }
        }
        glBindVertexArray(0);
      }
      stats.gpu_buffer_bytes +=
          out.quads.size() + out.pieces.size() + std::uint64_t(camera.size.x) * camera.size.y * 4;
      targets[i].resolve();
      draw_pass.end();
    }
    glDisable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (timer) timer->end_frame();
    for (std::uint8_t v : visible) stats.triangles_visible += v;
    return stats;
  }

 private:
  struct EyeTriangle {
    std::array<glm::vec3, 3> v;
    std::uint32_t material = 0;
    std::uint32_t first_index = 0;  // in Scene::indices
    glm::dvec3 centre{0.0};
    double radius = 0;
  };
  struct TileCone {
    RayCone cone;
    glm::ivec4 box;  // the tile's owned pixels
  };
  struct OutputState {
    std::shared_ptr<const PiecewiseGlc> camera;
    std::vector<RayCone> cones;  // per piece
    // Per piece, the cones of its tiles (none where the piece is one tile).
    std::vector<std::vector<TileCone>> tiles;
    Buffer pieces, quads;
    Texture piece_map;
  };

  // Piece k's quads: for every triangle its cone lets through, the triangle's pixel box clipped
  // to the box of the piece's tiles whose cones let it through.
  void box_piece(const PiecewiseGlc& camera, const RayCone& cone,
                 const std::vector<TileCone>& tiles, std::size_t k,
                 const std::vector<BoundingSphere>& spheres, std::vector<GpuQuad>& quads) const {
    const Glc& glc = camera.pieces[k];
    const glm::ivec4 box = camera.piece_boxes[k];
    if (box.x >= box.z || box.y >= box.w) return;
    const float h = float(camera.size.y);
    for (std::size_t o = 0; o + 1 < object_ranges_.size(); ++o) {
      if (spheres[o].radius < 0 || !cone.may_meet(spheres[o].centre, spheres[o].radius * 1.0001))
        continue;
      for (std::uint32_t t = object_ranges_[o]; t < object_ranges_[o + 1]; ++t) {
        const EyeTriangle& tri = triangles_[t];
        const double radius = tri.radius * 1.0001 + 1e-6;
        if (!cone.may_meet(tri.centre, radius)) continue;
        glm::ivec4 reach = box;
        if (!tiles.empty()) {
          reach = {box.z, box.w, box.x, box.y};
          for (const TileCone& tile : tiles) {
            if (!tile.cone.may_meet(tri.centre, radius)) continue;
            reach = {std::min(reach.x, tile.box.x), std::min(reach.y, tile.box.y),
                     std::max(reach.z, tile.box.z), std::max(reach.w, tile.box.w)};
          }
          if (reach.x >= reach.z || reach.y >= reach.w) continue;
        }
        const auto bounds = glc.triangle_bounds(glm::dvec3(tri.v[0]), glm::dvec3(tri.v[1]),
                                                glm::dvec3(tri.v[2]), settings_.z_near, 0.5);
        if (!bounds) continue;
        // Clip to the tiles' box (whole pixels); the bound's box holds every pixel centre whose
        // ray can meet the triangle.
        const double x0 = std::max<double>(reach.x, bounds->min.x);
        const double x1 = std::min<double>(reach.z, bounds->max.x);
        const double y0 = std::max<double>(reach.y, bounds->min.y);
        const double y1 = std::min<double>(reach.w, bounds->max.y);
        if (!(x0 < x1 && y0 < y1)) continue;
        quads.push_back({glm::vec4(float(x0), h - float(y1), float(x1), h - float(y0)),
                         glm::vec4(tri.v[0], 1), glm::vec4(tri.v[1], 1), glm::vec4(tri.v[2], 1),
                         glm::uvec4(triangle_id(o, t), std::uint32_t(k), tri.material, 0),
                         glm::uvec4(tri.first_index, std::uint32_t(o), 0, 0)});
      }
    }
  }

  // The ID of list triangle t of object o (render_method.hpp's numbering).
  std::uint32_t triangle_id(std::size_t o, std::uint32_t t) const {
    return triangle_base_[o] + (t - object_ranges_[o]) + 1;
  }

  const Scene* scene_ = nullptr;
  const GpuScene* gpu_ = nullptr;
  RenderSettings settings_;
  std::vector<std::uint32_t> triangle_base_;
  MaterialPrograms programs_;
  VertexArray vao_;
  Buffer quad_corners_;  // element indices of kSoftwareReplicasPerDraw quads
  std::vector<OutputState> outputs_;
  std::vector<EyeTriangle> triangles_;
  std::vector<std::uint32_t> object_ranges_;
  std::vector<GpuQuad> quads_;               // grouped by material
  std::vector<std::size_t> material_first_;  // material m's quads: [first[m], first[m + 1])
  std::vector<std::vector<GpuQuad>> piece_quads_;
};

}  // namespace

std::unique_ptr<RenderMethod> make_glc_method() { return std::make_unique<GlcMethod>(); }

Texture upload_piece_map(const PiecewiseGlc& camera) {
  std::vector<std::int32_t> rows(camera.piece_of_pixel.size());
  for (int y = 0; y < camera.size.y; ++y) {
    std::copy_n(camera.piece_of_pixel.begin() + std::ptrdiff_t(y) * camera.size.x, camera.size.x,
                rows.begin() + std::ptrdiff_t(camera.size.y - 1 - y) * camera.size.x);
  }
  Texture map = Texture::create_2d(GL_R32I, camera.size.x, camera.size.y);
  // Integer textures are complete only with nearest filtering.
  glTextureParameteri(map.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(map.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureSubImage2D(map.id(), 0, 0, 0, camera.size.x, camera.size.y, GL_RED_INTEGER, GL_INT,
                      rows.data());
  return map;
}

}  // namespace facet::driver::detail
