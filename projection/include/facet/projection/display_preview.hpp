#pragma once
// What the audience sees from the eye: every projector's coverage and blend weight per eye
// direction, sampled on a fisheye (dome master) or equirectangular image of the eye's sphere, with
// the coverage figures weighted by solid angle.
//
// Each preview pixel centre is an eye direction v (ContentProjection::v_eye_from_point). A
// projector covers v when its exact map takes v to a covered base point inside its output
// (Warp::project); its weight there is its blend map α sampled bilinearly at that output pixel
// (1 without a map). A well-blended display sums to 1 wherever it is covered.
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <vector>

#include "facet/projection/content_projection.hpp"
#include "facet/projection/warp.hpp"

namespace facet {

struct PreviewProjector {
  std::string name;
  const Warp* warp = nullptr;    // the projector's exact map, eye frame; not null
  glm::ivec2 alpha_size{0, 0};   // size of `alpha`: the output size, or (0, 0) for α = 1
  std::span<const float> alpha;  // blend weight per output pixel, row-major, alpha_channels each
  int alpha_channels = 1;        // 1, or 3 (R, G, B: their mean is used)
  // Optional: a calibration's fit residual (RMS, output pixels) per block of residual_block_px ×
  // residual_block_px output pixels, row-major over residual_blocks (which tile the output);
  // NaN where no sample fell.
  glm::ivec2 residual_blocks{0, 0};
  int residual_block_px = 8;
  std::span<const float> residual_px;
};

struct PreviewOptions {
  // fisheye_content(fov, orientation) or equirect_content(...): which eye directions the preview
  // image shows. Only fisheye and equirect are accepted.
  ContentProjection view = fisheye_content();
  int height_px = 1024;  // fisheye: height × height; equirect: 2·height × height; 8 to 8192
};

// The colourings of a preview (render_preview).
enum class PreviewShow { projectors, overlap, blend, uncovered, residual };
std::string to_string(PreviewShow show);
// "projectors", "overlap", "blend", "uncovered", "residual"; InputError(source, field, ...)
// otherwise.
PreviewShow preview_show_from_string(const std::string& name, const std::string& source,
                                     const std::string& field);

struct DisplayPreview {
  glm::ivec2 size{0, 0};  // W, H of the preview image
  std::vector<std::string> names;
  // Per preview pixel, row-major, row 0 at the top:
  std::vector<std::uint8_t> in_view;    // 1 where the pixel shows a direction (the fisheye disc)
  std::vector<std::uint8_t> count;      // projectors covering the direction
  std::vector<float> blend_sum;         // Σ α over the covering projectors
  std::vector<std::int16_t> strongest;  // the covering projector of largest α, or −1
  std::vector<std::array<float, 3>> rgb_by_projector;  // Σ α·colour(projector), linear
  // The strongest covering projector's fit residual at the direction (output pixels); NaN where
  // it has no residual map or no sample fell in that block.
  std::vector<float> residual_px;
  std::vector<double> solid_angle_sr;  // solid angle of each pixel (0 outside the view)

  struct Figures {
    double view_sr = 0;       // solid angle the preview shows (2π for a 180° fisheye)
    double covered_sr = 0;    // covered by at least one projector
    double overlap_sr = 0;    // covered by two or more
    double uncovered_sr = 0;  // in view and covered by none
    // Σ α − 1 over covered directions: worst |·|, 99th percentile of |·| (solid-angle weighted),
    // and the solid angle where |Σ α − 1| > 0.005.
    double blend_worst = 0, blend_p99 = 0, blend_off_sr = 0;
    std::vector<double> projector_sr;  // per projector: the solid angle it covers
    // Over the directions with a residual: solid-angle weighted median and 99th percentile, and
    // the worst (output pixels); 0 without residual maps.
    double residual_p50_px = 0, residual_p99_px = 0, residual_worst_px = 0;
  } figures;
};

// Samples every projector at every preview pixel; runs on all hardware threads. InputError
// (source, ...) for a view other than fisheye or equirect, a height outside [8, 8192], or an
// alpha map whose size disagrees with its warp's output size.
DisplayPreview preview_display(std::span<const PreviewProjector> projectors,
                               const PreviewOptions& options, const std::string& source);

// The view that shows every covered direction of `projectors` largest: a fisheye about the
// normalised mean of their covered directions (sampled on each base image's 65 × 65 grid where
// its coverage is at least 0.5), its field of view twice the largest angle from that axis rounded
// up to 10°, its front the eye's −z made perpendicular to the axis; an equirect panorama when
// that field of view would exceed 270° (a 360° cylinder). Domes come out centred on their
// zenith, walls zoomed in.
ContentProjection fitted_preview_view(std::span<const PreviewProjector> projectors);

// The residual heat scale (sRGB): blue at 0, green at 0.5 px, yellow at 1, red at 2, white from 4
// px on, linear between. calibrate's report pictures use it too.
glm::u8vec3 residual_heat_srgb(double residual_px);

// The preview as an sRGB RGBA8 image (size() × 4 bytes): the chosen colouring, a latitude and
// longitude grid every 30° of the view's frame, and a legend (projector colours, overlap counts,
// or the blend-sum scale) in the top-left corner. Outside the view is black.
std::vector<std::uint8_t> render_preview(const DisplayPreview& preview, PreviewShow show,
                                         const ContentProjection& view);

// The colour of projector `index` in the projectors view (linear RGB, distinct for the first 12).
glm::vec3 preview_projector_colour(std::size_t index);

}  // namespace facet
