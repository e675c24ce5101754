#pragma once
// Structured-light decoding: for every camera pixel, the continuous projector position it sees,
// a confidence, and why it was masked.
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <opencv2/core.hpp>
#include <span>
#include <string>

#include "facet/calibration/capture.hpp"
#include "facet/calibration/patterns.hpp"

namespace facet::calibration {

// Why a camera pixel has no projector position; bits of DecodedMap::mask, 0 when decoded.
enum DecodeMaskBit : std::uint8_t {
  kMaskShadow = 1,        // white − black below DecodeOptions::min_signal: no projector light
  kMaskLowContrast = 2,   // a Gray bit or the phase modulation too weak against white − black
  kMaskDisagreement = 4,  // the phase, unwrapped with the Gray code, lies too far from it
  kMaskOutOfRange = 8,    // the Gray code names a pixel beyond the projector's size
};

struct DecodeOptions {
  // Shadow: white − black (linear light, images in [0,1]) below this. Without white and black
  // frames, the largest |pattern − inverse| over the Gray bits stands in for white − black.
  double min_signal = 0.05;
  // Low contrast: some Gray bit has |pattern − inverse| < min_bit_contrast · (white − black).
  // A bit without an inverse is compared with the midpoint of white and black, and its contrast
  // counts twice its distance from it. Not applied on an axis with phase frames: the phase decides
  // there, and the disagreement test catches a wrong Gray code. The finest bits of a slightly
  // blurred capture lose contrast only where stripes meet, where a wrong bit moves the result by
  // one pixel; the default masks those ambiguous pixels and not much more (on the procam-board
  // capture it masks 20% of the image, and halves the 99th-percentile error).
  double min_bit_contrast = 0.03;
  // Low contrast, in absolute terms: some Gray bit has |pattern − inverse| below this (linear
  // light, images in [0,1]; 0.01 is 2.5 levels of an 8-bit camera). Catches pixels that only
  // indirect light reaches, where relative contrast alone would trust noise.
  double min_bit_signal = 0.01;
  // Low contrast: the phase modulation, as a fraction of the full modulation that white − black
  // allows (1 for a sharp pattern), is below this.
  double min_phase_modulation = 0.15;
  // Disagreement: the unwrapped phase position may lie this far outside the Gray code's pixel
  // (or block of pixels, when low Gray bits are left out), in projector pixels.
  double max_disagreement_px = 1.0;
};

struct DecodedMap {
  glm::ivec2 camera_size{0, 0};       // width, height in camera pixels
  glm::ivec2 projector_size{0, 0};    // W, H in projector pixels
  bool has_x = false, has_y = false;  // which axes the patterns measured
  // CV_64FC2, camera_size: the projector position (x, y) seen by each camera pixel, in output
  // pixels (projector pixel c spans [c, c+1), so Gray code alone gives centres c + 0.5). NaN in
  // an axis that was not measured and wherever mask != 0.
  cv::Mat q_projector;
  // CV_32F in [0,1]: the weakest normalised contrast that decided this pixel (Gray bit contrast,
  // or phase modulation on phase axes); 0 where masked.
  cv::Mat confidence;
  cv::Mat mask;  // CV_8U, DecodeMaskBit flags, 0 where decoded

  double decoded_fraction() const;
};

// Loads frame k of the pattern list as a CV_32F single-channel image, linear in light.
using FrameLoader = std::function<cv::Mat(std::size_t frame)>;

// Decodes one projector's frames. `patterns[k]` is what frame k shows, `gamma` the projector's
// response (a value v emits light ∝ v^gamma), used to linearise phase frames with the white and
// black frames.
//
// Needs, for every axis that has a Gray or phase frame: every Gray bit, each with its inverse or
// else white and black frames to compare with; with phase frames on the axis, the lowest Gray
// bits whose blocks are no wider than half a period may be left out, and all steps of one period
// must be present. Phase with gamma != 1 needs white and black. A missing frame throws
// InputError(source, field, ...) before any image is loaded; images of different sizes throw too.
// Decoding runs in parallel over rows.
DecodedMap decode(std::span<const Pattern> patterns, const FrameLoader& load,
                  glm::ivec2 projector_size, double gamma, const DecodeOptions& options = {},
                  const std::string& source = "patterns", const std::string& field = "frames");

// The same with the images in memory (CV_32F, or CV_8U / CV_16U scaled to [0,1]).
DecodedMap decode(std::span<const Pattern> patterns, std::span<const cv::Mat> images,
                  glm::ivec2 projector_size, double gamma, const DecodeOptions& options = {});

// Decodes projector `projector_index` of a capture: checks the frames and every image header
// first (InputError naming capture.json's field or the image), then streams the images.
DecodedMap decode_capture(const Capture& capture, std::size_t projector_index,
                          const DecodeOptions& options = {});

}  // namespace facet::calibration
