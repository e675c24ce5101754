#pragma once
// Command-line description of a display: an analytic base projection given by flags, or a
// `.warp.exr` file.
#include <CLI/CLI.hpp>
#include <glm/glm.hpp>
#include <optional>
#include <string>

#include "facet/projection/facets.hpp"
#include "facet/projection/warp.hpp"

namespace facet::cli {

struct DisplayFlags {
  std::string warp_path;
  std::string base = "cylindrical";
  std::string size = "1600x1200";
  std::string azimuth = "-180,180";
  std::string tan_elevation = "1,-1";
  std::string elevation = "90,-90";
  std::string tan_extent = "-1,1,1,-1";
  std::string fov;  // fisheye: degrees; perspective: "X" or "X,Y" degrees (instead of tan_extent)

  void add_to(CLI::App& command);
  Warp make_warp() const;
};

struct LayoutFlags {
  std::optional<int> pieces;
  std::string grid;
  std::optional<double> tolerance_px;
  std::string builder = "fewest";

  void add_to(CLI::App& command);
  // Defaults to a tolerance of 0.25 px when no flag is given.
  FacetLayout layout() const;
};

// "WxH" → (W, H); InputError naming the flag otherwise.
glm::ivec2 parse_size(const std::string& text, const std::string& flag);

}  // namespace facet::cli
