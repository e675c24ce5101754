#include "facet/projection/display_preview.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <thread>

#include "facet/projection/errors.hpp"
#include "facet/projection/memory_budget.hpp"
#include "raster.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;
// |Σ α − 1| above this counts as a blend error in the figures and in the blend colouring.
constexpr double kBlendTolerance = 0.005;

// Bilinear α at output position q (pixel centres at half-integers), clamped to the image; the
// mean of R, G, B for three-channel maps.
double alpha_at(const PreviewProjector& projector, glm::dvec2 q) {
  if (projector.alpha.empty()) return 1;
  const glm::ivec2 size = projector.alpha_size;
  const double x = std::clamp(q.x - 0.5, 0.0, double(size.x - 1));
  const double y = std::clamp(q.y - 0.5, 0.0, double(size.y - 1));
  const int x0 = std::min(int(x), size.x - 1), y0 = std::min(int(y), size.y - 1);
  const int x1 = std::min(x0 + 1, size.x - 1), y1 = std::min(y0 + 1, size.y - 1);
  const double fx = x - x0, fy = y - y0;
  const int channels = projector.alpha_channels;
  double sum = 0;
  for (int c = 0; c < channels; ++c) {
    auto at = [&](int xi, int yi) {
      return double(projector.alpha[(std::size_t(yi) * size.x + xi) * channels + c]);
    };
    sum += (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) +
           fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
  }
  return sum / channels;
}

// The preview image point of pixel (x, y)'s centre, and whether it shows a direction.
ContentPoint pixel_point(const DisplayPreview& preview, int x, int y) {
  return ContentPoint{0, {(x + 0.5) / preview.size.x, (y + 0.5) / preview.size.y}};
}

bool in_fisheye_disc(glm::dvec2 st) { return std::hypot(2 * st.x - 1, 1 - 2 * st.y) <= 1; }

// Solid angle of the pixel whose centre is at `st` (steradians).
double pixel_solid_angle(const ContentProjection& view, glm::ivec2 size, glm::dvec2 st) {
  if (view.format == ContentFormat::fisheye) {
    const double step = view.fov_deg * kPi / 180 / size.x;  // radians per pixel, both ways
    const double theta = std::hypot(2 * st.x - 1, 1 - 2 * st.y) * view.fov_deg * kPi / 360;
    const double sinc = theta > 1e-12 ? std::sin(theta) / theta : 1.0;
    return sinc * step * step;
  }
  const double elevation = (0.5 - st.y) * kPi;
  return std::cos(elevation) * (2 * kPi / size.x) * (kPi / size.y);
}

// The colour of an overlap count in the overlap colouring (linear).
glm::vec3 overlap_colour(int count) {
  static const glm::vec3 colours[] = {{0.35f, 0.0f, 0.0f},
                                      {0.25f, 0.25f, 0.25f},
                                      {0.9f, 0.75f, 0.05f},
                                      {0.95f, 0.3f, 0.02f},
                                      {0.8f, 0.05f, 0.7f}};
  return colours[std::clamp(count, 0, 4)];
}

// The blend colouring: grey within kBlendTolerance of 1, blue below, red above, saturating at
// ±0.1.
glm::vec3 blend_colour(double sum) {
  const double off = sum - 1;
  if (std::abs(off) <= kBlendTolerance) return {0.3f, 0.3f, 0.3f};
  const float k = float(std::clamp(std::abs(off) / 0.1, 0.15, 1.0));
  return off < 0 ? glm::vec3(0.05f, 0.1f + 0.2f * k, 0.3f + 0.7f * k)
                 : glm::vec3(0.3f + 0.7f * k, 0.05f, 0.05f);
}

// The smallest value below which `fraction` of the total weight lies; sorts `values`. 0 when
// empty.
double weighted_quantile(std::vector<std::pair<double, double>>& values, double fraction) {
  std::sort(values.begin(), values.end());
  double total = 0;
  for (const auto& value : values) total += value.second;
  double below = 0, result = 0;
  for (const auto& [value, weight] : values) {
    below += weight;
    result = value;
    if (below >= fraction * total * (1 - 1e-12)) break;
  }
  return result;
}

// sRGB byte → linear.
float srgb_to_linear(std::uint8_t byte) {
  const float c = float(byte) / 255;
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

glm::vec3 linear_of(glm::u8vec3 srgb) {
  return {srgb_to_linear(srgb.x), srgb_to_linear(srgb.y), srgb_to_linear(srgb.z)};
}

}  // namespace

