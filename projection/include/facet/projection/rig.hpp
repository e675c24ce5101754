#pragma once
// The virtual rig: a screen, posed projectors with lens models, a camera and the settings of a
// simulated capture, plus the exact warp of every projector (the ground truth of a simulation).
// Geometry only (glm and std); rendering images lives in calibration/simulate.hpp, and the rig's
// JSON file in projection_io/rig_file.hpp.
//
// Frames: the eye frame has the eye at its origin, x right, y up, looking down −z (metres). A
// projector's frame is a camera frame: x right, y down, z forward (the optical axis). Projector
// pixels are output pixels: (0,0) is the top-left corner of the image and pixel (c, r) spans
// [c, c+1) × [r, r+1), its centre at (c + 0.5, r + 0.5).
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "facet/projection/footprint.hpp"
#include "facet/projection/screen.hpp"
#include "facet/projection/warp.hpp"

namespace facet {

// A pinhole projector with radial distortion (the Brown–Conrady radial terms, as in OpenCV):
// an undistorted normalised point (x, y) = (X/Z, Y/Z) of the projector frame, at radius r, moves
// to (x, y)·(1 + k1 r² + k2 r⁴ + k3 r⁶) and then to the pixel q = (fx·x_d + cx, fy·y_d + cy).
// Point → pixel is this closed form; pixel → ray inverts the distortion by Newton's method.
//
// Domain: the distortion is used only where it is monotonic, r <= max_undistorted_radius()
// (the first radius where d(r·factor)/dr reaches 0; unbounded when it never does), so every pixel
// has at most one ray. Outside, and behind the projector (Z <= 0), there is no pixel.
struct ProjectorModel {
  std::string name;                  // letters, digits, '_', '-', '.'; names files
  glm::ivec2 size{0, 0};             // W, H in projector pixels
  glm::dvec2 focal_px{0, 0};         // fx, fy in pixels
  glm::dvec2 principal_px{0, 0};     // cx, cy in output pixels (corner convention)
  std::array<double, 3> k{0, 0, 0};  // radial distortion k1, k2, k3
  glm::dmat3 R_eye_projector{1.0};   // projector-frame vectors into the eye frame
  glm::dvec3 t_eye_projector{0.0};   // projector centre in the eye frame, metres
  double gamma = 1;  // a pattern value v in [0,1] emits light proportional to v^gamma

  bool operator==(const ProjectorModel&) const = default;

  // r_d = r·(1 + k1 r² + k2 r⁴ + k3 r⁶) on the normalised image plane.
  double distorted_radius(double r) const;
  // The largest r with a monotonic distortion on [0, r]; +infinity when it is monotonic for all r.
  double max_undistorted_radius() const;
  // True when the distortion is monotonic on [0, r].
  bool monotonic_up_to(double r) const;

  // Pixel of an eye-frame point (metres). nullopt behind the projector (Z <= 0), outside the
  // distortion's domain or for non-finite input. The pixel may lie outside the image.
  std::optional<glm::dvec2> q_from_p_eye(const glm::dvec3& p_eye) const;
  // Unit eye-frame direction of the ray from the projector centre through output pixel q (any
  // q, also outside the image). nullopt when q lies beyond the distortion's domain (its distorted
  // radius exceeds distorted_radius(max_undistorted_radius())). Newton converges to 1e-15 relative
  // in r; the round trip q → ray → q agrees to about 1e-10 px.
  std::optional<glm::dvec3> v_eye_from_q(const glm::dvec2& q) const;
};

// The camera of a simulated capture. The lens is an mrcal lens model given by name; calibration/
// builds the mrcal model from it (see calibration/simulate.hpp for how fov_deg sets intrinsics).
struct RigCamera {
  std::string lensmodel = "LENSMODEL_STEREOGRAPHIC";  // full mrcal name
  glm::ivec2 size{0, 0};                              // imager width, height in pixels
  // Field of view in degrees that sets the focal length when `intrinsics` is empty: across the
  // image width for LONLAT, across the smaller image side for the other models.
  double fov_deg = 180;
  std::vector<double> intrinsics;  // fx, fy, cx, cy, distortion...: used as is when not empty
  // Camera-frame vectors (x right, y down, z forward) into the eye frame; default: looking down −z.
  glm::dmat3 R_eye_camera{glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1)};
  glm::dvec3 t_eye_camera{0.0};  // camera centre in the eye frame, metres; 0 is the eye point

