#include "facet/projection/rig.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "facet/projection/errors.hpp"
#include "facet/projection/parallel.hpp"

namespace facet {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// d(r_d)/dr as a polynomial in u = r²: 1 + 3 k1 u + 5 k2 u² + 7 k3 u³.
double slope(const std::array<double, 3>& k, double u) {
  return 1 + u * (3 * k[0] + u * (5 * k[1] + u * 7 * k[2]));
}

bool valid_name(const std::string& name) {
  if (name.empty() || name.front() == '.' || name.size() > 128) return false;
  return std::all_of(name.begin(), name.end(), [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
           ch == '_' || ch == '-' || ch == '.';
  });
}

bool is_rotation(const glm::dmat3& R) {
  const glm::dmat3 error = glm::transpose(R) * R - glm::dmat3(1.0);
  double worst = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) worst = std::max(worst, std::abs(error[i][j]));
  }
  return worst <= 1e-6 && glm::determinant(R) > 0;
}

bool is_unit(const glm::dvec3& v) { return std::abs(glm::length(v) - 1.0) <= 1e-6; }

}  // namespace

double ProjectorModel::distorted_radius(double r) const {
  const double u = r * r;
  return r * (1 + u * (k[0] + u * (k[1] + u * k[2])));
}

bool ProjectorModel::monotonic_up_to(double r) const {
  // The slope is a cubic in u = r²; its minimum over [0, U] lies at an end or where its
  // derivative 3 k1 + 10 k2 u + 21 k3 u² vanishes.
  const double U = r * r;
  if (!(slope(k, U) > 0)) return false;
  const double a = 21 * k[2], b = 10 * k[1], c = 3 * k[0];
  std::array<double, 2> roots{-1, -1};
  if (a == 0) {
    if (b != 0) roots[0] = -c / b;
  } else {
    const double discriminant = b * b - 4 * a * c;
    if (discriminant >= 0) {
      const double root = std::sqrt(discriminant);
      roots = {(-b - root) / (2 * a), (-b + root) / (2 * a)};
    }
  }
  for (double u : roots) {
    if (u > 0 && u < U && !(slope(k, u) > 0)) return false;
  }
  return true;
}

double ProjectorModel::max_undistorted_radius() const {
  constexpr double kFar = 1e6;  // 89.99994° off axis: nothing beyond matters
  if (monotonic_up_to(kFar)) return kInfinity;
  double good = 0, bad = kFar;
  for (int iteration = 0; iteration < 200 && bad - good > 1e-14 * bad; ++iteration) {
    const double middle = 0.5 * (good + bad);
    (monotonic_up_to(middle) ? good : bad) = middle;
  }
  return good;
}

std::optional<glm::dvec2> ProjectorModel::q_from_p_eye(const glm::dvec3& p_eye) const {
  if (!finite(p_eye)) return std::nullopt;
  const glm::dvec3 p = glm::transpose(R_eye_projector) * (p_eye - t_eye_projector);
  if (!(p.z > 0)) return std::nullopt;
  const glm::dvec2 xy(p.x / p.z, p.y / p.z);
  const double r = glm::length(xy);
  if (!monotonic_up_to(r)) return std::nullopt;
  const double u = r * r;
  const double factor = 1 + u * (k[0] + u * (k[1] + u * k[2]));
  return glm::dvec2(focal_px.x * xy.x * factor + principal_px.x,
                    focal_px.y * xy.y * factor + principal_px.y);
}

std::optional<glm::dvec3> ProjectorModel::v_eye_from_q(const glm::dvec2& q) const {
  if (!std::isfinite(q.x) || !std::isfinite(q.y)) return std::nullopt;
  const glm::dvec2 xy_d((q.x - principal_px.x) / focal_px.x, (q.y - principal_px.y) / focal_px.y);
  const double r_d = glm::length(xy_d);
  glm::dvec2 xy(0.0);
  if (r_d > 0) {
    const double r_max = max_undistorted_radius();
    if (std::isfinite(r_max) && !(r_d < distorted_radius(r_max))) return std::nullopt;
    // r_d(r) is increasing on [0, r_max]: Newton, falling back to bisection inside the bracket.
    double low = 0, high = std::isfinite(r_max) ? r_max : kInfinity;
    double r = std::min(r_d, std::isfinite(r_max) ? r_max : r_d);
    for (int iteration = 0; iteration < 100; ++iteration) {
      const double error = distorted_radius(r) - r_d;
      if (error == 0) break;
      (error > 0 ? high : low) = r;
      double next = r - error / slope(k, r * r);
      if (!(next > low && next < high)) {
        next = std::isfinite(high) ? 0.5 * (low + high) : 2 * r + 1;
      }
      if (std::abs(next - r) <= 1e-16 * std::max(1.0, r)) {
        r = next;
        break;
      }
      r = next;
    }
    xy = xy_d * (r / r_d);
  }
  return glm::normalize(R_eye_projector * glm::dvec3(xy, 1.0));
}