glm::u8vec3 residual_heat_srgb(double residual_px) {
  struct Stop {
    double px;
    glm::u8vec3 rgb;
  };
  static const Stop stops[] = {{0.0, {0, 0, 255}},
                               {0.5, {0, 255, 0}},
                               {1.0, {255, 255, 0}},
                               {2.0, {255, 0, 0}},
                               {4.0, {255, 255, 255}}};
  if (!(residual_px > stops[0].px)) return stops[0].rgb;
  for (std::size_t n = 1; n < std::size(stops); ++n) {
    const Stop &low = stops[n - 1], &high = stops[n];
    if (residual_px > high.px) continue;
    const double f = (residual_px - low.px) / (high.px - low.px);
    glm::u8vec3 rgb;
    for (int c = 0; c < 3; ++c)
      rgb[c] = std::uint8_t(std::lround((1 - f) * low.rgb[c] + f * high.rgb[c]));
    return rgb;
  }
  return stops[std::size(stops) - 1].rgb;
}

ContentProjection fitted_preview_view(std::span<const PreviewProjector> projectors) {
  constexpr int kSamples = 65;
  std::vector<glm::dvec3> directions;
  glm::dvec3 sum{0.0};
  for (const PreviewProjector& projector : projectors)
    for (int j = 0; j < kSamples; ++j)
      for (int i = 0; i < kSamples; ++i) {
        const glm::dvec2 st{double(i) / (kSamples - 1), double(j) / (kSamples - 1)};
        if (!(projector.warp->coverage_at(st) >= 0.5)) continue;
        const glm::dvec3 v = glm::normalize(projector.warp->v_eye_from_st(st));
        if (!(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z))) continue;
        directions.push_back(v);
        sum += v;
      }
  const double length = glm::length(sum);
  if (directions.empty() || !(length > 1e-6 * double(directions.size()))) return equirect_content();
  const glm::dvec3 axis = sum / length;
  double widest = 0;
  for (const glm::dvec3& v : directions)
    widest = std::max(widest, std::acos(std::clamp(glm::dot(v, axis), -1.0, 1.0)));
  const double fov_deg = std::ceil(2 * widest * 180 / kPi / 10 - 1e-9) * 10;
  if (fov_deg > 270) return equirect_content();
  // The dome orientation whose zenith (sin o·sin t, cos t, −cos o·sin t) is the axis.
  DomeOrientation orientation;
  orientation.tilt_deg = std::acos(std::clamp(axis.y, -1.0, 1.0)) * 180 / kPi;
  orientation.orientation_deg =
      std::hypot(axis.x, axis.z) > 1e-9 ? std::atan2(axis.x, -axis.z) * 180 / kPi : 0.0;
  return fisheye_content(std::max(fov_deg, 10.0), orientation);
}

std::string to_string(PreviewShow show) {
  switch (show) {
    case PreviewShow::projectors:
      return "projectors";
    case PreviewShow::overlap:
      return "overlap";
    case PreviewShow::blend:
      return "blend";
    case PreviewShow::uncovered:
      return "uncovered";
    case PreviewShow::residual:
      return "residual";
  }
  return "projectors";
}

PreviewShow preview_show_from_string(const std::string& name, const std::string& source,
                                     const std::string& field) {
  for (PreviewShow show : {PreviewShow::projectors, PreviewShow::overlap, PreviewShow::blend,
                           PreviewShow::uncovered, PreviewShow::residual})
    if (name == to_string(show)) return show;
  throw InputError(source, field,
                   "projectors, overlap, blend, uncovered or residual, got '" + name + "'");
}

glm::vec3 preview_projector_colour(std::size_t index) {
  static const glm::vec3 palette[] = {
      {0.9f, 0.1f, 0.1f},   {0.1f, 0.7f, 0.1f},   {0.15f, 0.3f, 1.0f},  {0.95f, 0.8f, 0.05f},
      {0.8f, 0.1f, 0.85f},  {0.05f, 0.8f, 0.85f}, {1.0f, 0.45f, 0.05f}, {0.5f, 0.9f, 0.5f},
      {0.55f, 0.35f, 1.0f}, {1.0f, 0.5f, 0.6f},   {0.6f, 0.45f, 0.2f},  {0.7f, 0.7f, 0.7f}};
  return palette[index % std::size(palette)];
}

