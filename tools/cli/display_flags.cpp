#include "display_flags.hpp"

#include <map>
#include <sstream>
#include <vector>

#include "facet/projection/errors.hpp"
#include "facet/projection/warp.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet::cli {
namespace {

std::vector<double> parse_numbers(const std::string& text, const std::string& flag,
                                  std::size_t count_min, std::size_t count_max) {
  std::vector<double> values;
  // getline drops a last empty item: "1,2," would be read as "1,2".
  if (text.ends_with(','))
    throw InputError("command line", flag, "expected comma-separated numbers; got '" + text + "'");
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InputError("command line", flag,
                       "expected comma-separated numbers; got '" + text + "'");
    }
  }
  if (values.size() < count_min || values.size() > count_max) {
    throw InputError("command line", flag,
                     "expected " + std::to_string(count_min) +
                         (count_max > count_min ? " to " + std::to_string(count_max) : "") +
                         " comma-separated numbers; got '" + text + "'");
  }
  return values;
}

}  // namespace

glm::ivec2 parse_size(const std::string& text, const std::string& flag) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  std::stringstream stream(text);
  if (!(stream >> w >> x >> h) || (x != 'x' && x != 'X') || (stream >> extra) || w < 1 || h < 1) {
    throw InputError("command line", flag,
                     "expected WxH with positive integers; got '" + text + "'");
  }
  check_image_size({w, h}, "command line", flag);
  return {w, h};
}

void DisplayFlags::add_to(CLI::App& command) {
  command.add_option("--warp", warp_path, "Offset map (.warp.exr) instead of an analytic display");
  command.add_option("--base", base, "perspective | fisheye | cylindrical | equirectangular")
      ->capture_default_str();
  command.add_option("--size", size, "Output size WxH in pixels")->capture_default_str();
  command.add_option("--azimuth", azimuth, "Cylindrical/equirectangular azimuth a0,a1 (degrees)")
      ->capture_default_str();
  command.add_option("--tan-elevation", tan_elevation, "Cylindrical tan(elevation) top,bottom")
      ->capture_default_str();
  command.add_option("--elevation", elevation, "Equirectangular elevation top,bottom (degrees)")
      ->capture_default_str();
  command.add_option("--tan-extent", tan_extent, "Perspective tangents left,right,top,bottom")
      ->capture_default_str();
  command.add_option("--fov", fov,
                     "Fisheye field of view (degrees), or perspective X[,Y] fields of view");
}

Warp DisplayFlags::make_warp() const {
  if (!warp_path.empty()) return read_warp(warp_path);
  const BaseKind kind = base_kind_from_string(base, "command line", "--base");
  BaseProjection projection;
  switch (kind) {
    case BaseKind::perspective:
      if (!fov.empty()) {
        const auto f = parse_numbers(fov, "--fov", 1, 2);
        try {
          projection = BaseProjection::perspective_fov(f[0], f.size() > 1 ? f[1] : f[0]);
        } catch (const InputError& e) {
          throw InputError("command line", "--fov", e.expected());
        }
      } else {
        const auto t = parse_numbers(tan_extent, "--tan-extent", 4, 4);
        projection = BaseProjection::perspective(t[0], t[1], t[2], t[3]);
      }
      break;
    case BaseKind::fisheye:
      projection =
          BaseProjection::fisheye(fov.empty() ? 180.0 : parse_numbers(fov, "--fov", 1, 1)[0]);
      break;
    case BaseKind::cylindrical: {
      const auto a = parse_numbers(azimuth, "--azimuth", 2, 2);
      const auto t = parse_numbers(tan_elevation, "--tan-elevation", 2, 2);
      projection = BaseProjection::cylindrical(a[0], a[1], t[0], t[1]);
      break;
    }
    case BaseKind::equirectangular: {
      const auto a = parse_numbers(azimuth, "--azimuth", 2, 2);
      const auto e = parse_numbers(elevation, "--elevation", 2, 2);
      projection = BaseProjection::equirectangular(a[0], a[1], e[0], e[1]);
      break;
    }
  }
  // The projection's own checks name its fields: named here by the flags that set them.
  try {
    projection.validate("command line");
  } catch (const InputError& error) {
    const std::map<std::string, std::string> flags{
        {"azimuth", "--azimuth"},
        {"tan_elevation", "--tan-elevation"},
        {"elevation", "--elevation"},
        {"tan_extent", fov.empty() ? "--tan-extent" : "--fov"},
        {"fov", "--fov"}};
    const auto flag = flags.find(error.field());
    if (flag == flags.end()) throw;
    throw InputError("command line", flag->second, error.expected());
  }
  return Warp::analytic(projection, parse_size(size, "--size"));
}

