#include "facet/interop/bourke.hpp"

#include <cmath>
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

ImportedProjector import_bourke(const BourkeMesh& mesh, const BourkeImportOptions& options,
                                const std::string& source, const std::string& name) {
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
  const glm::ivec2 warp_grid = options.warp_grid.x >= 2 ? options.warp_grid : nodes;
  projector.warp =
      warp_from_inverse_grid(grid, options.base, options.R_eye_base, size, warp_grid, source);
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