void Rig::validate(const std::string& source) const {
  auto fail = [&](const std::string& field, const std::string& expected) {
    throw InputError(source, field, expected);
  };
  if (!finite(screen.center) || !finite(screen.point)) fail("screen", "finite coordinates");
  if (screen.type != Screen::Type::plane && !(screen.radius > 0 && std::isfinite(screen.radius))) {
    fail("screen.radius", "a positive number of metres");
  }
  if (screen.type == Screen::Type::cylinder && !is_unit(screen.axis)) {
    fail("screen.axis", "a unit vector");
  }
  if (screen.type == Screen::Type::plane && !is_unit(screen.normal)) {
    fail("screen.normal", "a unit vector");
  }
  if (projectors.empty()) fail("projectors", "a non-empty list of projectors");
  std::set<std::string> names;
  for (std::size_t index = 0; index < projectors.size(); ++index) {
    const ProjectorModel& p = projectors[index];
    const std::string at = "projectors[" + std::to_string(index) + "].";
    if (!valid_name(p.name)) {
      fail(at + "name",
           "a name of letters, digits, '_', '-' and '.' that does not start with '.' (it names "
           "files)");
    }
    if (!names.insert(p.name).second) {
      fail(at + "name", "a name no other projector has, but '" + p.name + "' repeats");
    }
    if (p.size.x < 1 || p.size.y < 1 || p.size.x > 65536 || p.size.y > 65536) {
      fail(at + "size", "[width, height], each from 1 to 65536");
    }
    if (!(p.focal_px.x > 0 && p.focal_px.y > 0) || !std::isfinite(p.focal_px.x) ||
        !std::isfinite(p.focal_px.y)) {
      fail(at + "focal_px", "two positive focal lengths in pixels");
    }
    if (!std::isfinite(p.principal_px.x) || !std::isfinite(p.principal_px.y)) {
      fail(at + "principal_px", "two finite pixel coordinates");
    }
    for (double value : p.k) {
      if (!std::isfinite(value)) fail(at + "distortion", "finite coefficients k1, k2, k3");
    }
    // Every pixel of the image needs its own ray: the distortion must stay monotonic out to the
    // farthest corner.
    double corner_r_d = 0;
    for (double x : {0.0, double(p.size.x)}) {
      for (double y : {0.0, double(p.size.y)}) {
        corner_r_d = std::max(corner_r_d, std::hypot((x - p.principal_px.x) / p.focal_px.x,
                                                     (y - p.principal_px.y) / p.focal_px.y));
      }
    }
    const double r_max = p.max_undistorted_radius();
    if (std::isfinite(r_max) && !(corner_r_d < p.distorted_radius(r_max))) {
      fail(at + "distortion",
           "a radial distortion that stays monotonic out to the image corners (it folds back at "
           "a normalised radius of " +
               std::to_string(p.distorted_radius(r_max)) + ", the corners reach " +
               std::to_string(corner_r_d) + ")");
    }
    if (!is_rotation(p.R_eye_projector)) {
      fail(at + "R_eye_projector", "a rotation matrix (orthonormal within 1e-6, determinant +1)");
    }
    if (!finite(p.t_eye_projector)) fail(at + "t_eye_projector", "a list of 3 finite numbers");
    if (!(p.gamma > 0 && p.gamma <= kMaxGamma)) fail(at + "gamma", "a gamma in (0, 10]");
  }
  if (camera.lensmodel.empty()) fail("camera.lensmodel", "an mrcal lens model name");
  if (camera.size.x < 1 || camera.size.y < 1 || camera.size.x > 32768 || camera.size.y > 32768) {
    fail("camera.size", "[width, height], each from 1 to 32768");
  }
  if (camera.intrinsics.empty() && !(camera.fov_deg > 0 && camera.fov_deg <= 360)) {
    fail("camera.fov_deg", "a field of view in (0, 360] degrees");
  }
  for (double value : camera.intrinsics) {
    if (!std::isfinite(value)) fail("camera.intrinsics", "finite numbers");
  }
  if (!is_rotation(camera.R_eye_camera)) {
    fail("camera.R_eye_camera", "a rotation matrix (orthonormal within 1e-6, determinant +1)");
  }
  if (!finite(camera.t_eye_camera)) fail("camera.t_eye_camera", "a list of 3 finite numbers");
  const SimulationSettings& s = simulation;
  if (!(s.phase_period >= kMinPhasePeriod && s.phase_period <= kMaxPhasePeriod)) {
    fail("simulation.phase_period", "a period from 2 to 65536 projector pixels");
  }
  if (s.phase_steps < 3 || s.phase_steps > 64) fail("simulation.phase_steps", "3 to 64 steps");
  auto check_range = [&](double value, double low, double high, const std::string& field,
                         const std::string& expected) {
    if (!(value >= low && value <= high)) fail("simulation." + field, expected);
  };
  check_range(s.defocus_px, 0, 50, "defocus_px", "a blur σ from 0 to 50 projector pixels");
  check_range(s.camera_blur_px, 0, 50, "camera_blur_px", "a blur σ from 0 to 50 camera pixels");
  check_range(s.peak, 1e-3, 1, "peak", "a fraction of full scale in (0, 1]");
  check_range(s.ambient, 0, 1, "ambient", "a fraction of full scale in [0, 1]");
  check_range(s.noise, 0, 1, "noise", "a noise σ in [0, 1] of full scale");
  if (s.bits != 8 && s.bits != 16) fail("simulation.bits", "8 or 16");
}