  bool operator==(const RigCamera&) const = default;
};

// Limits shared by rig files and the CLI's flags (simulate, patterns, capture).
inline constexpr double kMinPhasePeriod = 2;      // projector pixels: a shorter period aliases
inline constexpr double kMaxPhasePeriod = 65536;  // the largest projector side
inline constexpr double kMaxGamma = 10;           // gammas in (0, 10], as MPCDI's and the CLI's

// Image formation of a simulated capture, in the order they apply (see calibration/simulate.hpp).
struct SimulationSettings {
  bool phase = true;            // add phase-shift frames
  double phase_period = 16;     // projector pixels per cycle
  int phase_steps = 4;          // shifts per axis, >= 3
  double defocus_px = 1;        // projector defocus: Gaussian σ in projector pixels (0: sharp)
  bool falloff = true;          // light falls off with distance² and the cosine of incidence
  double peak = 0.85;           // brightest white on the screen, as a fraction of full scale
  double ambient = 0.05;        // constant light, fraction of full scale
  double camera_blur_px = 0.5;  // Gaussian σ in camera pixels (0: none)
  double noise = 0.01;          // Gaussian sensor noise σ, fraction of full scale
  int bits = 16;                // PNG bits per sample, 8 or 16
  std::uint64_t seed = 1;       // the noise is a function of the seed, the projector and the frame

  bool operator==(const SimulationSettings&) const = default;
};

struct Rig {
  Screen screen;
  std::vector<ProjectorModel> projectors;
  RigCamera camera;
  SimulationSettings simulation;

  bool operator==(const Rig&) const = default;

  // Throws InputError(source, field, expected) with JSON-style field names (e.g.
  // "projectors[1].focal_px") on the first problem: screen parameters, projector names (valid,
  // unique), sizes, focal lengths, a distortion that is not monotonic out to the image corners,
  // rotations (orthonormal within 1e-6, determinant +1), gamma, camera size and simulation ranges.
  void validate(const std::string& source = "rig") const;
};

// The exact map from an eye-frame direction (any length > 0) to projector pixel: the eye ray
// meets the screen, and the hit point projects into the projector. nullopt where the ray misses
// the screen or the point has no pixel. The pixel may lie outside the image. Occlusion is not
// modelled: the screens are convex as seen from inside.
std::optional<glm::dvec2> exact_projector_pixel(const Screen& screen,
                                                const ProjectorModel& projector,
                                                const glm::dvec3& v_eye);

struct TrueWarpOptions {
  // Largest distance in projector pixels between the bilinear warp and the exact map that the
  // node grid may show at its checked points (cell centres and edge midpoints, in cells with a
  // covered node). Kept below FORMATS.md's 0.01 px, since the largest error lies between them.
  double max_error_px = 0.004;
  int max_nodes_per_axis = 2049;  // the grid stops growing here (the result may then miss)
  // up_eye defaults to the projector's up. Perspective bases are allowed up to 80° off their
  // centre: a projector is a perspective device, so the map from a perspective base to its pixels
  // stays nearly projective and needs far fewer nodes than a fisheye for the same error.
  CoverOptions cover = [] {
    CoverOptions wide;
    wide.max_perspective_half_angle_rad = 1.40;
    return wide;
  }();
};

struct TrueWarpReport {
  double max_checked_error_px = 0;  // the worst error at the checked points
  int iterations = 0;
};

// The exact warp of projector `index` of the rig as an offset map (FORMATS.md §2): a base chosen
// by cover_directions over the projector's footprint seen from the eye (the rays of its image
// border and interior that meet the screen), a node grid refined until the bilinear error at the
// checked points is within options.max_error_px, offsets = exact pixel − q0, coverage 1 where the
// exact pixel lies inside [0,W]×[0,H] and 0 elsewhere. Nodes without an exact pixel get offset 0
// and coverage 0. Throws InputError when the projector does not light the screen at all.
Warp true_warp(const Rig& rig, std::size_t index, const TrueWarpOptions& options = {},
               TrueWarpReport* report = nullptr);

}  // namespace facet