DisplayPreview preview_display(std::span<const PreviewProjector> projectors,
                               const PreviewOptions& options, const std::string& source) {
  const ContentProjection& view = options.view;
  if (view.format != ContentFormat::fisheye && view.format != ContentFormat::equirect)
    throw InputError(source, OptionName{"view"}, "fisheye or equirect");
  view.validate(source);
  if (options.height_px < 8 || options.height_px > 8192)
    throw InputError(
        source, OptionName{"height_px"},
        "a preview height from 8 to 8192 pixels, got " + std::to_string(options.height_px));
  if (projectors.size() > 32767)
    throw InputError(source, "projectors", "at most 32767 projectors in a preview");
  for (const PreviewProjector& projector : projectors) {
    if (!projector.warp) throw std::invalid_argument("preview_display: a projector has no warp");
    if (projector.alpha.empty()) continue;
    if (projector.alpha_size != projector.warp->output_size ||
        (projector.alpha_channels != 1 && projector.alpha_channels != 3) ||
        projector.alpha.size() != std::size_t(projector.alpha_size.x) * projector.alpha_size.y *
                                      std::size_t(projector.alpha_channels))
      throw InputError(source, projector.name + ".blend",
                       "a blend map of the output's size " +
                           std::to_string(projector.warp->output_size.x) + "x" +
                           std::to_string(projector.warp->output_size.y));
  }

  for (const PreviewProjector& projector : projectors) {
    if (projector.residual_px.empty()) continue;
    const int block = projector.residual_block_px;
    const glm::ivec2 blocks = projector.residual_blocks;
    const glm::ivec2 output = projector.warp->output_size;
    if (block < 1 || blocks.x != (output.x + block - 1) / block ||
        blocks.y != (output.y + block - 1) / block ||
        projector.residual_px.size() != std::size_t(blocks.x) * std::size_t(blocks.y))
      throw std::invalid_argument("preview_display: " + projector.name +
                                  "'s residual map does not tile its output");
  }

  DisplayPreview preview;
  const int height = options.height_px;
  preview.size = {view.format == ContentFormat::fisheye ? height : 2 * height, height};
  const std::size_t pixels = std::size_t(preview.size.x) * preview.size.y;
  // The maps below take 32 bytes a pixel; the image drawn from them and its encoding about as
  // much again.
  require_memory(
      std::uint64_t(pixels) * 64, source, OptionName{"height_px"},
      "a " + std::to_string(preview.size.x) + "x" + std::to_string(preview.size.y) + " preview");
  for (const PreviewProjector& projector : projectors) preview.names.push_back(projector.name);
  preview.in_view.assign(pixels, 0);
  preview.count.assign(pixels, 0);
  preview.blend_sum.assign(pixels, 0.0f);
  preview.strongest.assign(pixels, -1);
  preview.rgb_by_projector.assign(pixels, {0.0f, 0.0f, 0.0f});
  preview.residual_px.assign(pixels, std::numeric_limits<float>::quiet_NaN());
  preview.solid_angle_sr.assign(pixels, 0.0);

  // Rows are independent: split them over the hardware threads, each summing the solid angle
  // every projector covers in its rows.
  const int threads = std::clamp(int(std::thread::hardware_concurrency()), 1, 64);
  std::vector<std::vector<double>> projector_sr(std::size_t(threads),
                                                std::vector<double>(projectors.size(), 0.0));
  auto sample_rows = [&](int y_begin, int y_end, std::vector<double>& covered_sr) {
    for (int y = y_begin; y < y_end; ++y)
      for (int x = 0; x < preview.size.x; ++x) {
        const std::size_t i = std::size_t(y) * preview.size.x + x;
        const ContentPoint point = pixel_point(preview, x, y);
        if (view.format == ContentFormat::fisheye && !in_fisheye_disc(point.st)) continue;
        preview.in_view[i] = 1;
        preview.solid_angle_sr[i] = pixel_solid_angle(view, preview.size, point.st);
        const glm::dvec3 v_eye = view.v_eye_from_point(point);
        double strongest_alpha = -1;
        glm::dvec2 strongest_q{0.0};
        for (std::size_t p = 0; p < projectors.size(); ++p) {
          const Warp& warp = *projectors[p].warp;
          const auto projected = warp.project(v_eye);
          if (!projected || !projected->covered) continue;
          const glm::dvec2 q = projected->q;
          if (!(q.x >= 0 && q.y >= 0 && q.x <= warp.output_size.x && q.y <= warp.output_size.y))
            continue;
          const double alpha = alpha_at(projectors[p], q);
          covered_sr[p] += preview.solid_angle_sr[i];
          ++preview.count[i];
          preview.blend_sum[i] += float(alpha);
          const glm::vec3 colour = preview_projector_colour(p) * float(alpha);
          for (int c = 0; c < 3; ++c) preview.rgb_by_projector[i][std::size_t(c)] += colour[c];
          if (alpha > strongest_alpha) {
            strongest_alpha = alpha;
            strongest_q = q;
            preview.strongest[i] = std::int16_t(p);
          }
        }
        if (preview.strongest[i] < 0) continue;
        const PreviewProjector& strongest = projectors[std::size_t(preview.strongest[i])];
        if (strongest.residual_px.empty()) continue;
        const int block = strongest.residual_block_px;
        const int bx = std::clamp(int(strongest_q.x) / block, 0, strongest.residual_blocks.x - 1);
        const int by = std::clamp(int(strongest_q.y) / block, 0, strongest.residual_blocks.y - 1);
        preview.residual_px[i] =
            strongest.residual_px[std::size_t(by) * strongest.residual_blocks.x + bx];
      }
  };
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t)
    workers.emplace_back(sample_rows, preview.size.y * t / threads,
                         preview.size.y * (t + 1) / threads,
                         std::ref(projector_sr[std::size_t(t)]));
  for (std::thread& worker : workers) worker.join();

  DisplayPreview::Figures& figures = preview.figures;
  figures.projector_sr.assign(projectors.size(), 0.0);
  for (const std::vector<double>& part : projector_sr)
    for (std::size_t p = 0; p < part.size(); ++p) figures.projector_sr[p] += part[p];
  std::vector<std::pair<double, double>> off_weights;  // (|Σ α − 1|, solid angle)
  for (std::size_t i = 0; i < pixels; ++i) {
    if (!preview.in_view[i]) continue;
    const double sr = preview.solid_angle_sr[i];
    figures.view_sr += sr;
    if (preview.count[i] == 0) {
      figures.uncovered_sr += sr;
      continue;
    }
    figures.covered_sr += sr;
    if (preview.count[i] >= 2) figures.overlap_sr += sr;
    const double off = std::abs(double(preview.blend_sum[i]) - 1);
    figures.blend_worst = std::max(figures.blend_worst, off);
    if (off > kBlendTolerance) figures.blend_off_sr += sr;
    off_weights.emplace_back(off, sr);
  }
  figures.blend_p99 = weighted_quantile(off_weights, 0.99);
  std::vector<std::pair<double, double>> residual_weights;  // (residual, solid angle)
  for (std::size_t i = 0; i < pixels; ++i)
    if (std::isfinite(preview.residual_px[i]))
      residual_weights.emplace_back(preview.residual_px[i], preview.solid_angle_sr[i]);
  if (!residual_weights.empty()) {
    figures.residual_p50_px = weighted_quantile(residual_weights, 0.5);
    figures.residual_p99_px = weighted_quantile(residual_weights, 0.99);
    figures.residual_worst_px = weighted_quantile(residual_weights, 1.0);
  }
  return preview;
}

