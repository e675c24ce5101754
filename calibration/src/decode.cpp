#include "facet/calibration/decode.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "facet/projection/errors.hpp"

namespace facet::calibration {
namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

// Which frame plays which role, found once before any image is loaded.
struct AxisPlan {
  bool used = false;
  int size = 0;        // projector pixels along the axis
  int bits = 0;        // gray_bits(size)
  int lowest_bit = 0;  // Gray bits below this are left out (phase decides there)
  std::vector<std::size_t> gray, inverse;  // frame index per bit, kNone when absent
  double period = 0;                       // phase, 0 when none
  std::vector<std::size_t> phase;          // frame index per step
};

struct Plan {
  std::size_t white = kNone, black = kNone;
  AxisPlan axes[2];
};

const char* axis_name(int axis) { return axis == 0 ? "x" : "y"; }

Plan plan_decode(std::span<const Pattern> patterns, glm::ivec2 projector_size, double gamma,
                 const std::string& source, const std::string& field) {
  FACET_ASSERT(projector_size.x >= 1 && projector_size.y >= 1);
  auto fail = [&](const std::string& expected) { throw InputError(source, field, expected); };
  Plan plan;
  for (int a = 0; a < 2; ++a) {
    AxisPlan& axis = plan.axes[a];
    axis.size = a == 0 ? projector_size.x : projector_size.y;
    axis.bits = gray_bits(axis.size);
    axis.gray.assign(std::size_t(axis.bits), kNone);
    axis.inverse.assign(std::size_t(axis.bits), kNone);
  }
  for (std::size_t k = 0; k < patterns.size(); ++k) {
    const Pattern& pattern = patterns[k];
    const std::string frame = "frame " + std::to_string(k);
    switch (pattern.type) {
      case PatternType::white:
        if (plan.white != kNone) fail("one white frame, but " + frame + " is another");
        plan.white = k;
        break;
      case PatternType::black:
        if (plan.black != kNone) fail("one black frame, but " + frame + " is another");
        plan.black = k;
        break;
      case PatternType::gray: {
        AxisPlan& axis = plan.axes[pattern.axis == Axis::x ? 0 : 1];
        axis.used = true;
        if (pattern.bit < 0 || pattern.bit >= axis.bits) {
          fail(frame + ": a Gray bit below " + std::to_string(axis.bits));
        }
        auto& slot = pattern.inverted ? axis.inverse : axis.gray;
        if (slot[std::size_t(pattern.bit)] != kNone) fail(frame + ": a pattern shown only once");
        slot[std::size_t(pattern.bit)] = k;
        break;
      }
      case PatternType::phase: {
        AxisPlan& axis = plan.axes[pattern.axis == Axis::x ? 0 : 1];
        axis.used = true;
        if (axis.period == 0) {
          axis.period = pattern.period;
          axis.phase.assign(std::size_t(pattern.steps), kNone);
        } else if (axis.period != pattern.period || int(axis.phase.size()) != pattern.steps) {
          fail(frame + ": one phase period and step count per axis (this decoder)");
        }
        FACET_ASSERT(pattern.step >= 0 && pattern.step < pattern.steps);
        if (axis.phase[std::size_t(pattern.step)] != kNone) fail(frame + ": a pattern shown once");
        axis.phase[std::size_t(pattern.step)] = k;
        break;
      }
    }
  }
  const bool white_black = plan.white != kNone && plan.black != kNone;
  bool any_axis = false;
  for (int a = 0; a < 2; ++a) {
    AxisPlan& axis = plan.axes[a];
    if (!axis.used) continue;
    any_axis = true;
    if (axis.period > 0) {
      for (std::size_t step = 0; step < axis.phase.size(); ++step) {
        if (axis.phase[step] == kNone) {
          fail("phase step " + std::to_string(step) + " of " + std::to_string(axis.phase.size()) +
               " on axis " + axis_name(a) + " (period " + std::to_string(axis.period) + ")");
        }
      }
      if (gamma != 1.0 && !white_black) {
        fail(
            "white and black frames: phase frames of a projector with gamma != 1 are "
            "linearised with them");
      }
      // Leaving out bits below k puts the Gray estimate within 2^(k-1) of the truth; keeping
      // that below a quarter period leaves the unwrapping a margin.
      while (axis.lowest_bit < axis.bits &&
             std::ldexp(1.0, axis.lowest_bit + 1) <= axis.period / 2) {
        ++axis.lowest_bit;
      }
      // Use the low bits that are there, as long as the ones above them are complete.
      while (axis.lowest_bit > 0 && axis.gray[std::size_t(axis.lowest_bit - 1)] != kNone) {
        --axis.lowest_bit;
      }
    }
    for (int bit = axis.bits - 1; bit >= axis.lowest_bit; --bit) {
      const std::size_t b = std::size_t(bit);
      const std::string what = "Gray bit " + std::to_string(bit) + " of axis " + axis_name(a);
      const std::string why = " (" + std::to_string(axis.bits) + " bits identify each of the " +
                              std::to_string(axis.size) + (a == 0 ? " columns" : " rows") +
                              (axis.period > 0 ? " to within half a phase period" : "") + ")";
      if (axis.gray[b] == kNone && axis.inverse[b] == kNone) fail("a frame with " + what + why);
      if (axis.gray[b] == kNone) fail("the non-inverted " + what + why);
      if (axis.inverse[b] == kNone && !white_black) {
        fail("the inverse of " + what + ", or white and black frames to compare it with");
      }
    }
  }
  if (!any_axis) fail("Gray code or phase frames for at least one axis");
  if (!white_black) {
    for (const AxisPlan& axis : plan.axes) {
      for (int bit = axis.lowest_bit; axis.used && bit < axis.bits; ++bit) {
        FACET_ASSERT(axis.inverse[std::size_t(bit)] != kNone);
      }
    }
    bool any_pair = false;
    for (const AxisPlan& axis : plan.axes)
      any_pair = any_pair || (axis.used && axis.bits > axis.lowest_bit);
    if (!any_pair) fail("white and black frames (to tell lit pixels from shadow)");
  }
  return plan;
}

cv::Mat as_float(const cv::Mat& image) {
  if (image.type() == CV_32F) return image;
  cv::Mat converted;
  if (image.depth() == CV_8U) {
    image.convertTo(converted, CV_32F, 1.0 / 255);
  } else if (image.depth() == CV_16U) {
    image.convertTo(converted, CV_32F, 1.0 / 65535);
  } else {
    image.convertTo(converted, CV_32F);
  }
  return converted;
}

template <typename Body>
void for_rows(int rows, const Body& body) {
  cv::parallel_for_(
      cv::Range(0, rows),
      [&](const cv::Range& range) {
        for (int y = range.start; y < range.end; ++y) body(y);
      },
      std::max(1.0, rows / 16.0));
}

std::uint32_t gray_to_binary(std::uint32_t gray) {
  for (std::uint32_t shift = 1; shift < 32; shift <<= 1) gray ^= gray >> shift;
  return gray;
}

}  // namespace

