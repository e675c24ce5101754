#pragma once
// display.json (FORMATS.md §4): one display's eye point, screen, projectors (output, warp, blend,
// black level, gamma) and render settings, as a plain value. The JSON schema of the file is
// configs/display.schema.json; this reader is the validator the project trusts.
//
// Units: metres for the eye and the screen (in the display's world frame, which shares its axes
// with the eye frame: x right, y up, the eye looking down −z), output pixels for sizes and window
// rectangles (desktop pixels, y down).
#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/projection/screen.hpp"

namespace facet::projection_io {

inline constexpr const char* kDisplayFormat = "facet-display/1";

// The display surface, in the same JSON shape as capture.json's `screen` (FORMATS.md §1): the
// projection core's Screen, so that a display's screen meets rays with facet::intersect_screen.
using DisplayScreen = facet::Screen;

// Where a projector's image goes. A monitor name (EDID/connector name as the window system
// reports it) survives a reboot; `position`/`size` say where that monitor sat on the desktop and
// serve as the fallback window when it is missing and `missing_monitor` is "window". A window is a
// fixed desktop rectangle.
struct DisplayOutput {
  enum class Kind { monitor, window };
  Kind kind = Kind::window;
  std::string monitor;                 // kind == monitor: non-empty
  std::optional<glm::ivec2> position;  // kind == monitor: optional fallback position
  std::optional<glm::ivec2> size;      // kind == monitor: optional fallback size (> 0)
  glm::ivec4 window{0, 0, 0, 0};       // kind == window: x, y, width (> 0), height (> 0)

  bool operator==(const DisplayOutput&) const = default;
};

struct DisplayProjector {
  std::string name;                            // letters, digits, '_', '-', '.'; unique
  glm::ivec2 size{0, 0};                       // W, H in output pixels
  std::filesystem::path warp;                  // .warp.exr, relative to the display.json folder
  std::optional<std::filesystem::path> blend;  // .blend.exr (FORMATS.md §3), relative
  std::optional<std::filesystem::path> black;  // .black.exr black level β, relative
  // Output encoding: value = linear^(1/gamma), > 0; nullopt (JSON "srgb", the default) for the
  // sRGB transfer function, which the GPU applies for free, so that blending touches only
  // pixels whose weight is below 1 or whose black level is above 0.
  std::optional<double> gamma;
  DisplayOutput output;

  bool operator==(const DisplayProjector&) const = default;
};

struct RenderSettings {
  // The render method (see the driver's render_method_names()); checked there, since the set of
  // methods belongs to the driver. Here: a non-empty name of [a-z0-9_-].
  std::string method = "facets";
  double tolerance_px = 0.25;  // facet builder tolerance, output pixels, > 0
  double z_near = 0.05;        // near plane distance, metres, > 0

  bool operator==(const RenderSettings&) const = default;
};

enum class MissingMonitor { error, window };

// One render node of a cluster: a machine (or, for a try-out, a process) that drives some of the
// display's projectors.
struct ClusterNode {
  std::string name;  // letters, digits, '_', '-', '.'; unique
  // Where this node listens: "tcp://HOST:PORT" (PORT in 1..65534) or "ipc://PATH". It uses this
  // address for the frame states and the next one (PORT + 1, or PATH + ".barrier") for the swap
  // barrier; the master dials every other node's pair.
  std::string address;
  std::vector<std::string> projectors;  // names in DisplayConfig::projectors; at least one
  bool critical = false;                // losing it stops the whole cluster

  bool operator==(const ClusterNode&) const = default;
};

// The display's projectors spread over render nodes (display.json "cluster"). Every projector
// belongs to exactly one node; one node is the master, which owns the frame state and the
// barrier.
struct DisplayCluster {
  std::vector<ClusterNode> nodes;  // at least one
  std::string master;              // the name of one of the nodes
  // How long the master waits at the swap barrier for a node before it drops it, and how long
  // a node waits to hear from the master before it gives up, in ms (> 0, at most 600,000);
  // nullopt: 3 frame periods (kDefaultClusterDeadlineFrames).
  std::optional<double> deadline_ms;

  bool operator==(const DisplayCluster&) const = default;
};
inline constexpr double kDefaultClusterDeadlineFrames = 3;
inline constexpr double kMaxClusterDeadline_ms = 600'000;

// The second address a node listens on (the swap barrier's), derived from its address:
// tcp://HOST:PORT -> tcp://HOST:PORT+1, ipc://PATH -> ipc://PATH.barrier. Expects a valid address.
std::string cluster_barrier_address(const std::string& address);
// An empty string when `address` is a valid node address, else what was expected.
std::string cluster_address_problem(const std::string& address);

struct DisplayConfig {
  // The folder relative paths resolve against (the folder of display.json). Not stored.
  std::filesystem::path folder;
  std::string name;     // non-empty
  glm::dvec3 eye{0.0};  // eye point in the display's world frame, metres
  std::optional<DisplayScreen> screen;
  std::vector<DisplayProjector> projectors;  // at least one
  RenderSettings render;
  MissingMonitor missing_monitor = MissingMonitor::error;
  std::optional<DisplayCluster> cluster;  // nullopt: one process drives every projector

  bool operator==(const DisplayConfig&) const = default;

  std::filesystem::path resolve(const std::filesystem::path& relative) const {
    return folder / relative;
  }
};

// Parses and validates the text of a display.json. `source` names the file in errors; `folder` is
// stored in the result. When `check_files` is set, every referenced warp, blend and black file
// must exist under `folder`. Throws InputError(source, field, expected) on the first problem:
// invalid JSON, missing or mistyped fields, NaN or Inf, unknown enumerated values, duplicate
// projector names, missing files, a cluster section that names an unknown projector or master,
// leaves a projector to no node or gives one to two, or repeats a node or an address, and
// unknown fields ("unknown field 'blnd'; did you mean
// 'blend'?"); keys starting with "x-" are free for users' notes.
DisplayConfig parse_display_config(const std::string& text, const std::string& source,
                                   const std::filesystem::path& folder, bool check_files);

// Reads display.json (`path` may also be its folder), checking that referenced files exist.
DisplayConfig read_display_config(const std::filesystem::path& path, bool check_files = true);

// Reads a display.json whose warps do not exist yet, as `facet capture` and `facet calibrate
// --display` take it: a projector without `warp` gets "<name>.warp.exr", and no referenced file
// is checked. `path` may also be its folder.
DisplayConfig read_display_template(const std::filesystem::path& path);

// Validates a value as the reader would (without touching files when check_files is false).
void validate_display_config(const DisplayConfig& config, const std::string& source,
                             bool check_files);

// The text of display.json for `config` (2-space indented JSON, a newline at the end), as
// write_display_config writes it; no validation.
std::string format_display_config(const DisplayConfig& config);

// Validates (without checking files), then writes atomically. Paths are written as stored.
void write_display_config(const DisplayConfig& config, const std::filesystem::path& path);

}  // namespace facet::projection_io