void DomeOrientationFlags::add_to(CLI::App& command) {
  command.add_option("--tilt", tilt,
                     "The dome tilted forward by DEG about the eye's x axis, its zenith toward the "
                     "front, in [-90, 90] (default 0)");
  command.add_option("--orientation", orientation,
                     "The dome turned by DEG about the vertical, its front toward the right as a "
                     "compass heading, in [-360, 360] (default 0)");
}

DomeOrientation DomeOrientationFlags::value() const {
  DomeOrientation result;
  if (!tilt.empty()) result.tilt_deg = parse_numbers(tilt, "--tilt", 1, 1)[0];
  if (!orientation.empty()) {
    result.orientation_deg = parse_numbers(orientation, "--orientation", 1, 1)[0];
  }
  try {
    result.validate("command line");
  } catch (const InputError& error) {
    // DomeOrientation names its fields; these flags set them.
    throw error.with_option_shown_as(error.option() == "tilt_deg" ? "--tilt" : "--orientation");
  }
  return result;
}

void orient_warp(Warp& warp, const DomeOrientation& orientation) {
  warp.R_eye_base = orientation.R_eye_dome() * warp.R_eye_base;
}

std::optional<DomeOrientation> builtin_dome_orientation(const DomeOrientationFlags& flags,
                                                        const std::string& display) {
  if (!flags.given()) return std::nullopt;
  const DomeOrientation orientation = flags.value();
  if (display != "builtin:dome180") {
    throw InputError("command line", flags.tilt.empty() ? "--orientation" : "--tilt",
                     "expected a built-in dome display (builtin:dome180), not '" + display +
                         "': imports take the flag (facet bourke|sgct|mpcdi import), and a file's "
                         "display is placed by its warps");
  }
  return orientation;
}

void LayoutFlags::add_to(CLI::App& command) {
  auto* group = command.add_option_group("facets", "How to choose the facets (one of)");
  group->add_option("--pieces", pieces, "N vertical strips, one row (the seed's cylinder)");
  group->add_option("--grid", grid, "A uniform GXxGY grid of cells, two facets each");
  group->add_option("--tolerance", tolerance_px, "Fewest facets with max error <= PX pixels");
  group->require_option(0, 1);
  command
      .add_option("--builder", builder,
                  "How a tolerance layout is built: fewest (default: both, keeping the one with "
                  "fewer facets), tensor (rows and columns spaced to fit) or bisection (refined "
                  "only where the warp needs it)")
      ->check(CLI::IsMember({"fewest", "tensor", "bisection"}));
}

FacetLayout LayoutFlags::layout() const {
  if (pieces) return FacetStrips{*pieces};
  if (!grid.empty()) {
    const glm::ivec2 g = parse_size(grid, "--grid");
    return FacetGrid{g.x, g.y};
  }
  FacetTolerance tolerance{tolerance_px.value_or(0.25)};
  if (builder == "tensor") tolerance.builder = FacetTolerance::Builder::tensor;
  if (builder == "bisection") tolerance.builder = FacetTolerance::Builder::bisection;
  return tolerance;
}

}  // namespace facet::cli