double DecodedMap::decoded_fraction() const {
  if (mask.empty()) return 0;
  return double(cv::countNonZero(mask == 0)) / double(mask.total());
}

DecodedMap decode(std::span<const Pattern> patterns, const FrameLoader& load,
                  glm::ivec2 projector_size, double gamma, const DecodeOptions& options,
                  const std::string& source, const std::string& field) {
  FACET_ASSERT(gamma > 0);
  const Plan plan = plan_decode(patterns, projector_size, gamma, source, field);

  std::optional<cv::Size> size;
  auto load_checked = [&](std::size_t frame) {
    cv::Mat image = as_float(load(frame));
    if (image.empty() || image.channels() != 1) {
      throw InputError(source, field,
                       "frame " + std::to_string(frame) + ": a single-channel image");
    }
    if (!size) {
      size = image.size();
    } else if (image.size() != *size) {
      throw InputError(source, field,
                       "frame " + std::to_string(frame) +
                           ": an image of the same size as the "
                           "others (" +
                           std::to_string(size->width) + "x" + std::to_string(size->height) + ")");
    }
    return image;
  };

  const bool white_black = plan.white != kNone && plan.black != kNone;
  cv::Mat white, black;
  if (white_black) {
    white = load_checked(plan.white);
    black = load_checked(plan.black);
  }

  // Per-axis accumulators, filled one frame pair at a time so that only a few images are held.
  struct AxisState {
    cv::Mat code;              // CV_32S Gray code bits
    cv::Mat min_contrast;      // CV_32F weakest bit contrast relative to white − black
    cv::Mat sum_sin, sum_cos;  // CV_64F phase sums
  };
  AxisState states[2];
  cv::Mat range;  // CV_32F white − black, or the strongest pair contrast without them

  // Gray bits first: without white and black their pair contrasts give the range.
  std::vector<std::pair<cv::Mat, cv::Mat>> bit_contrasts;  // only used without white/black
  for (int a = 0; a < 2; ++a) {
    const AxisPlan& axis = plan.axes[a];
    if (!axis.used) continue;
    AxisState& state = states[a];
    for (int bit = axis.bits - 1; bit >= axis.lowest_bit; --bit) {
      const std::size_t b = std::size_t(bit);
      const cv::Mat pattern = load_checked(axis.gray[b]);
      const cv::Mat inverse = axis.inverse[b] != kNone ? load_checked(axis.inverse[b]) : cv::Mat();
      if (state.code.empty()) {
        state.code = cv::Mat::zeros(*size, CV_32S);
        state.min_contrast = cv::Mat(*size, CV_32F, cv::Scalar(std::numeric_limits<float>::max()));
      }
      // Absolute contrast here; divided by the range once it is known.
      for_rows(size->height, [&](int y) {
        const float* p = pattern.ptr<float>(y);
        const float* inv = inverse.empty() ? nullptr : inverse.ptr<float>(y);
        const float* w = white_black ? white.ptr<float>(y) : nullptr;
        const float* k = white_black ? black.ptr<float>(y) : nullptr;
        auto* code = state.code.ptr<std::int32_t>(y);
        auto* contrast = state.min_contrast.ptr<float>(y);
        for (int x = 0; x < size->width; ++x) {
          // Compare with the inverse, not with a threshold: ambient light and the projector's
          // gamma move both alike.
          const float difference =
              inv != nullptr ? p[x] - inv[x] : 2 * (p[x] - 0.5f * (w[x] + k[x]));
          if (difference > 0) code[x] |= std::int32_t(1) << bit;
          contrast[x] = std::min(contrast[x], std::abs(difference));
        }
      });
      if (!white_black) {
        cv::Mat magnitude = cv::abs(pattern - inverse);
        range = range.empty() ? magnitude : cv::max(range, magnitude);
      }
    }
  }
  if (white_black) range = white - black;

  // Phase sums, linearised when the projector is not linear.
  const double inverse_gamma = 1.0 / gamma;
  for (int a = 0; a < 2; ++a) {
    const AxisPlan& axis = plan.axes[a];
    if (axis.period == 0) continue;
    AxisState& state = states[a];
    state.sum_sin = cv::Mat::zeros(*size, CV_64F);
    state.sum_cos = cv::Mat::zeros(*size, CV_64F);
    const int steps = int(axis.phase.size());
    for (int step = 0; step < steps; ++step) {
      const cv::Mat image = load_checked(axis.phase[std::size_t(step)]);
      const double delta = 2 * std::numbers::pi * step / steps;
      const double sin_delta = std::sin(delta), cos_delta = std::cos(delta);
      for_rows(size->height, [&](int y) {
        const float* intensity = image.ptr<float>(y);
        const float* w = white_black ? white.ptr<float>(y) : nullptr;
        const float* k = white_black ? black.ptr<float>(y) : nullptr;
        auto* s = state.sum_sin.ptr<double>(y);
        auto* c = state.sum_cos.ptr<double>(y);
        for (int x = 0; x < size->width; ++x) {
          double value = intensity[x];
          if (gamma != 1.0) {
            // Light ∝ v^gamma between black and white: recover the pattern value v.
            const double span = double(w[x]) - double(k[x]);
            const double relative = span > 0 ? (value - double(k[x])) / span : 0.0;
            value = std::pow(std::clamp(relative, 0.0, 1.0), inverse_gamma);
          }
          s[x] += value * sin_delta;
          c[x] += value * cos_delta;
        }
      });
    }
  }

  DecodedMap map;
  map.camera_size = {size->width, size->height};
  map.projector_size = projector_size;
  map.has_x = plan.axes[0].used;
  map.has_y = plan.axes[1].used;
  map.q_projector = cv::Mat(*size, CV_64FC2);
  map.confidence = cv::Mat(*size, CV_32F);
  map.mask = cv::Mat(*size, CV_8U);
  const double nan = std::numeric_limits<double>::quiet_NaN();

  for_rows(size->height, [&](int y) {
    const float* signal = range.ptr<float>(y);
    auto* q = map.q_projector.ptr<cv::Vec2d>(y);
    auto* confidence = map.confidence.ptr<float>(y);
    auto* mask = map.mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < size->width; ++x) {
      std::uint8_t flags = 0;
      double weakest = 1.0;
      cv::Vec2d position(nan, nan);
      if (!(signal[x] >= options.min_signal)) flags |= kMaskShadow;
      for (int a = 0; a < 2 && flags == 0; ++a) {
        const AxisPlan& axis = plan.axes[a];
        if (!axis.used) continue;
        const AxisState& state = states[a];
        // Gray estimate: the centre of the pixel, or of the block the kept bits name.
        const double block = std::ldexp(1.0, axis.lowest_bit);
        double start = 0;
        if (axis.bits > axis.lowest_bit) {
          const auto gray = std::uint32_t(state.code.ptr<std::int32_t>(y)[x]) >> axis.lowest_bit;
          start = double(gray_to_binary(gray)) * block;
          if (start >= axis.size) flags |= kMaskOutOfRange;
          const double absolute = state.min_contrast.ptr<float>(y)[x];
          const double contrast = absolute / signal[x];
          if (axis.period == 0) {
            if (contrast < options.min_bit_contrast || absolute < options.min_bit_signal) {
              flags |= kMaskLowContrast;
            }
            weakest = std::min(weakest, contrast);
          }
        }
        const double estimate = start + block / 2;
        double decoded = estimate;
        if (axis.period > 0) {
          const double s = state.sum_sin.ptr<double>(y)[x];
          const double c = state.sum_cos.ptr<double>(y)[x];
          const double steps = double(axis.phase.size());
          // I_k = A + B·cos(θ − δ_k) gives Σ I_k·(sin δ_k, cos δ_k) = (N/2)·B·(sin θ, cos θ).
          const double amplitude = 2 / steps * std::hypot(s, c);
          // A sharp pattern swings by half the white − black span (gamma 1), or by 0.5 in
          // linearised pattern values.
          const double full = gamma != 1.0 ? 0.5 : 0.5 * signal[x];
          const double modulation = amplitude / full;
          if (modulation < options.min_phase_modulation) flags |= kMaskLowContrast;
          weakest = std::min(weakest, modulation);
          const double turns = std::atan2(s, c) / (2 * std::numbers::pi);  // θ = 2π·x/period
          const double wrapped = axis.period * (turns - std::floor(turns));
          decoded = wrapped + axis.period * std::round((estimate - wrapped) / axis.period);
          if (std::abs(decoded - estimate) > block / 2 + options.max_disagreement_px) {
            flags |= kMaskDisagreement;
          }
        }
        position[a] = decoded;
      }
      mask[x] = flags;
      if (flags != 0) {
        q[x] = cv::Vec2d(nan, nan);
        confidence[x] = 0;
      } else {
        q[x] = position;
        confidence[x] = float(std::clamp(weakest, 0.0, 1.0));
      }
    }
  });
  return map;
}

DecodedMap decode(std::span<const Pattern> patterns, std::span<const cv::Mat> images,
                  glm::ivec2 projector_size, double gamma, const DecodeOptions& options) {
  FACET_ASSERT(patterns.size() == images.size());
  return decode(
      patterns, [&](std::size_t frame) { return images[frame]; }, projector_size, gamma, options,
      "patterns", "frames");
}

DecodedMap decode_capture(const Capture& capture, std::size_t projector_index,
                          const DecodeOptions& options) {
  FACET_ASSERT(projector_index < capture.projectors.size());
  const CaptureProjector& projector = capture.projectors[projector_index];
  std::vector<Pattern> patterns;
  for (const CaptureFrame& frame : projector.frames) patterns.push_back(frame.pattern);
  const std::string source = capture.resolve("capture.json").string();
  const std::string field = "projectors[" + std::to_string(projector_index) + "].frames";
  // Missing frames and bad image files are reported before the long part starts.
  plan_decode(patterns, projector.size, projector.gamma, source, field);
  check_capture_images(capture, projector_index);
  return decode(
      patterns, [&](std::size_t frame) { return load_frame(capture, projector.frames[frame]); },
      projector.size, projector.gamma, options, source, field);
}

}  // namespace facet::calibration
