#include "facet/interop/bourke.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "facet/interop/inverse_grid.hpp"
#include "facet/projection/errors.hpp"

namespace facet::interop {
namespace {

// Splits the text into lines without copying; accepts \n and \r\n.
std::vector<std::string_view> lines_of(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

// Parses whitespace-separated numbers; false on anything else.
bool numbers(std::string_view line, std::vector<double>& out) {
  out.clear();
  const std::string text(line);
  const char* p = text.c_str();
  while (true) {
    while (*p == ' ' || *p == '\t') ++p;
    if (*p == '\0') return true;
    char* end = nullptr;
    const double value = std::strtod(p, &end);
    if (end == p) return false;
    out.push_back(value);
    p = end;
  }
}

// The automatic warp grid: refined while an interior node is reproduced worse than this, up to
// this many nodes per side.
constexpr double kAutoGridBoundPx = 1.0;
constexpr int kMaxAutoGrid = 1025;

// The worst distance in output pixels between where `warp` sends a used mesh node's source
// position and the node's output position, over nodes whose eight neighbours are used too (the
// others sit next to extrapolated cells).
double worst_node_error_px(const BourkeMesh& mesh, const Warp& warp) {
  const int nx = mesh.grid_size.x, ny = mesh.grid_size.y;
  const auto used = [&](int i, int j) {
    const BourkeNode& n = mesh.nodes[std::size_t(j) * nx + i];
    return n.u >= 0 && n.v >= 0;
  };
  double worst = 0;
  for (int j = 1; j + 1 < ny; ++j) {
    for (int i = 1; i + 1 < nx; ++i) {
      bool interior = true;
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) interior = interior && used(i + di, j + dj);
      }
      if (!interior) continue;
      const BourkeNode& n = mesh.nodes[std::size_t(j) * nx + i];
      const glm::dvec2 q{(n.x / mesh.aspect + 1) / 2 * warp.output_size.x,
                         (1 - n.y) / 2 * warp.output_size.y};
      worst = std::max(worst, glm::length(warp.q_from_st({n.u, 1 - n.v}) - q));
    }
  }
  return worst;
}

}  // namespace

BourkeMesh parse_bourke(std::string_view text, const std::string& source) {
  std::vector<std::string_view> lines = lines_of(text);
  // Trailing blank lines are common.
  while (!lines.empty() && lines.back().find_first_not_of(" \t") == std::string_view::npos) {
    lines.pop_back();
  }
  std::vector<double> values;
  BourkeMesh mesh;
  if (lines.empty() || !numbers(lines[0], values) || values.size() != 1 ||
      values[0] != std::floor(values[0])) {
    throw InputError(source, "line 1", "expected the mesh type, a whole number");
  }
  if (values[0] != 2) {
    throw InputError(source, "line 1", "expected mesh type 2 (rectangular)");
  }
  mesh.mesh_type = 2;
  if (lines.size() < 2 || !numbers(lines[1], values) || values.size() != 2 ||
      values[0] != std::floor(values[0]) || values[1] != std::floor(values[1]) || values[0] < 2 ||
      values[1] < 2 || values[0] > 4096 || values[1] > 4096) {
    throw InputError(source, "line 2", "expected \"nx ny\", whole numbers in [2, 4096]");
  }
  mesh.grid_size = {int(values[0]), int(values[1])};
  const std::size_t count = std::size_t(mesh.grid_size.x) * mesh.grid_size.y;
  if (lines.size() - 2 != count) {
    throw InputError(source, "nodes",
                     "expected nx·ny = " + std::to_string(count) + " node lines, found " +
                         std::to_string(lines.size() - 2));
  }
  mesh.nodes.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::string field = "line " + std::to_string(k + 3);
    if (!numbers(lines[k + 2], values) || values.size() != 5) {
      throw InputError(source, field, "expected five numbers \"x y u v intensity\"");
    }
    for (double value : values) {
      if (!std::isfinite(value)) throw InputError(source, field, "expected finite numbers");
    }
    mesh.nodes.push_back({values[0], values[1], values[2], values[3], values[4]});
  }
  // The output positions must form the regular grid the format promises.
  const BourkeNode& first = mesh.nodes.front();
  const BourkeNode& last = mesh.nodes.back();
  mesh.aspect = std::max(std::abs(first.x), std::abs(last.x));
  if (!(mesh.aspect > 1e-6) || std::abs(first.y + 1) > 1e-3 || std::abs(last.y - 1) > 1e-3 ||
      std::abs(first.x + mesh.aspect) > 1e-3 * mesh.aspect ||
      std::abs(last.x - mesh.aspect) > 1e-3 * mesh.aspect) {
    throw InputError(source, "line 3",
                     "expected the first node at (−aspect, −1) and the last at (aspect, 1)");
  }
  const double step_x = 2 * mesh.aspect / (mesh.grid_size.x - 1);
  const double step_y = 2.0 / (mesh.grid_size.y - 1);
  for (int j = 0; j < mesh.grid_size.y; ++j) {
    for (int i = 0; i < mesh.grid_size.x; ++i) {
      const BourkeNode& node = mesh.nodes[std::size_t(j) * mesh.grid_size.x + i];
      if (std::abs(node.x - (-mesh.aspect + i * step_x)) > 0.01 * step_x ||
          std::abs(node.y - (-1 + j * step_y)) > 0.01 * step_y) {
        throw InputError(source, "line " + std::to_string(j * mesh.grid_size.x + i + 3),
                         "expected x, y on the regular " + std::to_string(mesh.grid_size.x) + "×" +
                             std::to_string(mesh.grid_size.y) + " grid over ±aspect × ±1");
      }
    }
  }
  return mesh;
}

