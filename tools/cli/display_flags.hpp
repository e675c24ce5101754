#pragma once
// Command-line description of a display: an analytic base projection given by flags, or a
// `.warp.exr` file.
#include <CLI/CLI.hpp>
#include <glm/glm.hpp>
#include <optional>
#include <string>

#include "facet/projection/dome_orientation.hpp"
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

// --tilt DEG and --orientation DEG: where a dome sits around the viewer (DomeOrientation), for
// built-in domes and imports.
struct DomeOrientationFlags {
  std::string tilt, orientation;  // degrees; empty: 0

  void add_to(CLI::App& command);
  bool given() const { return !tilt.empty() || !orientation.empty(); }
  // InputError("command line", "--tilt" or "--orientation", ...) for a bad or out-of-range value.
  DomeOrientation value() const;
};

// Turns `warp`'s directions about the eye: R_eye_base ← R_eye_dome · R_eye_base.
void orient_warp(Warp& warp, const DomeOrientation& orientation);

// The orientation for the outputs of `display` as render, run and display name it: flags apply to
// built-in domes (builtin:dome180) only; nullopt when none is given. InputError naming the flag
// for a bad value or another display (a file's display is placed by its file; imports take the
// flags).
std::optional<DomeOrientation> builtin_dome_orientation(const DomeOrientationFlags& flags,
                                                        const std::string& display);

// "WxH" → (W, H); InputError naming the flag otherwise.
glm::ivec2 parse_size(const std::string& text, const std::string& flag);

}  // namespace facet::cli