std::vector<std::uint8_t> render_preview(const DisplayPreview& preview, PreviewShow show,
                                         const ContentProjection& view) {
  const glm::ivec2 size = preview.size;
  std::vector<std::uint8_t> rgba(std::size_t(size.x) * size.y * 4, 0);
  for (std::size_t i = 3; i < rgba.size(); i += 4) rgba[i] = 255;

  // The grid's frame: "up" the direction at the fisheye's centre (the dome's zenith) or the
  // equirect's top edge; "front" the direction below the fisheye's centre or at the equirect's
  // centre, made horizontal.
  const bool fisheye = view.format == ContentFormat::fisheye;
  const glm::dvec3 up =
      view.v_eye_from_point({0, fisheye ? glm::dvec2(0.5, 0.5) : glm::dvec2(0.5, 0.0)});
  glm::dvec3 front =
      view.v_eye_from_point({0, fisheye ? glm::dvec2(0.5, 0.75) : glm::dvec2(0.5, 0.5)});
  front = glm::normalize(front - glm::dot(front, up) * up);
  const glm::dvec3 right = glm::cross(front, up);
  const double grid_step = 30 * kPi / 180;

  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      const std::size_t i = std::size_t(y) * size.x + x;
      if (!preview.in_view[i]) continue;
      const int count = preview.count[i];
      glm::vec3 colour;
      switch (show) {
        case PreviewShow::projectors: {
          const auto& rgb = preview.rgb_by_projector[i];
          colour = count ? glm::vec3(rgb[0], rgb[1], rgb[2]) : glm::vec3(0.02f);
          break;
        }
        case PreviewShow::overlap:
          colour = overlap_colour(count);
          break;
        case PreviewShow::blend:
          colour = count ? blend_colour(preview.blend_sum[i]) : glm::vec3(0.0f);
          break;
        case PreviewShow::uncovered:
          colour = count ? glm::vec3(0.2f) : glm::vec3(1.0f, 0.0f, 0.0f);
          break;
        case PreviewShow::residual:
          colour = !count ? glm::vec3(0.0f)
                   : std::isfinite(preview.residual_px[i])
                       ? linear_of(residual_heat_srgb(preview.residual_px[i]))
                       : glm::vec3(0.06f);
          break;
      }
      // The grid: within half a pixel's angle of a multiple of 30° in elevation or azimuth.
      const glm::dvec3 v = view.v_eye_from_point(pixel_point(preview, x, y));
      const double pixel_angle = std::sqrt(preview.solid_angle_sr[i]);
      const double elevation = std::asin(std::clamp(glm::dot(v, up), -1.0, 1.0));
      const double azimuth = std::atan2(glm::dot(v, right), glm::dot(v, front));
      auto near_line = [&](double angle, double scale) {
        const double d = std::abs(angle - std::round(angle / grid_step) * grid_step);
        return d * scale < 0.5 * pixel_angle;
      };
      if (near_line(elevation, 1.0) ||
          (std::cos(elevation) > 0.2 && near_line(azimuth, std::cos(elevation))))
        colour = 0.6f * colour + glm::vec3(0.4f);
      const glm::u8vec4 encoded = raster::srgb8(colour);
      std::copy_n(&encoded[0], 4, &rgba[i * 4]);
    }

  // The legend, top-left: a swatch and a label per entry.
  const int scale = std::max(1, size.y / 400);
  const int row = 12 * scale, swatch = 9 * scale;
  std::vector<std::pair<glm::vec3, std::string>> entries;
  switch (show) {
    case PreviewShow::projectors:
      for (std::size_t p = 0; p < preview.names.size(); ++p)
        entries.emplace_back(preview_projector_colour(p), preview.names[p]);
      entries.emplace_back(glm::vec3(0.02f), "uncovered");
      break;
    case PreviewShow::overlap:
      for (int c = 0; c <= 4; ++c)
        entries.emplace_back(overlap_colour(c),
                             c == 4 ? "4 or more projectors"
                                    : std::to_string(c) + " projector" + (c == 1 ? "" : "s"));
      break;
    case PreviewShow::blend:
      entries.emplace_back(blend_colour(1.0), "blend sum 1 +- 0.005");
      entries.emplace_back(blend_colour(0.9), "below 1 (to 0.9 and less)");
      entries.emplace_back(blend_colour(1.1), "above 1 (to 1.1 and more)");
      entries.emplace_back(glm::vec3(0.0f), "uncovered");
      break;
    case PreviewShow::uncovered:
      entries.emplace_back(glm::vec3(0.2f), "covered");
      entries.emplace_back(glm::vec3(1.0f, 0.0f, 0.0f), "uncovered");
      break;
    case PreviewShow::residual:
      for (const double px : {0.0, 0.5, 1.0, 2.0, 4.0})
        entries.emplace_back(linear_of(residual_heat_srgb(px)),
                             "fit residual " +
                                 std::string(px == 0.0   ? "0"
                                             : px == 0.5 ? "0.5"
                                             : px == 1.0 ? "1"
                                             : px == 2.0 ? "2"
                                                         : "4 or more") +
                                 " px (RMS per block)");
      entries.emplace_back(glm::vec3(0.06f), "no sample");
      entries.emplace_back(glm::vec3(0.0f), "uncovered");
      break;
  }
  entries.emplace_back(glm::vec3(0.6f), "grid every 30 degrees");
  int y = 4 * scale;
  for (const auto& [colour, label] : entries) {
    raster::fill_rect(rgba, size, {4 * scale, y, swatch, swatch}, raster::srgb8(colour));
    raster::draw_text(rgba, size, 4 * scale + swatch + 4 * scale, y + scale, label,
                      {255, 255, 255, 255}, scale);
    y += row;
  }
  return rgba;
}

}  // namespace facet