std::optional<glm::dvec2> exact_projector_pixel(const Screen& screen,
                                                const ProjectorModel& projector,
                                                const glm::dvec3& v_eye) {
  const auto p = screen_hit(screen, glm::dvec3(0.0), v_eye);
  if (!p) return std::nullopt;
  return projector.q_from_p_eye(*p);
}

Warp true_warp(const Rig& rig, std::size_t index, const TrueWarpOptions& options,
               TrueWarpReport* report) {
  FACET_ASSERT(index < rig.projectors.size());
  const ProjectorModel& projector = rig.projectors[index];
  const glm::dvec2 size(projector.size);

  // The footprint: rays through the image border, densely, and a coarse interior grid.
  std::vector<glm::dvec2> q_samples;
  const int border = 512;
  for (int k = 0; k <= border; ++k) {
    const double f = double(k) / border;
    q_samples.insert(
        q_samples.end(),
        {{f * size.x, 0.0}, {f * size.x, size.y}, {0.0, f * size.y}, {size.x, f * size.y}});
  }
  for (int j = 1; j < 16; ++j) {
    for (int i = 1; i < 16; ++i) q_samples.push_back({size.x * i / 16.0, size.y * j / 16.0});
  }
  std::vector<glm::dvec3> v_eye;
  for (const auto& q : q_samples) {
    const auto ray = projector.v_eye_from_q(q);
    if (!ray) continue;
    const auto p = screen_hit(rig.screen, projector.t_eye_projector, *ray);
    if (p && glm::length(*p) > 0) v_eye.push_back(*p);
  }
  if (v_eye.empty()) {
    throw InputError(
        "rig", "projectors[" + std::to_string(index) + "]",
        "a projector whose image meets the screen (no ray of '" + projector.name + "' does)");
  }
  CoverOptions cover_options = options.cover;
  if (!cover_options.up_eye) cover_options.up_eye = projector.R_eye_projector[1] * -1.0;
  const BaseCover cover = cover_directions(v_eye, cover_options);

  Warp warp;
  warp.base = cover.base;
  warp.R_eye_base = cover.R_eye_base;
  warp.output_size = projector.size;

  auto exact_at = [&](glm::dvec2 st) {
    return exact_projector_pixel(rig.screen, projector,
                                 cover.R_eye_base * cover.base.direction(st));
  };
  auto inside = [&](const glm::dvec2& q) {
    return q.x >= 0 && q.y >= 0 && q.x <= size.x && q.y <= size.y;
  };

  // Start with nodes about 32 px apart along the longer side, then refine: the bilinear error
  // falls with the square of the node spacing.
  glm::ivec2 grid(33, std::max(2, int(std::lround(32.0 * size.y / size.x)) + 1));
  if (size.y > size.x) grid = {std::max(2, int(std::lround(32.0 * size.x / size.y)) + 1), 33};
  TrueWarpReport local;
  std::vector<glm::dvec2> q_node;
  std::vector<char> valid;
  for (;;) {
    ++local.iterations;
    const std::size_t count = std::size_t(grid.x) * grid.y;
    q_node.assign(count, glm::dvec2(0.0));
    valid.assign(count, 0);
    const glm::dvec2 step(1.0 / (grid.x - 1), 1.0 / (grid.y - 1));
    detail::parallel_for(std::size_t(grid.y), [&](std::size_t j, std::size_t) {
      for (int i = 0; i < grid.x; ++i) {
        const auto q = exact_at({i * step.x, double(j) * step.y});
        const std::size_t n = j * grid.x + i;
        if (q) {
          q_node[n] = *q;
          valid[n] = 1;
        }
      }
    });
    // The error of the bilinear interpolation at cell centres and edge midpoints, in every cell
    // whose four nodes are valid and one of them is covered. Horizontal edges measure the
    // spacing along s, vertical edges along t, centres both.
    std::vector<glm::dvec3> worst(std::size_t(grid.y), glm::dvec3(0.0));  // (s, t, centre)
    detail::parallel_for(std::size_t(grid.y - 1), [&](std::size_t j, std::size_t) {
      for (int i = 0; i + 1 < grid.x; ++i) {
        const std::size_t n00 = j * grid.x + i, n10 = n00 + 1, n01 = n00 + grid.x, n11 = n01 + 1;
        if (!(valid[n00] && valid[n10] && valid[n01] && valid[n11])) continue;
        if (!(inside(q_node[n00]) || inside(q_node[n10]) || inside(q_node[n01]) ||
              inside(q_node[n11]))) {
          continue;
        }
        const glm::dvec2 st00(i * step.x, double(j) * step.y);
        auto error = [&](glm::dvec2 f, glm::dvec2 bilinear) {
          const auto q = exact_at(st00 + f * step);
          return q ? glm::length(*q - bilinear) : 0.0;
        };
        glm::dvec3& w = worst[j];
        w.x = std::max(w.x, error({0.5, 0}, 0.5 * (q_node[n00] + q_node[n10])));
        w.x = std::max(w.x, error({0.5, 1}, 0.5 * (q_node[n01] + q_node[n11])));
        w.y = std::max(w.y, error({0, 0.5}, 0.5 * (q_node[n00] + q_node[n01])));
        w.y = std::max(w.y, error({1, 0.5}, 0.5 * (q_node[n10] + q_node[n11])));
        w.z = std::max(
            w.z, error({0.5, 0.5}, 0.25 * (q_node[n00] + q_node[n10] + q_node[n01] + q_node[n11])));
      }
    });
    glm::dvec3 error(0.0);
    for (const auto& w : worst) error = glm::max(error, w);
    local.max_checked_error_px = std::max({error.x, error.y, error.z});
    if (local.max_checked_error_px <= options.max_error_px) break;
    if (grid.x >= options.max_nodes_per_axis && grid.y >= options.max_nodes_per_axis) break;
    auto grow = [&](int nodes, double axis_error) {
      const double factor = std::sqrt(std::max(axis_error, error.z) / options.max_error_px);
      if (factor <= 1) return nodes;
      const int grown = int(std::ceil((nodes - 1) * factor * 1.1)) + 1;
      return std::min(options.max_nodes_per_axis, std::max(grown, nodes + 1));
    };
    grid = {grow(grid.x, error.x), grow(grid.y, error.y)};
  }

  warp.grid_size = grid;
  const std::size_t count = std::size_t(grid.x) * grid.y;
  warp.offset_px.assign(count, glm::vec2(0.0f));
  warp.coverage.assign(count, 0.0f);
  for (int j = 0; j < grid.y; ++j) {
    for (int i = 0; i < grid.x; ++i) {
      const std::size_t n = warp.node_index(i, j);
      if (!valid[n]) continue;
      const glm::dvec2 q0(double(i) / (grid.x - 1) * size.x, double(j) / (grid.y - 1) * size.y);
      warp.offset_px[n] = glm::vec2(q_node[n] - q0);
      warp.coverage[n] = inside(q_node[n]) ? 1.0f : 0.0f;
    }
  }
  if (report) *report = local;
  return warp;
}

}  // namespace facet