std::vector<glm::ivec2> unfold_bourke(BourkeMesh& mesh) {
  const int nx = mesh.grid_size.x, ny = mesh.grid_size.y;
  const auto node = [&](int i, int j) -> BourkeNode& {
    return mesh.nodes[std::size_t(j) * nx + i];
  };
  const auto used = [&](int i, int j) {
    return i >= 0 && j >= 0 && i < nx && j < ny && node(i, j).u >= 0 && node(i, j).v >= 0;
  };
  const auto uv = [&](int i, int j) { return glm::dvec2(node(i, j).u, node(i, j).v); };
  const auto cross = [](glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; };
  // Output x right and y up, source u right and v up: an unfolded cell keeps its orientation.
  // Collapsed means under a thousandth of the median cell's area.
  std::vector<double> areas;
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      if (used(i, j) && used(i + 1, j) && used(i, j + 1) && used(i + 1, j + 1)) {
        areas.push_back(cross(uv(i + 1, j) - uv(i, j), uv(i, j + 1) - uv(i, j)));
      }
    }
  }
  if (areas.empty()) return {};
  std::nth_element(areas.begin(), areas.begin() + areas.size() / 2, areas.end());
  const double min_area = 1e-3 * std::abs(areas[areas.size() / 2]);
  const double sign = areas[areas.size() / 2] >= 0 ? 1.0 : -1.0;
  const auto folded = [&](int i, int j) {
    if (!(used(i, j) && used(i + 1, j) && used(i, j + 1) && used(i + 1, j + 1))) return false;
    const glm::dvec2 a = uv(i, j), b = uv(i + 1, j), c = uv(i, j + 1), d = uv(i + 1, j + 1);
    return !(sign * cross(b - a, c - a) > min_area && sign * cross(c - d, b - d) > min_area);
  };
  // How far a node strays from the continuation of its used neighbours, in source units.
  const auto stray = [&](int i, int j) {
    double worst = 0;
    const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
    for (int d = 0; d < 4; ++d) {
      if (used(i + di[d], j + dj[d]) && used(i + 2 * di[d], j + 2 * dj[d])) {
        const glm::dvec2 line = 2.0 * uv(i + di[d], j + dj[d]) - uv(i + 2 * di[d], j + 2 * dj[d]);
        worst = std::max(worst, glm::length(uv(i, j) - line));
      }
    }
    return worst;
  };
  std::vector<glm::ivec2> masked;
  for (bool changed = true; changed;) {
    changed = false;
    for (int j = 0; j + 1 < ny; ++j) {
      for (int i = 0; i + 1 < nx; ++i) {
        if (!folded(i, j)) continue;
        glm::ivec2 worst_node{i, j};
        double worst = -1;
        for (int c = 0; c < 4; ++c) {
          const glm::ivec2 n{i + c % 2, j + c / 2};
          const double s = stray(n.x, n.y);
          if (s > worst) worst = s, worst_node = n;
        }
        node(worst_node.x, worst_node.y).u = -1;
        node(worst_node.x, worst_node.y).v = -1;
        masked.push_back(worst_node);
        changed = true;
      }
    }
  }
  return masked;
}

