#pragma once
// `facet simulate`: renders what the rig's camera sees while each projector shows the standard
// pattern set, and writes a capture folder (FORMATS.md §1) with the ground truth (§5).
//
// Image formation, per projector and frame, in this order:
//   1. the pattern value v of each projector pixel (patterns.hpp), constant over the pixel;
//   2. the projector's gamma: emitted light v^gamma;
//   3. projector defocus: a Gaussian of σ = defocus_px in projector pixels over the emitted light
//      (light spills past the image edge too). With σ > 0 the blurred image, known at pixel
//      centres, is read bilinearly; with σ = 0 every point of pixel (c, r) gets exactly its value;
//   4. geometry: each camera pixel centre unprojects through the mrcal lens to a ray from the
//      camera centre, which meets the screen (screen.hpp); the point projects into the projector
//      (ProjectorModel). Occlusion is not modelled (the screens are convex, seen from inside);
//   5. light falloff (when enabled): cos(incidence) / distance² from the projector, scaled so that
//      its largest value over the camera image is 1; points lit from behind get nothing;
//   6. exposure: image = ambient + peak · falloff · light;
//   7. camera blur: a Gaussian of σ = camera_blur_px in camera pixels;
//   8. sensor noise: Gaussian, σ = noise (fraction of full scale), from a generator seeded by
//      (seed, projector, frame, repeat), so a capture is a pure function of the rig and settings
//      (repeat counts the exposures of one frame that a live capture averages; simulate takes one);
//   9. quantisation: clamped to [0,1] and rounded to 8- or 16-bit PNG levels.
// The other projectors are dark while one projector's frames are captured.
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "facet/calibration/camera_model.hpp"
#include "facet/calibration/patterns.hpp"
#include "facet/projection/progress.hpp"
#include "facet/projection/rig.hpp"

namespace facet::calibration {

// The rig camera as an mrcal model. With explicit intrinsics they are used as is. Otherwise
// fov_deg sets the focal length and the principal point is the image centre ((W−1)/2, (H−1)/2):
//   - LENSMODEL_STEREOGRAPHIC and LENSMODEL_SPLINED_STEREOGRAPHIC_* (all spline coefficients 0, so
//     both are the plain stereographic lens): fov across the smaller image side,
//     f = (min(W,H)/2) / (2·tan(fov/4));
//   - LENSMODEL_PINHOLE and LENSMODEL_OPENCV4/5/8/12 (distortion 0): fov across the smaller side,
//     below 180°, f = (min(W,H)/2) / tan(fov/2);
//   - LENSMODEL_LONLAT and LENSMODEL_LATLON: fov across the width, f = W / fov (radians), the same
//     angular scale vertically; fov 360 sees all around.
// Throws InputError(source, "camera.…", ...) for other models without intrinsics, a field of
// view out of range, or a model mrcal does not know.
CameraModel rig_camera_model(const RigCamera& camera, const std::string& source = "rig");

// What one projector puts into each camera pixel, before patterns.
struct ProjectorView {
  // CV_64FC2, camera size: the projector position (output pixels) seen by each camera pixel
  // centre; NaN where the camera ray misses the screen, the point has no projector pixel, or the
  // projector lights the surface from behind. May lie outside the projector image.
  cv::Mat q_projector;
  // CV_32F, camera size: the relative falloff factor in [0,1] (1 everywhere lit when falloff is
  // off), 0 where q_projector is NaN.
  cv::Mat irradiance;
};
ProjectorView view_projector(const Rig& rig, const CameraModel& camera, std::size_t projector);

// The pattern list the simulation shows (standard_patterns with the rig's phase settings).
std::vector<Pattern> simulated_patterns(const Rig& rig, std::size_t projector);

// Renders frame `pattern` of one projector as the camera image, CV_32F linear light, with every
// step above except quantisation (values may lie outside [0,1] before it). `frame_index` and
// `repeat` feed the noise seed. This is ambient_image, add_projector_light of the pattern, then
// finish_camera_image: the fake camera of live capture (fake_camera.hpp) forms its images from the
// same three steps.
cv::Mat render_frame(const Rig& rig, const ProjectorView& view, std::size_t projector,
                     const Pattern& pattern, std::size_t frame_index, std::size_t repeat = 0);

// The pieces of render_frame, for images lit by what projectors actually show.
// Step 6's constant: the ambient light alone, CV_32F of camera_size (W, H).
cv::Mat ambient_image(const Rig& rig, glm::ivec2 camera_size);
// Steps 2–6 for one projector: adds to `image` (CV_32F, the camera size of `view`) the light of
// `values`, the image the projector shows (CV_32F, the projector's size, values in [0,1] before
// its gamma). All-zero values add nothing.
void add_projector_light(const Rig& rig, const ProjectorView& view, std::size_t projector,
                         const cv::Mat& values, cv::Mat& image);
// Steps 7–8 in place: camera blur, then noise from noise_seed(seed, projector, frame, repeat).
void finish_camera_image(const Rig& rig, cv::Mat& image, std::size_t projector, std::size_t frame,
                         std::size_t repeat = 0);
// The noise generator's seed of one exposure; repeat 0 is the seed of simulate's frame.
std::uint64_t noise_seed(std::uint64_t seed, std::size_t projector, std::size_t frame,
                         std::size_t repeat);

struct SimulationReport {
  glm::ivec2 camera_size{0, 0};
  std::size_t frames = 0;  // images written, all projectors
  struct Truth {
    std::string projector;
    std::string base;       // the base projection chosen for the truth warp
    glm::ivec2 grid{0, 0};  // its node grid
    double max_checked_error_px = 0;
    double lit_fraction = 0;  // of camera pixels that see this projector's image
  };
  std::vector<Truth> truth;
  double seconds = 0;
};

// Writes the capture folder `out`: capture.json, camera.cameramodel, <projector>/<frame>.png for
// every projector and frame, and truth/ with <projector>.warp.exr (true_warp) plus rig.json (the
// rig as simulated). The folder appears whole or not at all: it must not exist or be empty
// (InputError otherwise). Frames render in parallel on the hardware threads. After
// watch_interrupts(), SIGINT or SIGTERM stops it before the next frame with Interrupted, leaving
// nothing. `source` names the rig in errors. `progress` gets ("frames", done, all) as frames are
// written (from one thread at a time).
SimulationReport simulate_capture(const Rig& rig, const std::filesystem::path& out,
                                  const std::string& source = "rig",
                                  const ProgressSink& progress = {});

}  // namespace facet::calibration