ImportedProjector import_bourke(const BourkeMesh& original, const BourkeImportOptions& options,
                                const std::string& source, const std::string& name) {
  BourkeMesh mesh = original;
  const std::vector<glm::ivec2> masked = unfold_bourke(mesh);
  const glm::ivec2 size = options.output_size;
  FACET_ASSERT(size.x > 0 && size.y > 0);
  if (std::abs(double(size.x) / size.y / mesh.aspect - 1) > 0.01) {
    throw InputError(source, "aspect",
                     "expected the output size's aspect (" +
                         std::to_string(double(size.x) / size.y) + ") to match the mesh's (" +
                         std::to_string(mesh.aspect) + ") within 1%");
  }
  const glm::ivec2 nodes = mesh.grid_size;
  // File rows run bottom to top; facet's grids run top to bottom.
  InverseGrid grid;
  grid.grid_size = nodes;
  grid.st.resize(mesh.nodes.size());
  std::vector<double> intensity(mesh.nodes.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int j = 0; j < nodes.y; ++j) {
    for (int i = 0; i < nodes.x; ++i) {
      const BourkeNode& node = mesh.nodes[std::size_t(nodes.y - 1 - j) * nodes.x + i];
      const std::size_t k = std::size_t(j) * nodes.x + i;
      const bool used = node.u >= 0 && node.v >= 0;
      grid.st[k] = used ? glm::dvec2(node.u, 1 - node.v) : glm::dvec2(nan);
      intensity[k] =
          used ? std::pow(std::clamp(node.intensity, 0.0, 1.0), options.intensity_gamma) : 0;
    }
  }
  ImportedProjector projector;
  projector.name = name;
  for (const glm::ivec2& n : masked) {
    const BourkeNode& node = original.nodes[std::size_t(n.y) * nodes.x + n.x];
    char text[256];
    std::snprintf(text, sizeof text,
                  "mesh node (%d, %d) (line %d) at output pixel (%.0f, %.0f) shows (u, v) = "
                  "(%g, %g), which folds the mesh over its neighbours: taken as unused",
                  n.x, n.y, n.y * nodes.x + n.x + 3, (node.x / mesh.aspect + 1) / 2 * size.x,
                  (1 - node.y) / 2 * size.y, node.u, node.v);
    projector.notes.push_back(text);
  }
  if (options.warp_grid.x >= 2) {
    projector.warp = warp_from_inverse_grid(grid, options.base, options.R_eye_base, size,
                                            options.warp_grid, source);
  } else {
    // The forward grid is uniform over the source image, the mesh is not: where a mirror's edge
    // crowds many mesh rows into a sliver of the source, a forward grid as coarse as the mesh
    // cannot follow it. Refine until every interior mesh node is reproduced within the bound.
    glm::ivec2 warp_grid = nodes;
    for (;;) {
      projector.warp =
          warp_from_inverse_grid(grid, options.base, options.R_eye_base, size, warp_grid, source);
      const double worst = worst_node_error_px(mesh, projector.warp);
      const glm::ivec2 finer = glm::min(2 * (warp_grid - 1) + 1, glm::ivec2(kMaxAutoGrid));
      if (worst <= kAutoGridBoundPx || finer == warp_grid) {
        if (warp_grid != nodes) {
          char text[200];
          std::snprintf(text, sizeof text,
                        "warp grid %d×%d (the mesh's %d×%d does not follow it within %.0f px); "
                        "interior mesh nodes reproduced within %.2f px",
                        warp_grid.x, warp_grid.y, nodes.x, nodes.y, kAutoGridBoundPx, worst);
          projector.notes.push_back(text);
        }
        break;
      }
      warp_grid = finer;
    }
  }
  projection_io::BlendMap blend = projection_io::BlendMap::constant(size, 0.0f);
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      // Output pixel centre in node units; nodes span the image edge to edge.
      const double gx = (x + 0.5) / size.x * (nodes.x - 1);
      const double gy = (y + 0.5) / size.y * (nodes.y - 1);
      const int i = std::min(int(gx), nodes.x - 2), j = std::min(int(gy), nodes.y - 2);
      const double fx = gx - i, fy = gy - j;
      const auto at = [&](int a, int b) { return intensity[std::size_t(b) * nodes.x + a]; };
      const double value = (at(i, j) * (1 - fx) + at(i + 1, j) * fx) * (1 - fy) +
                           (at(i, j + 1) * (1 - fx) + at(i + 1, j + 1) * fx) * fy;
      blend.at(x, y) = float(std::clamp(value, 0.0, 1.0));
    }
  }
  projector.blend = std::move(blend);
  projector.output.kind = projection_io::DisplayOutput::Kind::window;
  projector.output.window = {0, 0, size.x, size.y};
  return projector;
}

}  // namespace facet::interop
